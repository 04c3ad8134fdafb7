//! The open rim of a mesh: its boundary edges (vertices identified by position), each with
//! its triangle's frame, and its corners. Shared by the caps and the thin shell.

use std::collections::HashMap;

use mesh_io::TriMesh;
use vf_common::vec3::{cross, dot, norm, sub};

/// A boundary edge (a, b) with its triangle's unit normal and the unit direction across the
/// edge, away from the triangle, in its plane.
pub(super) type RimEdge = ([f64; 3], [f64; 3], [f64; 3], [f64; 3]);

/// A rim point with its normal and outward direction (as [`RimEdge`]'s).
pub(super) type RimPoint = ([f64; 3], [f64; 3], [f64; 3]);

/// A rim corner as a [`RimPoint`] (the mean of its edges' frames) with each of its two
/// edges' outward directions.
pub(super) type Corner = (RimPoint, [[f64; 3]; 2]);

/// The corners of a rim given as edges with frames (from [`rim_with_frames`]): boundary
/// vertices (by position) with exactly two boundary edges that meet at an angle below 150°
/// (a straight rim: 180°), each with the mean of its edges' normals and of their outward
/// directions (unit), sorted by position so the order does not depend on hashing.
pub(super) fn rim_corners(frames: &[RimEdge]) -> Vec<Corner> {
    let mut at: HashMap<[u64; 3], Vec<(usize, [f64; 3])>> = HashMap::new();
    for (i, &(a, b, _, _)) in frames.iter().enumerate() {
        at.entry(a.map(f64::to_bits)).or_default().push((i, b));
        at.entry(b.map(f64::to_bits)).or_default().push((i, a));
    }
    let unit = |v: [f64; 3]| {
        let l = norm(v);
        (l > 0.0).then(|| v.map(|x| x / l))
    };
    let mut corners: Vec<([u64; 3], Corner)> = Vec::new();
    for (key, ends) in &at {
        let [(e, p), (f, q)] = ends[..] else { continue };
        let v = key.map(f64::from_bits);
        let (Some(u), Some(w)) = (unit([0, 1, 2].map(|c| p[c] - v[c])), unit([0, 1, 2].map(|c| q[c] - v[c]))) else {
            continue;
        };
        let cos = dot(u, w);
        if cos <= 150f64.to_radians().cos() {
            continue;
        }
        let (ne, de) = (frames[e].2, frames[e].3);
        let (nf, df) = (frames[f].2, frames[f].3);
        let n = unit([0, 1, 2].map(|c| ne[c] + nf[c])).unwrap_or(ne);
        let d = unit([0, 1, 2].map(|c| de[c] + df[c])).unwrap_or(de);
        corners.push((*key, ((v, n, d), [de, df])));
    }
    corners.sort_by_key(|c| c.0);
    corners.into_iter().map(|(_, p)| p).collect()
}

/// Open boundary edges (one incident triangle), with vertices identified by position so a
/// soup of triangles sharing corners has no false boundary: (a, b, triangle).
pub(super) fn boundary_edges(mesh: &TriMesh) -> Vec<([f64; 3], [f64; 3], u32)> {
    let mut id: HashMap<[u64; 3], u32> = HashMap::new();
    let canon: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let next = id.len() as u32;
            *id.entry(p.map(f64::to_bits)).or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for e in 0..3 {
            let (a, b) = (canon[tri[e] as usize], canon[tri[(e + 1) % 3] as usize]);
            if a != b {
                let entry = edges.entry((a.min(b), a.max(b))).or_insert((0, t as u32));
                entry.0 += 1;
            }
        }
    }
    let mut out: Vec<([f64; 3], [f64; 3], u32)> = Vec::new();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        for e in 0..3 {
            let (va, vb) = (tri[e] as usize, tri[(e + 1) % 3] as usize);
            let (a, b) = (canon[va], canon[vb]);
            if a != b && edges[&(a.min(b), a.max(b))] == (1, t as u32) {
                out.push((mesh.positions[va], mesh.positions[vb], t as u32));
            }
        }
    }
    out
}

/// Each boundary edge with its triangle's unit normal n and the unit direction d in the
/// triangle's plane, across the edge and away from the triangle (degenerate triangles are
/// skipped).
pub(super) fn rim_with_frames(mesh: &TriMesh, rim: &[([f64; 3], [f64; 3], u32)]) -> Vec<RimEdge> {
    let unit = |v: [f64; 3]| {
        let l = norm(v);
        (l > 0.0).then(|| v.map(|x| x / l))
    };
    rim.iter()
        .filter_map(|&(a, b, t)| {
            let [p, q, r] = mesh.triangles[t as usize].map(|v| mesh.positions[v as usize]);
            let n = unit(cross(sub(q, p), sub(r, p)))?;
            let mut d = unit(cross(sub(b, a), n))?;
            let centroid = [0, 1, 2].map(|c| (p[c] + q[c] + r[c]) / 3.0);
            if (0..3).map(|c| d[c] * (centroid[c] - a[c])).sum::<f64>() > 0.0 {
                d = d.map(|x| -x);
            }
            Some((a, b, n, d))
        })
        .collect()
}
