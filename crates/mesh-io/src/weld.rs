//! Welding: exactly coincident positions always, positions within a tolerance on request.
//!
//! tobj's merging option needs a nightly feature, and STL stores every triangle's corners
//! separately, so every reader's output goes through [`weld_exact`].
//!
//! CAD exports often have hairline cracks: two copies of a vertex a few float32 ulps apart,
//! so exact welding leaves boundary loops where the part is really closed.
//! [`weld_tolerance`] merges such vertices and [`count_near_pairs`] counts them, so that
//! `info` can suggest it.
//!
//! **Tolerances are relative to the bounding-box diagonal** everywhere in this module and
//! on the command line (`--weld-tolerance 1e-6` merges vertices at most 1e-6 × diagonal
//! apart): the same value means the same thing for a part in millimetres and in metres,
//! and it compares directly with float32 rounding (about 6e-8 relative).

use crate::dsu::Dsu;
use std::collections::HashMap;

use serde::Serialize;

use crate::TriMesh;

/// Merge vertices whose coordinates are bitwise equal (with -0.0 taken as 0.0), keeping
/// the first occurrence's index order. Triangles are kept as they are, even when welding
/// makes them degenerate: the topology report counts those.
///
/// # Complexity
/// O(V + F) expected time (hashing).
pub fn weld_exact(mesh: &TriMesh) -> TriMesh {
    let key = |p: &[f64; 3]| p.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
    let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let mut remap = Vec::with_capacity(mesh.positions.len());
    let mut positions = Vec::with_capacity(mesh.positions.len());
    for p in &mesh.positions {
        let next = positions.len() as u32;
        let id = *map.entry(key(p)).or_insert_with(|| {
            positions.push(p.map(|c| if c == 0.0 { 0.0 } else { c }));
            next
        });
        remap.push(id);
    }
    let triangles = mesh.triangles.iter().map(|t| t.map(|i| remap[i as usize])).collect();
    TriMesh { positions, triangles }
}

/// The largest relative weld tolerance: beyond 1% of the diagonal, welding erases
/// features rather than cracks.
pub const MAX_RELATIVE_TOLERANCE: f64 = 1e-2;

/// The smallest non-zero relative weld tolerance: below it lies the f64 rounding of the
/// coordinates themselves (and the grid's cell numbers would exceed 2^52).
pub const MIN_RELATIVE_TOLERANCE: f64 = 1e-15;

/// The relative distance `info` probes with [`count_near_pairs`]: float32 exports (STL,
/// glTF) round to about 6e-8 of the coordinates, so their cracks lie well within it.
pub const PROBE_RELATIVE_TOLERANCE: f64 = 1e-6;

/// [`count_near_pairs`] stops counting here, which bounds its time on any input.
pub const NEAR_PAIR_LIMIT: usize = 1_000_000;

/// What [`weld_tolerance`] did.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WeldStats {
    /// The tolerance asked for, relative to the bounding-box diagonal.
    pub relative_tolerance: f64,
    /// The same in the mesh's units: `relative_tolerance × diagonal`.
    pub absolute_tolerance: f64,
    /// Vertices before the weld.
    pub vertices_before: usize,
    /// Vertices after it.
    pub vertices_after: usize,
    /// Triangles removed because two or more of their corners became one vertex (any
    /// triangle that already had a repeated vertex is removed and counted too).
    pub degenerate_triangles_dropped: usize,
}

/// Check a relative weld tolerance given by a user: a finite number, 0 or within
/// [[`MIN_RELATIVE_TOLERANCE`], [`MAX_RELATIVE_TOLERANCE`]]. Usable as a clap
/// `value_parser`.
///
/// ```
/// assert_eq!(mesh_io::weld::parse_tolerance("1e-6"), Ok(1e-6));
/// assert!(mesh_io::weld::parse_tolerance("0.5").is_err());
/// ```
pub fn parse_tolerance(s: &str) -> Result<f64, String> {
    let t: f64 = s.trim().parse().map_err(|_| format!("{s:?} is not a number"))?;
    if tolerance_ok(t) {
        Ok(t)
    } else {
        Err(format!(
            "{s} is outside [{MIN_RELATIVE_TOLERANCE:e}, {MAX_RELATIVE_TOLERANCE:e}] (a fraction of the bounding-box diagonal; 0 welds nothing more)"
        ))
    }
}

fn tolerance_ok(t: f64) -> bool {
    t == 0.0 || (MIN_RELATIVE_TOLERANCE..=MAX_RELATIVE_TOLERANCE).contains(&t)
}

/// Merge vertices within `relative_tolerance × diagonal` of each other (Euclidean), then
/// drop the triangles that became degenerate.
///
/// - Merging is transitive (single linkage): a chain of vertices, each within the
///   tolerance of the next, becomes one vertex even if its ends are farther apart.
/// - Deterministic: each merged vertex keeps the position of its lowest-index member, and
///   vertices keep the order of their lowest-index member, as in [`weld_exact`]. Positions
///   are never moved or averaged, so the result is a function of the input alone.
/// - Triangles with a repeated vertex after merging are dropped and counted; duplicate
///   triangles are kept (the topology report counts them). Vertices no triangle uses any
///   more stay.
/// - A tolerance of 0 merges nothing (the readers already weld exact duplicates) but still
///   drops triangles with a repeated vertex.
///
/// # Panics
/// If `relative_tolerance` is not 0 or within [[`MIN_RELATIVE_TOLERANCE`],
/// [`MAX_RELATIVE_TOLERANCE`]]; check user input with [`parse_tolerance`].
///
/// # Complexity
/// A uniform grid of cells twice the tolerance: O(V log V + F) for meshes whose vertices
/// are spread out; O(k²) more for each cluster of k distinct vertices within a few
/// tolerances of one another.
pub fn weld_tolerance(mesh: &TriMesh, relative_tolerance: f64) -> (TriMesh, WeldStats) {
    assert!(
        tolerance_ok(relative_tolerance),
        "relative weld tolerance {relative_tolerance} outside [{MIN_RELATIVE_TOLERANCE:e}, {MAX_RELATIVE_TOLERANCE:e}]"
    );
    let h = relative_tolerance * mesh.diagonal();
    let n = mesh.positions.len();
    let mut dsu = Dsu::new(n);
    if h > 0.0 {
        for_each_near_pair(&mesh.positions, h, |i, j| {
            dsu.union(i, j);
            true
        });
    }
    // Classes in order of their lowest member; each keeps that member's position.
    let mut id_of_root = vec![u32::MAX; n];
    let mut remap = Vec::with_capacity(n);
    let mut positions = Vec::new();
    for i in 0..n as u32 {
        let r = dsu.find(i) as usize;
        if id_of_root[r] == u32::MAX {
            id_of_root[r] = positions.len() as u32;
            positions.push(mesh.positions[i as usize]);
        }
        remap.push(id_of_root[r]);
    }
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| remap[i as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let stats = WeldStats {
        relative_tolerance,
        absolute_tolerance: h,
        vertices_before: n,
        vertices_after: positions.len(),
        degenerate_triangles_dropped: mesh.triangles.len() - triangles.len(),
    };
    (TriMesh { positions, triangles }, stats)
}

/// The number of pairs of distinct positions at most `relative_tolerance × diagonal` apart
/// (Euclidean), counting stops at [`NEAR_PAIR_LIMIT`]. On a mesh read by
/// [`crate::read_mesh`] (exact duplicates already welded), a non-zero count at
/// [`PROBE_RELATIVE_TOLERANCE`] means hairline cracks that [`weld_tolerance`] closes.
///
/// # Panics
/// As [`weld_tolerance`], for a tolerance outside its range.
///
/// # Complexity
/// O(V log V) plus the pairs examined, which are bounded by a constant times the pairs
/// found (a cell holds few points that are pairwise farther apart than the tolerance), so
/// the limit bounds the time.
pub fn count_near_pairs(mesh: &TriMesh, relative_tolerance: f64) -> usize {
    assert!(
        tolerance_ok(relative_tolerance),
        "relative tolerance {relative_tolerance} outside [{MIN_RELATIVE_TOLERANCE:e}, {MAX_RELATIVE_TOLERANCE:e}]"
    );
    let h = relative_tolerance * mesh.diagonal();
    if h <= 0.0 {
        return 0;
    }
    let mut count = 0usize;
    for_each_near_pair(&mesh.positions, h, |i, j| {
        if mesh.positions[i as usize] != mesh.positions[j as usize] {
            count += 1;
        }
        count < NEAR_PAIR_LIMIT
    });
    count
}

/// Call `f(i, j)` once for every unordered pair of points at most `h` apart, i < j, until
/// `f` returns false. Points are binned in a grid of cells `2h` wide (so that a pair
/// within `h` lands in the same or adjacent cells even after rounding in the cell
/// computation, for any cell number up to 2^52), and each cell is compared with itself and
/// its 13 "forward" neighbours.
fn for_each_near_pair(points: &[[f64; 3]], h: f64, mut f: impl FnMut(u32, u32) -> bool) {
    if points.is_empty() {
        return;
    }
    let lo = points.iter().fold([f64::INFINITY; 3], |m, p| [0, 1, 2].map(|k| m[k].min(p[k])));
    let cell = 2.0 * h;
    let key = |p: &[f64; 3]| [0, 1, 2].map(|k| ((p[k] - lo[k]) / cell).floor().clamp(0.0, 4.5e15) as i64);
    let mut order: Vec<([i64; 3], u32)> = points.iter().enumerate().map(|(i, p)| (key(p), i as u32)).collect();
    order.sort_unstable();
    // Cell key -> range in `order`.
    let mut cells: HashMap<[i64; 3], (usize, usize)> = HashMap::new();
    let mut start = 0;
    for run in order.chunk_by(|a, b| a.0 == b.0) {
        cells.insert(run[0].0, (start, start + run.len()));
        start += run.len();
    }
    let h2 = h * h;
    let near = |i: u32, j: u32| {
        let (a, b) = (points[i as usize], points[j as usize]);
        let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= h2
    };
    let forward: Vec<[i64; 3]> = (-1..=1)
        .flat_map(|x| (-1..=1).flat_map(move |y| (-1..=1).map(move |z| [x, y, z])))
        .filter(|o| *o > [0, 0, 0])
        .collect();
    let mut start = 0;
    for run in order.chunk_by(|a, b| a.0 == b.0) {
        let here = &order[start..start + run.len()];
        start += run.len();
        let k = run[0].0;
        for (a, &(_, i)) in here.iter().enumerate() {
            for &(_, j) in &here[a + 1..] {
                if near(i, j) && !f(i.min(j), i.max(j)) {
                    return;
                }
            }
        }
        for o in &forward {
            let Some(&(s, e)) = cells.get(&[k[0] + o[0], k[1] + o[1], k[2] + o[2]]) else { continue };
            for &(_, i) in here {
                for &(_, j) in &order[s..e] {
                    if near(i, j) && !f(i.min(j), i.max(j)) {
                        return;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_pairs(points: &[[f64; 3]], h: f64) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        for i in 0..points.len() {
            for j in i + 1..points.len() {
                let (a, b) = (points[i], points[j]);
                let d2 = (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2);
                if d2 <= h * h {
                    v.push((i as u32, j as u32));
                }
            }
        }
        v
    }

    #[test]
    fn grid_pairs_equal_brute_force() {
        // A deterministic cloud with clusters at many scales.
        let mut s = 0x1234_5678_9abc_def0u64;
        let mut rnd = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts = Vec::new();
        for _ in 0..400 {
            let c = [rnd(), rnd(), rnd()];
            pts.push(c);
            for _ in 0..3 {
                let r = 10f64.powf(-1.0 - 3.0 * rnd());
                pts.push([c[0] + r * (rnd() - 0.5), c[1] + r * (rnd() - 0.5), c[2] + r * (rnd() - 0.5)]);
            }
        }
        for h in [1e-4, 1e-3, 1e-2, 0.05] {
            let mut got = Vec::new();
            for_each_near_pair(&pts, h, |i, j| {
                got.push((i, j));
                true
            });
            got.sort_unstable();
            assert_eq!(got, brute_pairs(&pts, h), "h = {h}");
        }
    }

    #[test]
    fn tolerance_bounds() {
        assert!(parse_tolerance("0").is_ok());
        assert!(parse_tolerance("1e-16").is_err());
        assert!(parse_tolerance("-1e-6").is_err());
        assert!(parse_tolerance("NaN").is_err());
        assert!(parse_tolerance("0.02").is_err());
        assert!(parse_tolerance("x").is_err());
    }
}
