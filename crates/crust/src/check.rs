//! The exact checker of the crust's guarantees.
//!
//! Combinatorics come from [`mesh_io::TopologyReport`]; self-intersection is decided with
//! Shewchuk's exact orientation predicates (robust), so the verdict does not depend on
//! rounding.

use mesh_io::{TopologyReport, TriMesh};
use robust::{orient2d, orient3d, Coord, Coord3D};

type V = [f64; 3];

/// What the checker measured.
#[derive(Clone, Debug, PartialEq)]
pub struct CrustCheck {
    pub report: TopologyReport,
    /// Triangle pairs whose bounding boxes overlap and that share no vertex position.
    pub num_pairs_tested: usize,
}

/// Check a crust: closed (every edge in exactly two triangles, opposite orientations),
/// vertex-manifold, positive volume (unless empty), and no two triangles that share no
/// vertex position intersect (exact test). Triangles meeting at a split vertex share its
/// position, so they count as adjacent.
///
/// # Errors
/// A message naming the first guarantee that fails.
pub fn check_crust(mesh: &TriMesh) -> Result<CrustCheck, String> {
    let report = TopologyReport::of(mesh);
    if mesh.triangles.is_empty() {
        return Ok(CrustCheck { report, num_pairs_tested: 0 });
    }
    if !report.is_closed {
        return Err(format!(
            "not closed: {} boundary and {} non-manifold edges",
            report.num_boundary_edges, report.num_non_manifold_edges
        ));
    }
    if !report.is_orientation_consistent {
        return Err("inconsistent orientation: an edge is used twice in the same direction".into());
    }
    if report.num_non_manifold_vertices > 0 {
        return Err(format!("{} non-manifold vertices", report.num_non_manifold_vertices));
    }
    if !(report.signed_volume > 0.0) {
        return Err(format!("volume {} is not positive", report.signed_volume));
    }
    let (num_pairs_tested, hit) = self_intersections(mesh, true);
    if let Some((a, b)) = hit {
        return Err(format!("triangles {a} and {b} intersect (exact test)"));
    }
    Ok(CrustCheck { report, num_pairs_tested })
}

/// Broad phase on a uniform grid (about one cell per triangle) over the triangles'
/// bounding boxes; a pair is tested once, in the cell holding the lower corner of the
/// intersection of their boxes. Exact tests on the candidate pairs that share no vertex
/// position. Returns the number of pairs tested and the first intersecting pair (stopping
/// there if `stop_at_first`).
///
/// # Complexity
/// O(F) expected for evenly sized triangles, plus the exact tests.
pub fn self_intersections(mesh: &TriMesh, stop_at_first: bool) -> (usize, Option<(usize, usize)>) {
    let n = mesh.triangles.len();
    let tri = |t: usize| mesh.triangles[t].map(|i| mesh.positions[i as usize]);
    let boxes: Vec<(V, V)> = (0..n)
        .map(|t| {
            let c = tri(t);
            let lo = [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k]));
            let hi = [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k]));
            (lo, hi)
        })
        .collect();
    if n < 2 {
        return (0, None);
    }
    let (lo, hi) = mesh.bounding_box();
    let res = ((n as f64).cbrt().ceil() as usize).clamp(1, 512);
    let size = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / res as f64).max(f64::MIN_POSITIVE));
    let cell = |p: V, k: usize| (((p[k] - lo[k]) / size[k]) as usize).min(res - 1);
    let mut buckets: std::collections::HashMap<(usize, usize, usize), Vec<u32>> = std::collections::HashMap::new();
    for (t, (blo, bhi)) in boxes.iter().enumerate() {
        for i in cell(*blo, 0)..=cell(*bhi, 0) {
            for j in cell(*blo, 1)..=cell(*bhi, 1) {
                for k in cell(*blo, 2)..=cell(*bhi, 2) {
                    buckets.entry((i, j, k)).or_default().push(t as u32);
                }
            }
        }
    }
    let mut keys: Vec<_> = buckets.keys().copied().collect();
    keys.sort_unstable();
    let mut tested = 0;
    let mut first: Option<(usize, usize)> = None;
    for key in keys {
        let ts = &buckets[&key];
        for (x, &a) in ts.iter().enumerate() {
            let (alo, ahi) = boxes[a as usize];
            for &b in &ts[x + 1..] {
                let (blo, bhi) = boxes[b as usize];
                if (0..3).any(|k| blo[k] > ahi[k] || bhi[k] < alo[k]) {
                    continue;
                }
                let corner = [0, 1, 2].map(|k| alo[k].max(blo[k]));
                if (cell(corner, 0), cell(corner, 1), cell(corner, 2)) != key {
                    continue; // tested in another cell
                }
                let (ta, tb) = (tri(a as usize), tri(b as usize));
                if ta.iter().any(|p| tb.iter().any(|q| p == q)) {
                    continue;
                }
                tested += 1;
                if triangles_intersect(ta, tb) {
                    let pair = ((a.min(b)) as usize, (a.max(b)) as usize);
                    if first.is_none_or(|f| pair < f) {
                        first = Some(pair);
                    }
                    if stop_at_first {
                        return (tested, first);
                    }
                }
            }
        }
    }
    (tested, first)
}

fn c3(p: V) -> Coord3D<f64> {
    Coord3D { x: p[0], y: p[1], z: p[2] }
}

fn sign(x: f64) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

fn o3(a: V, b: V, c: V, d: V) -> i8 {
    sign(orient3d(c3(a), c3(b), c3(c), c3(d)))
}

/// Exact test: do the closed triangles `a` and `b` share a point?
pub fn triangles_intersect(a: [V; 3], b: [V; 3]) -> bool {
    let sb = b.map(|p| o3(a[0], a[1], a[2], p));
    if sb.iter().all(|&s| s > 0) || sb.iter().all(|&s| s < 0) {
        return false;
    }
    let sa = a.map(|p| o3(b[0], b[1], b[2], p));
    if sa.iter().all(|&s| s > 0) || sa.iter().all(|&s| s < 0) {
        return false;
    }
    if sb.iter().all(|&s| s == 0) {
        return coplanar_intersect(a, b);
    }
    // Not coplanar: they meet iff an edge of one meets the other.
    (0..3).any(|k| segment_meets_triangle(a[k], a[(k + 1) % 3], b))
        || (0..3).any(|k| segment_meets_triangle(b[k], b[(k + 1) % 3], a))
}

fn segment_meets_triangle(p: V, q: V, t: [V; 3]) -> bool {
    let (op, oq) = (o3(t[0], t[1], t[2], p), o3(t[0], t[1], t[2], q));
    if op * oq > 0 {
        return false;
    }
    if op == 0 && oq == 0 {
        return coplanar_intersect([p, q, q], t);
    }
    let s = [o3(p, q, t[0], t[1]), o3(p, q, t[1], t[2]), o3(p, q, t[2], t[0])];
    s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
}

/// Coplanar closed triangles (or a segment given as a degenerate triangle) in a
/// projection where the plane does not degenerate.
fn coplanar_intersect(a: [V; 3], b: [V; 3]) -> bool {
    let drop_axis = (0..3)
        .find(|&k| {
            let proj = |p: V| proj(p, k);
            orient2d(proj(b[0]), proj(b[1]), proj(b[2])) != 0.0 || orient2d(proj(a[0]), proj(a[1]), proj(a[2])) != 0.0
        })
        .unwrap_or(2);
    let pa = a.map(|p| proj(p, drop_axis));
    let pb = b.map(|p| proj(p, drop_axis));
    for i in 0..3 {
        for j in 0..3 {
            if segments_meet(pa[i], pa[(i + 1) % 3], pb[j], pb[(j + 1) % 3]) {
                return true;
            }
        }
    }
    point_in_triangle(pa[0], pb) || point_in_triangle(pb[0], pa)
}

fn proj(p: V, drop_axis: usize) -> Coord<f64> {
    match drop_axis {
        0 => Coord { x: p[1], y: p[2] },
        1 => Coord { x: p[2], y: p[0] },
        _ => Coord { x: p[0], y: p[1] },
    }
}

fn o2(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>) -> i8 {
    sign(orient2d(a, b, c))
}

fn on_segment(a: Coord<f64>, b: Coord<f64>, p: Coord<f64>) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

fn segments_meet(a: Coord<f64>, b: Coord<f64>, c: Coord<f64>, d: Coord<f64>) -> bool {
    let (d1, d2, d3, d4) = (o2(a, b, c), o2(a, b, d), o2(c, d, a), o2(c, d, b));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    (d1 == 0 && on_segment(a, b, c))
        || (d2 == 0 && on_segment(a, b, d))
        || (d3 == 0 && on_segment(c, d, a))
        || (d4 == 0 && on_segment(c, d, b))
}

fn point_in_triangle(p: Coord<f64>, t: [Coord<f64>; 3]) -> bool {
    let s = [o2(t[0], t[1], p), o2(t[1], t[2], p), o2(t[2], t[0], p)];
    if s.iter().all(|&x| x == 0) {
        return false; // degenerate triangle: covered by the segment tests
    }
    s.iter().all(|&x| x >= 0) || s.iter().all(|&x| x <= 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossing_touching_and_separate_triangles() {
        let t = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]];
        assert!(triangles_intersect(t, [[0.2, 0.2, -1.], [0.2, 0.2, 1.], [2., 2., 0.5]]));
        assert!(!triangles_intersect(t, [[0., 0., 1.], [1., 0., 1.], [0., 1., 1.]]));
        // Touching at a point exactly (vertex on the other's edge).
        assert!(triangles_intersect(t, [[0.5, 0., 0.], [0.5, -1., 1.], [0.5, -1., -1.]]));
        // Coplanar, overlapping and disjoint.
        assert!(triangles_intersect(t, [[0.1, 0.1, 0.], [2., 0.1, 0.], [0.1, 2., 0.]]));
        assert!(!triangles_intersect(t, [[1., 1., 0.], [2., 1., 0.], [1., 2., 0.]]));
    }
}
