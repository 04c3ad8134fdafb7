//! The exact checker of the crust's guarantees.
//!
//! Combinatorics come from [`mesh_io::TopologyReport`]; degeneracy and intersections are
//! decided with Shewchuk's exact orientation predicates (robust), so the verdict does not
//! depend on rounding.

use mesh_io::{TopologyReport, TriMesh};
use robust::{orient2d, orient3d, Coord, Coord3D};

type V = [f64; 3];

/// What the checker measured.
#[derive(Clone, Debug, PartialEq)]
pub struct CrustCheck {
    /// The crust's topology (closed, manifold, components, genus, orientation).
    pub report: TopologyReport,
    /// Triangle pairs whose bounding boxes overlap and that share no vertex position.
    pub num_pairs_tested: usize,
    /// Triangle pairs that share one or two vertex positions (an edge), tested for meeting
    /// anywhere else.
    pub num_adjacent_pairs_tested: usize,
}

/// Check a crust: closed (every edge in exactly two triangles, opposite orientations),
/// vertex-manifold, positive volume (unless empty), no degenerate triangle (a repeated
/// vertex or exactly collinear corners), and no two triangles meet where they should not
/// (exact tests): triangles that share no vertex position are disjoint, triangles that
/// share one vertex position meet only there, and triangles that share an edge meet only
/// along it (no fold). Triangles meeting at a split vertex share its position, so they
/// count as adjacent.
///
/// # Errors
/// A message naming the first guarantee that fails.
pub fn check_crust(mesh: &TriMesh) -> Result<CrustCheck, String> {
    find_defects(mesh, true).map_err(|d| d.message)
}

/// Why a mesh failed [`check_crust`]: the message, and the triangles at fault where the
/// failure is geometric (degenerate triangles and both triangles of every meeting pair, or
/// only the first pair when stopping at the first).
#[derive(Clone, Debug)]
pub(crate) struct Defects {
    pub message: String,
    /// Triangle indices at fault (empty for a combinatorial failure).
    pub triangles: Vec<u32>,
    /// Components and genus, when the mesh is closed, manifold and oriented.
    pub topology: Option<(usize, i64)>,
}

/// [`check_crust`], reporting the triangles at fault; with `stop_at_first` false, every
/// degenerate triangle and every meeting pair is listed.
pub(crate) fn find_defects(mesh: &TriMesh, stop_at_first: bool) -> Result<CrustCheck, Defects> {
    let report = TopologyReport::of(mesh);
    let topology = report.genus.map(|g| (report.num_components, g));
    let fail = |message: String| Defects { message, triangles: Vec::new(), topology };
    if mesh.triangles.is_empty() {
        return Ok(CrustCheck { report, num_pairs_tested: 0, num_adjacent_pairs_tested: 0 });
    }
    if !report.is_closed {
        return Err(fail(format!(
            "not closed: {} boundary and {} non-manifold edges",
            report.num_boundary_edges, report.num_non_manifold_edges
        )));
    }
    if !report.is_orientation_consistent {
        return Err(fail("inconsistent orientation: an edge is used twice in the same direction".into()));
    }
    if report.num_non_manifold_vertices > 0 {
        return Err(fail(format!("{} non-manifold vertices", report.num_non_manifold_vertices)));
    }
    let degenerate: Vec<u32> = (0..mesh.triangles.len() as u32).filter(|&t| is_degenerate(mesh, t as usize)).collect();
    if let Some(&first) = degenerate.first() {
        return Err(Defects {
            message: format!(
                "{} degenerate triangles (a repeated vertex or collinear corners), the first {first}",
                degenerate.len()
            ),
            triangles: degenerate,
            topology,
        });
    }
    if !(report.signed_volume > 0.0) {
        return Err(fail(format!("volume {} is not positive", report.signed_volume)));
    }
    let scan = scan(mesh, stop_at_first, true);
    if let Some(&(a, b)) = scan.hits.first() {
        let what = if shared_positions(mesh, a, b) == 0 { "intersect" } else { "overlap beyond their shared vertices" };
        return Err(Defects {
            message: format!("triangles {a} and {b} {what} (exact test)"),
            triangles: scan.hits.iter().flat_map(|&(a, b)| [a as u32, b as u32]).collect(),
            topology,
        });
    }
    Ok(CrustCheck { report, num_pairs_tested: scan.disjoint_tested, num_adjacent_pairs_tested: scan.adjacent_tested })
}

/// Whether triangle `t` has a repeated vertex or exactly collinear corners (the topology
/// report's definition of degenerate).
fn is_degenerate(mesh: &TriMesh, t: usize) -> bool {
    let [i, j, k] = mesh.triangles[t];
    if i == j || j == k || i == k {
        return true;
    }
    let [a, b, c] = [i, j, k].map(|v| mesh.positions[v as usize]);
    collinear(a, b, c)
}

/// Exact collinearity: all three coordinate-plane projections have zero signed area.
fn collinear(a: V, b: V, c: V) -> bool {
    (0..3).all(|k| o2(proj(a, k), proj(b, k), proj(c, k)) == 0)
}

fn shared_positions(mesh: &TriMesh, a: usize, b: usize) -> usize {
    let ta = mesh.triangles[a].map(|i| mesh.positions[i as usize]);
    let tb = mesh.triangles[b].map(|i| mesh.positions[i as usize]);
    ta.iter().filter(|p| tb.contains(p)).count()
}

/// Broad phase on a uniform grid (about one cell per triangle) over the triangles'
/// bounding boxes; a pair is tested once, in the cell holding the lower corner of the
/// intersection of their boxes. Exact tests on the candidate pairs that share no vertex
/// position. Returns the number of pairs tested and the first intersecting pair (stopping
/// there if `stop_at_first`).
///
/// Pairs that share a vertex position are not tested here (see [`check_crust`], which
/// also tests those).
///
/// # Complexity
/// O(F) expected for evenly sized triangles, plus the exact tests.
pub fn self_intersections(mesh: &TriMesh, stop_at_first: bool) -> (usize, Option<(usize, usize)>) {
    let s = scan(mesh, stop_at_first, false);
    (s.disjoint_tested, s.hits.first().copied())
}

struct Scan {
    disjoint_tested: usize,
    adjacent_tested: usize,
    /// Meeting pairs (a < b), sorted; only the first found when stopping at the first.
    hits: Vec<(usize, usize)>,
}

/// The broad phase of [`self_intersections`]; with `adjacent`, pairs sharing one or two
/// vertex positions are tested too ([`adjacent_overlap`]) and pairs sharing three count
/// as meeting. Degenerate triangles are skipped when `adjacent` (the caller reports them).
fn scan(mesh: &TriMesh, stop_at_first: bool, adjacent: bool) -> Scan {
    let n = mesh.triangles.len();
    let mut out = Scan { disjoint_tested: 0, adjacent_tested: 0, hits: Vec::new() };
    let corners: Vec<[V; 3]> = mesh.triangles.iter().map(|t| t.map(|i| mesh.positions[i as usize])).collect();
    let tri = |t: usize| corners[t];
    let boxes: Vec<(V, V)> = (0..n)
        .map(|t| {
            let c = tri(t);
            let lo = [0, 1, 2].map(|k| c[0][k].min(c[1][k]).min(c[2][k]));
            let hi = [0, 1, 2].map(|k| c[0][k].max(c[1][k]).max(c[2][k]));
            (lo, hi)
        })
        .collect();
    if n < 2 {
        return out;
    }
    let skip: Vec<bool> = if adjacent { (0..n).map(|t| is_degenerate(mesh, t)).collect() } else { vec![false; n] };
    // One id per distinct position (−0.0 and 0.0 alike), so that shared positions are found
    // by comparing integers.
    let mut id_of: std::collections::HashMap<[u64; 3], u32> =
        std::collections::HashMap::with_capacity(mesh.positions.len());
    let position_id: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let next = id_of.len() as u32;
            *id_of.entry(p.map(|c| if c == 0.0 { 0 } else { c.to_bits() })).or_insert(next)
        })
        .collect();
    drop(id_of);
    let pid: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|i| position_id[i as usize])).collect();
    let (lo, hi) = mesh.bounding_box();
    let res = ((n as f64).cbrt().ceil() as usize).clamp(1, 512);
    let size = [0, 1, 2].map(|k| ((hi[k] - lo[k]) / res as f64).max(f64::MIN_POSITIVE));
    let cell = |p: V, k: usize| (((p[k] - lo[k]) / size[k]) as usize).min(res - 1);
    // Cells in (i, j, k) lexicographic order as one index; triangles bucketed by a
    // counting sort (compressed rows).
    let index = |i: usize, j: usize, k: usize| (i * res + j) * res + k;
    let range = |t: usize| {
        let (blo, bhi) = boxes[t];
        [0, 1, 2].map(|k| (cell(blo, k), cell(bhi, k)))
    };
    let mut start = vec![0u32; res * res * res + 1];
    for t in (0..n).filter(|&t| !skip[t]) {
        let r = range(t);
        for i in r[0].0..=r[0].1 {
            for j in r[1].0..=r[1].1 {
                for k in r[2].0..=r[2].1 {
                    start[index(i, j, k) + 1] += 1;
                }
            }
        }
    }
    for c in 1..start.len() {
        start[c] += start[c - 1];
    }
    let mut fill = start.clone();
    let mut members = vec![0u32; start[start.len() - 1] as usize];
    for t in (0..n).filter(|&t| !skip[t]) {
        let r = range(t);
        for i in r[0].0..=r[0].1 {
            for j in r[1].0..=r[1].1 {
                for k in r[2].0..=r[2].1 {
                    let c = index(i, j, k);
                    members[fill[c] as usize] = t as u32;
                    fill[c] += 1;
                }
            }
        }
    }
    for key in 0..res * res * res {
        let ts = &mut members[start[key] as usize..start[key + 1] as usize];
        // Sorted by the lower x of their boxes, so the scan of a triangle's partners stops
        // at the first that starts beyond it.
        ts.sort_unstable_by(|&a, &b| boxes[a as usize].0[0].total_cmp(&boxes[b as usize].0[0]).then(a.cmp(&b)));
        let ts = &*ts;
        for (x, &a) in ts.iter().enumerate() {
            let (alo, ahi) = boxes[a as usize];
            for &b in &ts[x + 1..] {
                let (blo, bhi) = boxes[b as usize];
                if blo[0] > ahi[0] {
                    break;
                }
                if (1..3).any(|k| blo[k] > ahi[k] || bhi[k] < alo[k]) {
                    continue;
                }
                let corner = [0, 1, 2].map(|k| alo[k].max(blo[k]));
                if index(cell(corner, 0), cell(corner, 1), cell(corner, 2)) != key {
                    continue; // tested in another cell
                }
                let (ta, tb) = (tri(a as usize), tri(b as usize));
                let (ia, ib) = (pid[a as usize], pid[b as usize]);
                let meet = if ia.iter().any(|p| ib.contains(p)) {
                    if !adjacent {
                        continue;
                    }
                    out.adjacent_tested += 1;
                    adjacent_overlap(ta, tb)
                } else {
                    out.disjoint_tested += 1;
                    triangles_intersect(ta, tb)
                };
                if meet {
                    out.hits.push(((a.min(b)) as usize, (a.max(b)) as usize));
                    if stop_at_first {
                        return out;
                    }
                }
            }
        }
    }
    out.hits.sort_unstable();
    out
}

/// Exact test for non-degenerate triangles that share one or more vertex positions: do
/// they meet anywhere but at their shared vertices and the edge between them?
pub fn adjacent_overlap(a: [V; 3], b: [V; 3]) -> bool {
    let mut shared = [(0usize, 0usize); 3];
    let mut count = 0;
    for i in 0..3 {
        if let Some(j) = (0..3).find(|&j| b[j] == a[i]) {
            shared[count] = (i, j);
            count += 1;
        }
    }
    let shared = &shared[..count];
    match count {
        0 => triangles_intersect(a, b),
        1 => {
            let (i, j) = shared[0];
            let p = a[i];
            let (a1, a2) = (a[(i + 1) % 3], a[(i + 2) % 3]);
            let (b1, b2) = (b[(j + 1) % 3], b[(j + 2) % 3]);
            // Their intersection is convex and holds p, so it holds more iff their angles at
            // p overlap. First in a projection where both are non-degenerate (cheap and
            // conclusive for the common case of neighbours in one plane, where orient3d
            // needs its exact stages): if the projected angles are disjoint, so are the
            // triangles beyond p.
            let k = dominant_axis(a);
            let pp = proj(p, k);
            let [pa1, pa2, pb1, pb2] = [a1, a2, b1, b2].map(|x| proj(x, k));
            let (sa, sb) = (o2(pp, pa1, pa2), o2(pp, pb1, pb2));
            if sa != 0 && sb != 0 {
                let in_a = |x| o2(pp, pa1, x) * sa >= 0 && o2(pp, x, pa2) * sa >= 0;
                let in_b = |x| o2(pp, pb1, x) * sb >= 0 && o2(pp, x, pb2) * sb >= 0;
                if !in_a(pb1) && !in_a(pb2) && !in_b(pa1) && !in_b(pa2) {
                    return false;
                }
            }
            // If a1 and a2 lie strictly on one side of b's
            // plane, a meets that plane only at p (and likewise the other way round).
            let (sa1, sa2) = (o3(p, b1, b2, a1), o3(p, b1, b2, a2));
            if sa1 * sa2 > 0 {
                return false;
            }
            let (sb1, sb2) = (o3(p, a1, a2, b1), o3(p, a1, a2, b2));
            if sb1 * sb2 > 0 {
                return false;
            }
            // Otherwise they meet elsewhere iff the edge opposite p in one meets the other,
            // or an edge at p runs into the other (it then lies in the other's plane,
            // inside its angle at p).
            segment_meets_triangle(a1, a2, b)
                || segment_meets_triangle(b1, b2, a)
                || (sa1 == 0 && in_angle(p, b1, b2, a1))
                || (sa2 == 0 && in_angle(p, b1, b2, a2))
                || (sb1 == 0 && in_angle(p, a1, a2, b1))
                || (sb2 == 0 && in_angle(p, a1, a2, b2))
        }
        2 => {
            // A shared edge (p, q): the triangles meet elsewhere iff they are coplanar and
            // lie on the same side of it (a fold).
            let (p, q) = (a[shared[0].0], a[shared[1].0]);
            let x = a[(0..3).find(|&i| shared.iter().all(|s| s.0 != i)).unwrap_or(0)];
            let y = b[(0..3).find(|&j| shared.iter().all(|s| s.1 != j)).unwrap_or(0)];
            // Strictly opposite sides in a projection: no fold, coplanar or not.
            let k = dominant_axis(a);
            let (sx, sy) = (o2(proj(p, k), proj(q, k), proj(x, k)), o2(proj(p, k), proj(q, k), proj(y, k)));
            if sx * sy < 0 {
                return false;
            }
            if o3(p, q, x, y) != 0 {
                return false;
            }
            let k = (0..3).find(|&k| o2(proj(p, k), proj(q, k), proj(x, k)) != 0).unwrap_or(2);
            o2(proj(p, k), proj(q, k), proj(x, k)) == o2(proj(p, k), proj(q, k), proj(y, k))
        }
        _ => true,
    }
}

/// The axis along which triangle `t`'s (f64) normal is largest: dropping it gives a
/// projection where `t` is not degenerate unless it is nearly so.
fn dominant_axis(t: [V; 3]) -> usize {
    let (u, v) = ([0, 1, 2].map(|k| t[1][k] - t[0][k]), [0, 1, 2].map(|k| t[2][k] - t[0][k]));
    let n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    if n[0].abs() >= n[1].abs() && n[0].abs() >= n[2].abs() {
        0
    } else if n[1].abs() >= n[2].abs() {
        1
    } else {
        2
    }
}

/// For `x` in the plane of the non-degenerate triangle (p, b1, b2): does `x` lie in the
/// closed angle of the triangle at p (so the segment p→x enters the triangle)?
fn in_angle(p: V, b1: V, b2: V, x: V) -> bool {
    let k = (0..3).find(|&k| o2(proj(p, k), proj(b1, k), proj(b2, k)) != 0).unwrap_or(2);
    let (p, b1, b2, x) = (proj(p, k), proj(b1, k), proj(b2, k), proj(x, k));
    let s = o2(p, b1, b2);
    o2(p, b1, x) * s >= 0 && o2(p, x, b2) * s >= 0
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

    #[test]
    fn triangles_sharing_vertices_meet_only_there_unless_they_fold_or_cross() {
        let (o, x, y, z) = ([0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]);
        // A shared edge: opposite sides in one plane, a dihedral angle, a fold.
        assert!(!adjacent_overlap([o, x, y], [x, o, [0., -1., 0.]]));
        assert!(!adjacent_overlap([o, x, y], [x, o, z]));
        assert!(adjacent_overlap([o, x, y], [x, o, [0.5, 0.5, 0.]]));
        // One shared vertex: disjoint angles in one plane; overlapping angles; a shared
        // ray; crossing through each other; an edge running into the other in its plane.
        assert!(!adjacent_overlap([o, x, y], [o, [-1., 0., 0.], [0., -1., 0.]]));
        assert!(adjacent_overlap([o, x, y], [o, [1., 1., 0.], [-1., 2., 0.]]));
        assert!(adjacent_overlap([o, x, y], [o, [2., 0., 0.], [0., -1., 0.]]));
        assert!(adjacent_overlap([o, x, y], [o, [0.3, 0.3, -1.], [0.3, 0.3, 1.]]));
        assert!(adjacent_overlap([o, x, y], [o, [0.5, 0.2, 0.], z]));
        assert!(!adjacent_overlap([o, x, y], [o, [-0.5, -0.2, 0.], z]));
        assert!(!adjacent_overlap([o, x, y], [o, z, [-1., 0., 1.]]));
        // The same triangle twice (either orientation).
        assert!(adjacent_overlap([o, x, y], [o, y, x]));
    }
}
