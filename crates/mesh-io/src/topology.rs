//! The topology report: what a geometry person checks before trusting a mesh.
//!
//! Definitions follow trimesh where it has the same quantity (closedness, winding
//! consistency, Euler number, body count, volume), so the reference checks can compare
//! them one for one.

use crate::dsu::Dsu;
use serde::Serialize;

use crate::TriMesh;

/// Topology and geometry summary of a [`TriMesh`].
///
/// The JSON form (field names and meanings) is part of the CLI's stable interface; new
/// fields may be added, none is renamed or removed without bumping `format_version`.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct TopologyReport {
    /// Version of this report's JSON layout.
    pub format_version: u32,
    /// Vertices after exact welding, including unreferenced ones.
    pub num_vertices: usize,
    /// Vertices used by at least one face.
    pub num_referenced_vertices: usize,
    /// Triangles.
    pub num_faces: usize,
    /// Distinct undirected edges.
    pub num_edges: usize,
    /// Faces with a repeated vertex or three exactly collinear corners (exact predicate).
    pub num_degenerate_faces: usize,
    /// Faces whose vertex set equals that of an earlier face (either orientation).
    pub num_duplicate_faces: usize,
    /// Edges used by exactly one face.
    pub num_boundary_edges: usize,
    /// Connected cycles of boundary edges (holes).
    pub num_boundary_loops: usize,
    /// Edges used by three or more faces.
    pub num_non_manifold_edges: usize,
    /// Vertices whose faces form more than one edge-connected fan (bow-ties).
    pub num_non_manifold_vertices: usize,
    /// Connected components through shared vertices (trimesh's `body_count`).
    pub num_components: usize,
    /// V − E + F over referenced vertices (trimesh's `euler_number`).
    pub euler_characteristic: i64,
    /// Total genus, Σ over components; only for closed, manifold, consistently oriented
    /// meshes, otherwise `null`.
    pub genus: Option<i64>,
    /// Every edge has exactly two faces (trimesh's `is_watertight`).
    pub is_closed: bool,
    /// No non-manifold edge and no non-manifold vertex.
    pub is_manifold: bool,
    /// Every edge with exactly two faces is traversed in opposite directions by them
    /// (trimesh's `is_winding_consistent`).
    pub is_orientation_consistent: bool,
    /// Σ over faces of det(a, b, c) / 6 (the origin as reference point, as trimesh), in the
    /// file's units cubed; positive for a closed mesh oriented counter-clockwise seen from
    /// outside. For an open mesh it depends on where the origin is.
    pub signed_volume: f64,
    /// Total triangle area, in the file's units squared.
    pub surface_area: f64,
    /// Bounding box of the referenced vertices: lower corner.
    pub bbox_min: [f64; 3],
    /// Upper corner.
    pub bbox_max: [f64; 3],
}

/// Exact collinearity of three points: all three coordinate-plane projections have zero
/// signed area (Shewchuk's adaptive orient2d, exact for finite doubles).
pub fn collinear(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> bool {
    let o = |i: usize, j: usize| {
        robust::orient2d(
            robust::Coord { x: a[i], y: a[j] },
            robust::Coord { x: b[i], y: b[j] },
            robust::Coord { x: c[i], y: c[j] },
        )
    };
    o(0, 1) == 0.0 && o(1, 2) == 0.0 && o(2, 0) == 0.0
}

impl TopologyReport {
    /// Compute the report.
    ///
    /// # Complexity
    /// O(F log F) time (edge sort), O(V + F) memory.
    pub fn of(mesh: &TriMesh) -> TopologyReport {
        let nv = mesh.positions.len();
        let nf = mesh.triangles.len();
        let referenced = referenced_vertices(mesh);
        let num_referenced_vertices = referenced.iter().filter(|&&r| r).count();
        let edges = EdgeSummary::of(mesh);
        let num_non_manifold_vertices = count_non_manifold_vertices(mesh, edges.corner_dsu);
        let num_components = count_components(mesh, &referenced);

        let euler_characteristic = num_referenced_vertices as i64 - edges.num_edges as i64 + nf as i64;
        let is_closed = nf > 0 && edges.num_boundary_edges == 0 && edges.num_non_manifold_edges == 0;
        let is_manifold = edges.num_non_manifold_edges == 0 && num_non_manifold_vertices == 0;
        let is_orientation_consistent = nf > 0 && edges.orientation_ok;
        let twice_genus = 2 * num_components as i64 - euler_characteristic;
        let genus =
            (is_closed && is_manifold && is_orientation_consistent && twice_genus % 2 == 0).then_some(twice_genus / 2);

        let (bbox_min, bbox_max) = referenced_bounding_box(mesh, &referenced);
        let (signed_volume, surface_area) = volume_and_area(mesh, bbox_min, bbox_max);

        TopologyReport {
            format_version: 1,
            num_vertices: nv,
            num_referenced_vertices,
            num_faces: nf,
            num_edges: edges.num_edges,
            num_degenerate_faces: count_degenerate_faces(mesh),
            num_duplicate_faces: count_duplicate_faces(mesh),
            num_boundary_edges: edges.num_boundary_edges,
            num_boundary_loops: edges.num_boundary_loops,
            num_non_manifold_edges: edges.num_non_manifold_edges,
            num_non_manifold_vertices,
            num_components,
            euler_characteristic,
            genus,
            is_closed,
            is_manifold,
            is_orientation_consistent,
            signed_volume,
            surface_area,
            bbox_min,
            bbox_max,
        }
    }
}

/// Which vertices some face uses.
fn referenced_vertices(mesh: &TriMesh) -> Vec<bool> {
    let mut referenced = vec![false; mesh.positions.len()];
    for t in &mesh.triangles {
        for &i in t {
            referenced[i as usize] = true;
        }
    }
    referenced
}

/// Faces with a repeated vertex or three exactly collinear corners.
fn count_degenerate_faces(mesh: &TriMesh) -> usize {
    let p = &mesh.positions;
    mesh.triangles
        .iter()
        .filter(|t| {
            t[0] == t[1]
                || t[1] == t[2]
                || t[0] == t[2]
                || collinear(p[t[0] as usize], p[t[1] as usize], p[t[2] as usize])
        })
        .count()
}

/// Faces whose vertex set equals that of an earlier face.
fn count_duplicate_faces(mesh: &TriMesh) -> usize {
    let mut sorted_faces: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| {
            let mut s = *t;
            s.sort_unstable();
            s
        })
        .collect();
    sorted_faces.sort_unstable();
    sorted_faces.windows(2).filter(|w| w[0] == w[1]).count()
}

/// What one pass over the sorted half-edges finds.
struct EdgeSummary {
    num_edges: usize,
    num_boundary_edges: usize,
    num_boundary_loops: usize,
    num_non_manifold_edges: usize,
    orientation_ok: bool,
    /// Corners `3·face + slot`, joined when they meet at a vertex across a shared edge:
    /// each class is one fan.
    corner_dsu: Dsu,
}

impl EdgeSummary {
    fn of(mesh: &TriMesh) -> EdgeSummary {
        let nv = mesh.positions.len();
        let half = sorted_half_edges(mesh);
        let mut s = EdgeSummary {
            num_edges: 0,
            num_boundary_edges: 0,
            num_boundary_loops: 0,
            num_non_manifold_edges: 0,
            orientation_ok: true,
            corner_dsu: Dsu::new(3 * mesh.triangles.len()),
        };
        let mut boundary_dsu = Dsu::new(nv);
        let mut boundary_vertex = vec![false; nv];
        let corner = |f: u32, v: u32| -> u32 {
            let t = mesh.triangles[f as usize];
            let slot = t.iter().position(|&x| x == v).unwrap_or(0) as u32;
            3 * f + slot
        };
        for group in half.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1) {
            let (a, b) = (group[0].0, group[0].1);
            s.num_edges += 1;
            match group.len() {
                1 => {
                    s.num_boundary_edges += 1;
                    boundary_dsu.union(a, b);
                    boundary_vertex[a as usize] = true;
                    boundary_vertex[b as usize] = true;
                }
                2 => {
                    if group[0].3 == group[1].3 {
                        s.orientation_ok = false;
                    }
                }
                _ => s.num_non_manifold_edges += 1,
            }
            if a != b {
                for w in group.windows(2) {
                    s.corner_dsu.union(corner(w[0].2, a), corner(w[1].2, a));
                    s.corner_dsu.union(corner(w[0].2, b), corner(w[1].2, b));
                }
            }
        }
        s.num_boundary_loops =
            (0..nv as u32).filter(|&v| boundary_vertex[v as usize] && boundary_dsu.find(v) == v).count();
        s
    }
}

/// The edges used by exactly one triangle (the rims of holes and open parts), as
/// `(min, max)` vertex pairs in sorted order (search them with `binary_search`).
pub fn boundary_edges(mesh: &TriMesh) -> Vec<(u32, u32)> {
    let half = sorted_half_edges(mesh);
    half.chunk_by(|x, y| x.0 == y.0 && x.1 == y.1).filter(|g| g.len() == 1).map(|g| (g[0].0, g[0].1)).collect()
}

/// Directed half-edges `(min, max, face, forward?)`, sorted by their undirected key.
fn sorted_half_edges(mesh: &TriMesh) -> Vec<(u32, u32, u32, bool)> {
    let mut half: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(3 * mesh.triangles.len());
    for (f, t) in mesh.triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            half.push((a.min(b), a.max(b), f as u32, a < b));
        }
    }
    half.sort_unstable();
    half
}

/// Vertices whose corners fall in more than one fan (distinct corner roots).
fn count_non_manifold_vertices(mesh: &TriMesh, mut corner_dsu: Dsu) -> usize {
    let nv = mesh.positions.len();
    let mut fan_root = vec![u32::MAX; nv];
    let mut non_manifold_vertex = vec![false; nv];
    for (f, t) in mesh.triangles.iter().enumerate() {
        for (slot, &v) in t.iter().enumerate() {
            if t[..slot].contains(&v) {
                continue; // a repeated corner of a degenerate face
            }
            let r = corner_dsu.find(3 * f as u32 + slot as u32);
            let fr = &mut fan_root[v as usize];
            if *fr == u32::MAX {
                *fr = r;
            } else if *fr != r {
                non_manifold_vertex[v as usize] = true;
            }
        }
    }
    non_manifold_vertex.iter().filter(|&&b| b).count()
}

/// Connected components through shared vertices, over referenced vertices.
fn count_components(mesh: &TriMesh, referenced: &[bool]) -> usize {
    let nv = mesh.positions.len();
    let mut comp = Dsu::new(nv);
    for t in &mesh.triangles {
        comp.union(t[0], t[1]);
        comp.union(t[1], t[2]);
    }
    (0..nv as u32).filter(|&v| referenced[v as usize] && comp.find(v) == v).count()
}

/// Bounding box of the referenced vertices.
fn referenced_bounding_box(mesh: &TriMesh, referenced: &[bool]) -> ([f64; 3], [f64; 3]) {
    let mut bbox_min = [f64::INFINITY; 3];
    let mut bbox_max = [f64::NEG_INFINITY; 3];
    for (q, _) in mesh.positions.iter().zip(referenced).filter(|(_, &r)| r) {
        for k in 0..3 {
            bbox_min[k] = bbox_min[k].min(q[k]);
            bbox_max[k] = bbox_max[k].max(q[k]);
        }
    }
    (bbox_min, bbox_max)
}

/// Signed volume (the origin as reference point) and surface area.
fn volume_and_area(mesh: &TriMesh, bbox_min: [f64; 3], bbox_max: [f64; 3]) -> (f64, f64) {
    let p = &mesh.positions;
    // Volume and area relative to the box centre, which keeps the determinants small.
    let c = [0, 1, 2].map(|k| 0.5 * (bbox_min[k] + bbox_max[k]));
    let mut volume = 0.0;
    let mut area = 0.0;
    let mut normal_sum = [0.0; 3];
    for t in &mesh.triangles {
        let [a, b, d] = t.map(|i| {
            let q = p[i as usize];
            [q[0] - c[0], q[1] - c[1], q[2] - c[2]]
        });
        let cross = [b[1] * d[2] - b[2] * d[1], b[2] * d[0] - b[0] * d[2], b[0] * d[1] - b[1] * d[0]];
        volume += a[0] * cross[0] + a[1] * cross[1] + a[2] * cross[2];
        let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let e2 = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        let n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        area += 0.5 * (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        for k in 0..3 {
            normal_sum[k] += n[k];
        }
    }
    // Back to the origin as the reference point (trimesh's convention), exactly:
    // det(a, b, d) = det(a', b', d') + c · ((b' − a') × (d' − a')) for a' = a − c.
    // Σ N is zero on a closed mesh, so only open meshes, whose "volume" depends on the
    // reference point anyway, are affected.
    if !mesh.triangles.is_empty() {
        volume += c[0] * normal_sum[0] + c[1] * normal_sum[1] + c[2] * normal_sum[2];
    }
    (volume / 6.0, area)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tetrahedron has no boundary edge; without its last face, the three edges of the
    /// hole are the boundary, sorted.
    #[test]
    fn boundary_edges_are_the_rim_of_the_hole() {
        let positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let closed = TriMesh { positions, triangles: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]] };
        assert!(boundary_edges(&closed).is_empty());
        let open = TriMesh { positions: closed.positions.clone(), triangles: closed.triangles[..3].to_vec() };
        assert_eq!(boundary_edges(&open), vec![(0, 2), (0, 3), (2, 3)]);
    }
}
