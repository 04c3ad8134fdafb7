//! From Voronoi face polygons to a closed manifold triangle mesh.
//!
//! On generic input every Voronoi edge has three cells around it and every Voronoi vertex
//! four, so the crust is a manifold as it stands. On exactly degenerate input (lattices,
//! cospherical sets) several tetrahedra share one Voronoi vertex and two inside cells can
//! touch along an edge or at a point only; there the half-edges around an edge are paired
//! by angle (each face with its neighbour on its inside side, so each pair bounds one
//! wedge of solid), and each vertex is split into one copy per umbrella of faces.

use std::collections::{HashMap, HashSet};

use mesh_io::TriMesh;
use vf_common::vec3::{cross, dot, sub, V3 as V};

use crate::error::CrustError;

/// Newell normal of a polygon (not normalised).
fn newell(poly: &[u32], pos: &[V]) -> V {
    let mut n = [0.0; 3];
    for i in 0..poly.len() {
        let (p, q) = (pos[poly[i] as usize], pos[poly[(i + 1) % poly.len()] as usize]);
        n[0] += (p[1] - q[1]) * (p[2] + q[2]);
        n[1] += (p[2] - q[2]) * (p[0] + q[0]);
        n[2] += (p[0] - q[0]) * (p[1] + q[1]);
    }
    n
}

/// A built mesh and where its vertices come from.
pub(crate) struct Built {
    pub mesh: TriMesh,
    /// Distinct polygon vertex ids used.
    pub num_used: usize,
    /// Extra copies made by splitting and midpoints.
    pub num_split: usize,
    /// Per mesh vertex: the polygon vertex id it copies (for a computed vertex, one of the
    /// polygon vertices it was computed from).
    pub source: Vec<u32>,
    /// Per mesh vertex: whether its position is computed (an edge midpoint or a polygon
    /// centroid) rather than copied.
    pub computed: Vec<bool>,
    /// The polygons as mesh vertex ids (split copies and inserted midpoints included),
    /// before triangulation.
    pub faces: Vec<Vec<u32>>,
}

/// Why the polygons do not make a closed oriented manifold, and the polygon vertices at
/// fault.
#[derive(Debug)]
pub(crate) struct BuildError {
    pub message: String,
    pub vertices: Vec<u32>,
}

impl From<BuildError> for CrustError {
    fn from(e: BuildError) -> Self {
        CrustError::Internal(e.message)
    }
}

/// Build the mesh. `polygons`: oriented simple polygons (no vertex repeated) as ids into
/// `positions` (#P×3 f64).
///
/// About 180 lines, over the workspace's ~150: its phases (half-edges, twin pairing by
/// angle, vertex umbrellas and splitting, midpoints on repeated edges, triangulation), each
/// marked by a comment, share the half-edge closures (`from`, `next`, `prev`, `to` over
/// `offset` and `face_of`) and six per-half-edge arrays; passing those between functions
/// would take a struct of its own, which the next change of this module should introduce.
pub(crate) fn build(polygons: &[Vec<u32>], positions: &[V]) -> Result<Built, BuildError> {
    // Half-edge h = offset[f] + i goes from polygons[f][i] to polygons[f][i + 1].
    let mut offset = Vec::with_capacity(polygons.len() + 1);
    let mut total = 0usize;
    for p in polygons {
        offset.push(total);
        total += p.len();
    }
    offset.push(total);
    let mut face_of = Vec::with_capacity(total);
    for (f, p) in polygons.iter().enumerate() {
        face_of.extend(std::iter::repeat_n(f as u32, p.len()));
    }
    let from = |h: usize| polygons[face_of[h] as usize][h - offset[face_of[h] as usize]];
    let next = |h: usize| {
        let f = face_of[h] as usize;
        let i = h - offset[f];
        offset[f] + (i + 1) % polygons[f].len()
    };
    let prev = |h: usize| {
        let f = face_of[h] as usize;
        let i = h - offset[f];
        offset[f] + (i + polygons[f].len() - 1) % polygons[f].len()
    };
    let to = |h: usize| from(next(h));

    // Group half-edges by undirected edge.
    let mut groups: HashMap<(u32, u32), Vec<usize>> = HashMap::with_capacity(total / 2);
    for h in 0..total {
        let (a, b) = (from(h), to(h));
        if a == b {
            return Err(BuildError { message: format!("polygon {} repeats a vertex", face_of[h]), vertices: vec![a] });
        }
        groups.entry((a.min(b), a.max(b))).or_default().push(h);
    }
    let mut twin = vec![usize::MAX; total];
    // Every edge that cannot be paired, reported together (smallest edge first) so that the
    // error does not depend on the map's order.
    let mut failed: Vec<((u32, u32), String)> = Vec::new();
    for (&(u, v), hs) in &groups {
        let forward = hs.iter().filter(|&&h| from(h) == u).count();
        if forward * 2 != hs.len() {
            failed.push((
                (u, v),
                format!(
                    "Voronoi edge {u}-{v} has {forward} of {} half-edges one way: the crust would not be closed and oriented",
                    hs.len()
                ),
            ));
            continue;
        }
        if hs.len() == 2 {
            twin[hs[0]] = hs[1];
            twin[hs[1]] = hs[0];
            continue;
        }
        if let Err(message) = pair_around_edge(u, v, hs, positions, polygons, &face_of, &mut twin) {
            failed.push(((u, v), message));
        }
    }
    if !failed.is_empty() {
        failed.sort_unstable();
        let message = format!("{} (and {} more edges)", failed[0].1, failed.len() - 1);
        return Err(BuildError { message, vertices: failed.iter().flat_map(|((u, v), _)| [*u, *v]).collect() });
    }

    // Vertex umbrellas: the corner at the start of half-edge h continues, around its
    // vertex, at the start of twin(prev(h)).
    let mut corner_vertex = vec![u32::MAX; total];
    let mut mesh = TriMesh::default();
    let mut source: Vec<u32> = Vec::new();
    let mut used = vec![false; positions.len()];
    let mut copies = 0usize;
    for h0 in 0..total {
        if corner_vertex[h0] != u32::MAX {
            continue;
        }
        let v = from(h0);
        let id = mesh.positions.len() as u32;
        mesh.positions.push(positions[v as usize]);
        source.push(v);
        if used[v as usize] {
            copies += 1;
        }
        used[v as usize] = true;
        let mut h = h0;
        loop {
            corner_vertex[h] = id;
            h = twin[prev(h)];
            if h == h0 {
                break;
            }
            if corner_vertex[h] != u32::MAX {
                return Err(BuildError { message: format!("vertex {v}: umbrellas do not close"), vertices: vec![v] });
            }
        }
    }
    // Two sheets that touch along an edge can still share both endpoint copies (the
    // umbrellas at the endpoints connect elsewhere): the paired surface is a manifold, but
    // two of its edges have the same two vertex ids. Every edge of such a group gets its
    // own midpoint vertex, inserted in both of its polygons, so edges are told apart by
    // their ids; the midpoints of one group share a position, so the sheets still meet
    // only at shared vertex positions.
    let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(total / 2);
    let key = |h: usize| {
        let (a, b) = (corner_vertex[h], corner_vertex[twin[h]]);
        (a.min(b), a.max(b))
    };
    for h in 0..total {
        if twin[h] > h {
            *count.entry(key(h)).or_insert(0) += 1;
        }
    }
    let mut midpoint_after = vec![u32::MAX; total];
    let mut computed = vec![false; mesh.positions.len()];
    for h in 0..total {
        let g = twin[h];
        if g < h || count[&key(h)] < 2 {
            continue;
        }
        let (a, b) = (corner_vertex[h], corner_vertex[g]);
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let w = mesh.positions.len() as u32;
        mesh.positions.push([0, 1, 2].map(|k| 0.5 * (pa[k] + pb[k])));
        source.push(source[a as usize]);
        computed.push(true);
        copies += 1;
        midpoint_after[h] = w;
        midpoint_after[g] = w;
    }
    // Triangulate each polygon without new edges that exist elsewhere (convex Voronoi faces
    // share at most an edge, but polygons rebuilt after merging vertices, see `resolve`,
    // may share two corners that are not neighbours) and, in the projection along its
    // dominant normal axis, without a triangle of the wrong orientation or zero area
    // (exact orient2d): rebuilt polygons can be non-convex, with corners bent by an ulp.
    // The best-shaped such triangulation (`triangulate`), else a fan from a new vertex at
    // the centroid.
    let mut taken: HashSet<(u32, u32)> = HashSet::new();
    let mut polys: Vec<Vec<u32>> = Vec::with_capacity(polygons.len());
    for (f, p) in polygons.iter().enumerate() {
        let o = offset[f];
        let mut ids = Vec::with_capacity(p.len() + 1);
        for i in 0..p.len() {
            ids.push(corner_vertex[o + i]);
            if midpoint_after[o + i] != u32::MAX {
                ids.push(midpoint_after[o + i]);
            }
        }
        for i in 0..ids.len() {
            taken.insert(ukey(ids[i], ids[(i + 1) % ids.len()]));
        }
        polys.push(ids);
    }
    let mut tris = Vec::new();
    for ids in &polys {
        tris.clear();
        if triangulate(ids, &mesh.positions, &taken, &mut tris) {
            for &[a, b, c] in &tris {
                for (x, y) in [(a, b), (b, c), (c, a)] {
                    taken.insert(ukey(x, y));
                }
            }
        } else {
            let n = ids.len();
            let w = mesh.positions.len() as u32;
            let c = [0, 1, 2].map(|k| ids.iter().map(|&v| mesh.positions[v as usize][k]).sum::<f64>() / n as f64);
            mesh.positions.push(c);
            source.push(source[ids[0] as usize]);
            computed.push(true);
            copies += 1;
            for k in 0..n {
                tris.push([w, ids[k], ids[(k + 1) % n]]);
            }
        }
        mesh.triangles.extend_from_slice(&tris);
    }
    let num_used = used.iter().filter(|&&u| u).count();
    // Number the vertices in order of first use by the triangles, as readers of OBJ and
    // PLY files number them, so that a written crust reads back as the same mesh.
    let mut new_id = vec![u32::MAX; mesh.positions.len()];
    let mut order: Vec<u32> = Vec::with_capacity(mesh.positions.len());
    for v in mesh.triangles.iter().flatten().copied().chain(0..mesh.positions.len() as u32) {
        if new_id[v as usize] == u32::MAX {
            new_id[v as usize] = order.len() as u32;
            order.push(v);
        }
    }
    mesh.positions = order.iter().map(|&v| mesh.positions[v as usize]).collect();
    let source = order.iter().map(|&v| source[v as usize]).collect();
    let computed = order.iter().map(|&v| computed[v as usize]).collect();
    mesh.triangles.iter_mut().flatten().for_each(|v| *v = new_id[*v as usize]);
    let faces = polys.into_iter().map(|f| f.into_iter().map(|v| new_id[v as usize]).collect()).collect();
    Ok(Built { mesh, num_used, num_split: copies, source, computed, faces })
}

fn ukey(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Triangulate the polygon `ids` (mesh vertex ids, counter-clockwise seen from outside)
/// into `out`: every triangle positively oriented in the projection along the polygon's
/// dominant normal axis (exact orient2d), no new edge in `taken`, and among those
/// triangulations the one whose worst triangle is best shaped (largest smallest
/// [`shape`]). `false` when there is none.
///
/// Why the best-shaped one and not the first fan that is valid: a Voronoi face often has
/// a corner that is all but straight (a short Voronoi edge of a nearly degenerate cluster,
/// or an inserted midpoint). A fan from another corner makes that corner the middle of a
/// sliver whose width is below the rounding of the output's floats, and once rounded the
/// sliver folds onto its neighbours (the crust of the soup in `../shared/meshes`, written
/// as float32, failed so). The best-shaped triangulation uses such a corner as an apex.
///
/// Dynamic programming over the sub-polygons `ids[i..=j]` (Klincsek's optimal polygon
/// triangulation), O(n³) for n corners; Voronoi faces have a handful. Every triangle of a
/// triangulation by diagonals being positively oriented in the projection makes it a
/// triangulation of the (possibly non-convex) polygon: the triangles' signed coverage is
/// the polygon's winding number, so positive triangles cover each inside point once and
/// nothing outside.
fn triangulate(ids: &[u32], positions: &[V], taken: &HashSet<(u32, u32)>, out: &mut Vec<[u32; 3]>) -> bool {
    let n = ids.len();
    if n == 3 {
        out.push([ids[0], ids[1], ids[2]]);
        return true;
    }
    let normal = newell(ids, positions);
    let axis = (0..3).max_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs())).unwrap_or(2);
    if !(normal[axis] != 0.0) {
        return false;
    }
    // Drop `axis`; keep the orientation: (x, y) chosen so that a polygon counter-clockwise
    // about +axis is counter-clockwise in 2D, then flip when the normal points along −axis.
    let flip = normal[axis] < 0.0;
    let pt = |v: u32| {
        let p = positions[v as usize];
        let (x, y) = match axis {
            0 => (p[1], p[2]),
            1 => (p[2], p[0]),
            _ => (p[0], p[1]),
        };
        robust::Coord { x, y: if flip { -y } else { y } }
    };
    let ccw = |a: u32, b: u32, c: u32| robust::orient2d(pt(a), pt(b), pt(c)) > 0.0;
    // A diagonal (not a polygon edge) may not be an edge elsewhere.
    let open = |i: usize, j: usize| j == i + 1 || (i == 0 && j == n - 1) || !taken.contains(&ukey(ids[i], ids[j]));
    // best[i][j]: the best worst shape over triangulations of ids[i..=j] (−1: none), and the
    // apex k of its triangle on the diagonal (i, j).
    let mut best = vec![-1.0f64; n * n];
    let mut apex = vec![usize::MAX; n * n];
    for i in 0..n - 1 {
        best[i * n + i + 1] = f64::INFINITY;
    }
    for len in 2..n {
        for i in 0..n - len {
            let j = i + len;
            if !open(i, j) {
                continue;
            }
            for k in i + 1..j {
                let worst = best[i * n + k].min(best[k * n + j]);
                if !(worst > best[i * n + j]) || !ccw(ids[i], ids[k], ids[j]) {
                    continue;
                }
                let q = worst.min(shape(positions, ids[i], ids[k], ids[j]));
                if q > best[i * n + j] {
                    best[i * n + j] = q;
                    apex[i * n + j] = k;
                }
            }
        }
    }
    if apex[n - 1] == usize::MAX {
        return false;
    }
    let mut stack = vec![(0, n - 1)];
    while let Some((i, j)) = stack.pop() {
        if j <= i + 1 {
            continue;
        }
        let k = apex[i * n + j];
        out.push([ids[i], ids[k], ids[j]]);
        stack.push((i, k));
        stack.push((k, j));
    }
    true
}

/// Shape of a triangle: twice its area over its longest edge squared (the height over
/// the longest edge as a share of that edge: √3/2 for the equilateral, 0 for a degenerate
/// one), in f64. Only ranks triangulations; validity is decided exactly.
fn shape(positions: &[V], a: u32, b: u32, c: u32) -> f64 {
    let [pa, pb, pc] = [a, b, c].map(|v| positions[v as usize]);
    let n = cross(sub(pb, pa), sub(pc, pa));
    let area2 = dot(n, n).sqrt();
    let longest = [sub(pb, pa), sub(pc, pb), sub(pa, pc)].iter().map(|e| dot(*e, *e)).fold(0.0f64, f64::max);
    if longest > 0.0 {
        area2 / longest
    } else {
        0.0
    }
}

/// Pair the 2k half-edges around edge (u, v) by the angle of their faces about the edge.
fn pair_around_edge(
    u: u32,
    v: u32,
    hs: &[usize],
    positions: &[V],
    polygons: &[Vec<u32>],
    face_of: &[u32],
    twin: &mut [usize],
) -> Result<(), String> {
    let pu = positions[u as usize];
    let axis = sub(positions[v as usize], pu);
    // An orthonormal-ish frame (e1, e2) perpendicular to the axis.
    let helper = if axis[0].abs() <= axis[1].abs() && axis[0].abs() <= axis[2].abs() {
        [1.0, 0.0, 0.0]
    } else if axis[1].abs() <= axis[2].abs() {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    let e1 = cross(axis, helper);
    let e2 = cross(axis, e1);
    let mut items: Vec<(f64, bool, usize)> = Vec::with_capacity(hs.len());
    for &h in hs {
        let poly = &polygons[face_of[h] as usize];
        // Direction from the edge into the face: its centroid, projected off the axis.
        let mut c = [0.0; 3];
        for &w in poly {
            let p = positions[w as usize];
            for k in 0..3 {
                c[k] += p[k] / poly.len() as f64;
            }
        }
        let r = sub(c, pu);
        let angle = dot(r, e2).atan2(dot(r, e1));
        // The solid lies on the −normal side of the face. Increasing angle turns by
        // `axis × r`; the inside wedge is at increasing angle when that agrees with −n.
        let n = newell(poly, positions);
        let inside_ccw = dot(cross(axis, r), n) < 0.0;
        items.push((angle, inside_ccw, h));
    }
    items.sort_by(|a, b| a.0.total_cmp(&b.0));
    let m = items.len();
    for i in 0..m {
        let (_, ccw, h) = items[i];
        if !ccw {
            continue;
        }
        let (_, other_ccw, g) = items[(i + 1) % m];
        if other_ccw {
            return Err(format!("faces around Voronoi edge {u}-{v} do not alternate inside/outside"));
        }
        twin[h] = g;
        twin[g] = h;
    }
    if hs.iter().any(|&h| twin[h] == usize::MAX) {
        return Err(format!("could not pair the faces around Voronoi edge {u}-{v}"));
    }
    Ok(())
}
