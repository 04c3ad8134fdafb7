//! Hausdorff distances between triangle meshes: libigl-compatible (vertices only) and
//! certified (an interval that contains the true distance between the surfaces).
//!
//! # libigl-compatible
//! [`hausdorff_libigl`] is `igl::hausdorff(VA, FA, VB, FB)`: the square root of the larger of
//! the largest squared distance from a vertex of A (every row of `VA`, referenced or not)
//! to the triangles of B, and the same from B to A. The squared point-triangle distances
//! are the occupancy crate's, which are bit-identical to `igl::point_mesh_squared_distance`
//! (Ericson's regions in f64), so the value agrees with libigl to the last bit on the test
//! pairs. It is only a lower bound of the surface Hausdorff distance: the farthest point of
//! a surface from the other is often inside a triangle.
//!
//! # Certified
//! [`hausdorff_certified`] returns `[lo, hi]` containing `H(A, B) = max(h(A, B), h(B, A))`,
//! `h(A, B) = max_{x ∈ A} d(x, B)`, with `hi − lo ≤` the tolerance (default `1e-6 ×` the
//! diagonal of the bounding box of both meshes). Branch and bound over sub-triangles of the
//! source mesh of each direction, breadth-first, both directions sharing one lower bound
//! (a cell of the smaller direction is discarded as soon as it cannot beat the larger):
//!
//! - every distance `d(x, B)` is an exact BVH closest-point query (occupancy crate);
//! - lower bound: the largest `d(x, B)` at any evaluated point (all vertices, then the edge
//!   midpoints of every subdivided cell);
//! - upper bound of a cell `T` with corners `x_j` and distances `d_j`, the smaller of
//!   - *Lipschitz*: `max_j d_j + r(T)`, where `r(T)` is the covering radius of `T` by its
//!     corners (circumradius of an acute triangle, half the longest edge otherwise), since
//!     `d(·, B)` is 1-Lipschitz;
//!   - *convexity* (after Tang, Lee, Kim 2009): for any triangle `t` of B, `d(x, B) ≤ d(x, t)`
//!     and `d(·, t)` is convex, so on `T` it lies below the affine interpolation of its corner
//!     values; with `t` ranging over the closest triangles of the three corners, `d(·, B)` is
//!     below the lower envelope of (up to) three affine functions, whose maximum over `T` is
//!     computed exactly (`max_of_min_affine`). This bound is exact wherever one triangle of
//!     B is closest to the whole cell (most cells settle without subdividing), and also at a
//!     crease between two face regions (cells at a ridge settle after a few splits).
//! - a cell whose upper bound is at most `lo + tolerance` is discarded (its bound is kept for
//!   `hi`); the others are split 4-to-1 at their edge midpoints. Corners are dyadic
//!   barycentric coordinates of the original triangle, exact in f64, so no error accumulates
//!   with depth.
//! - `hi = max(lo, largest discarded bound)` once no cell is left.
//!
//! Both bounds converge at least linearly in the cell size, so the search ends after at most
//! about `log2(edge / tolerance)` levels, with work concentrated near the maximiser.
//!
//! Before the first split, work is saved on large meshes: only every 16th vertex of a large
//! source is queried at first; every triangle is bounded against the closest target
//! triangle of a nearby known vertex without a BVH query (pass A); of those left, the 1,024
//! with the largest bounds are made exact and the best 32 cells probed greedily downwards to
//! raise `lo`, and the rest are settled against it, querying corners only when needed
//! (pass B). Every step works on fixed chunks, so the result is independent of the thread
//! count.
//!
//! ## Rounding
//! The distances are computed in f64. The reported interval is widened on both sides by
//! [`HausdorffInterval::rounding_margin`] `= 128 ε M` (ε the f64 machine epsilon, `M` the
//! largest coordinate magnitude of both meshes), a forward-error bound of the point-triangle
//! distance evaluation (a few roundings of quantities of size ≤ 3M) and of the corner
//! positions. The bound assumes triangles that are not needles at the scale of `ε M` (for
//! a triangle whose smallest altitude is below about `1e-8 M` the f64 closest point can
//! err more); it is a careful estimate, not a machine-checked proof. `witness` is the
//! unwidened largest evaluated distance, which is `≥` the libigl value bit for bit when no
//! vertex is unreferenced.

use std::time::Instant;

use mesh_io::TriMesh;
use occupancy::bvh::TriangleBvh;
use occupancy::distance::closest_point_triangle::closest_point_triangle;
use occupancy::{BvhPreset, Config, Workspace, MAX_COORDINATE};
use rayon::prelude::*;
use serde::Serialize;

use crate::MetricsError;

type V3 = [f64; 3];

/// Queries per rayon task; fixed (with a fresh workspace per task) so results never depend
/// on the thread count.
const CHUNK: usize = 512;

/// Options of [`hausdorff_certified`].
#[derive(Clone, Debug, PartialEq)]
pub struct CertifiedOptions {
    /// Largest width of the interval as a fraction of the diagonal of the bounding box of
    /// both meshes (unitless, > 0). Default 1e-6.
    pub rel_tolerance: f64,
    /// Deepest subdivision level (each level halves the cells' edges), 1..=48. Default 40.
    pub max_depth: u32,
    /// Most cells alive at one level before giving up (the interval is then still valid but
    /// wider than asked, and `converged` is false). Default 20,000,000 (about 2 GB).
    pub max_active_cells: usize,
    /// Query every vertex exactly (needed for [`HausdorffInterval::libigl`], and makes the
    /// witness at least the libigl value when every vertex is referenced). Default false:
    /// a large source's vertices are only queried where the bounds need them.
    pub all_vertices: bool,
}

impl Default for CertifiedOptions {
    fn default() -> Self {
        CertifiedOptions { rel_tolerance: 1e-6, max_depth: 40, max_active_cells: 20_000_000, all_vertices: false }
    }
}

impl CertifiedOptions {
    fn validate(&self) -> Result<(), MetricsError> {
        if !(self.rel_tolerance.is_finite() && self.rel_tolerance > 0.0) {
            return Err(MetricsError::BadOption(format!(
                "rel_tolerance = {} must be a finite number > 0",
                self.rel_tolerance
            )));
        }
        if !(1..=48).contains(&self.max_depth) {
            return Err(MetricsError::BadOption(format!("max_depth = {} must be in 1..=48", self.max_depth)));
        }
        if self.max_active_cells == 0 {
            return Err(MetricsError::BadOption("max_active_cells must be > 0".into()));
        }
        Ok(())
    }
}

/// An interval containing the Hausdorff distance, and how it was found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HausdorffInterval {
    /// Lower bound, mesh units: `witness − rounding_margin` (at least 0).
    pub lo: f64,
    /// Upper bound, mesh units.
    pub hi: f64,
    /// The largest f64 distance evaluated at a point of a source surface, mesh units.
    pub witness: f64,
    /// A point attaining `witness`, on the source mesh of `witness_direction`.
    pub witness_point: V3,
    /// 0 if the witness lies on A (distance to B), 1 if on B.
    pub witness_direction: u8,
    /// Largest witnessed distance per direction `[A → B, B → A]` (a lower bound of each
    /// one-sided distance; the smaller one is not refined once it cannot matter).
    pub directed_witness: [f64; 2],
    /// The libigl-compatible value (vertices only, see [`hausdorff_libigl`]); `None` for a
    /// one-sided interval or unless every vertex was queried (`all_vertices`).
    pub libigl: Option<f64>,
    /// The tolerance asked for, mesh units (`rel_tolerance ×` the diagonal).
    pub tolerance: f64,
    /// Diagonal of the bounding box of both meshes, mesh units.
    pub diagonal: f64,
    /// Widening applied on each side for f64 rounding, mesh units (see the module doc).
    pub rounding_margin: f64,
    /// Whether `hi − lo ≤ tolerance` was reached within the depth and cell limits.
    pub converged: bool,
    /// Subdivision levels used.
    pub depth: u32,
    /// Sub-triangles whose bounds were evaluated.
    pub cells_evaluated: u64,
    /// Closest-point queries made (vertices and midpoints).
    pub queries: u64,
    /// Wall time of the search, seconds (BVH builds included).
    pub seconds: f64,
}

/// A validated mesh with its distance BVH.
pub struct DistanceMesh<'a> {
    mesh: &'a TriMesh,
    bvh: TriangleBvh,
}

/// Checks a mesh for the metrics: at least one triangle, indices in range, every
/// coordinate finite and at most [`MAX_COORDINATE`] in magnitude.
///
/// # Errors
/// [`MetricsError::Empty`], [`MetricsError::VertexOutOfRange`], [`MetricsError::BadVertex`].
pub fn check_mesh(mesh: &TriMesh, name: &'static str) -> Result<(), MetricsError> {
    if mesh.triangles.is_empty() || mesh.positions.is_empty() {
        return Err(MetricsError::Empty { mesh: name });
    }
    for (vertex, p) in mesh.positions.iter().enumerate() {
        if let Some(&value) = p.iter().find(|x| !(x.is_finite() && x.abs() <= MAX_COORDINATE)) {
            return Err(MetricsError::BadVertex { mesh: name, vertex, value, limit: MAX_COORDINATE });
        }
    }
    let num_vertices = mesh.positions.len();
    for (triangle, t) in mesh.triangles.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&v| v as usize >= num_vertices) {
            return Err(MetricsError::VertexOutOfRange { mesh: name, triangle, vertex, num_vertices });
        }
    }
    Ok(())
}

impl<'a> DistanceMesh<'a> {
    /// Validates `mesh` ([`check_mesh`]) and builds its BVH.
    ///
    /// # Errors
    /// As [`check_mesh`].
    pub fn new(mesh: &'a TriMesh, name: &'static str) -> Result<Self, MetricsError> {
        Self::with_preset(mesh, name, BvhPreset::Medium)
    }

    /// As [`DistanceMesh::new`] with a chosen BVH build preset: `VeryFast` builds in about
    /// half the time of `Medium` and answers the few hundred thousand queries of a
    /// Hausdorff search as fast (measured on the dragon pair; see the crate README).
    ///
    /// # Errors
    /// As [`check_mesh`].
    pub fn with_preset(mesh: &'a TriMesh, name: &'static str, preset: BvhPreset) -> Result<Self, MetricsError> {
        check_mesh(mesh, name)?;
        let config = Config { bvh_preset: preset, ..Config::default() };
        let bvh = TriangleBvh::for_distance(&mesh.positions, &mesh.triangles, &config)?;
        Ok(DistanceMesh { mesh, bvh })
    }

    /// The mesh.
    pub fn mesh(&self) -> &TriMesh {
        self.mesh
    }

    /// The BVH.
    pub fn bvh(&self) -> &TriangleBvh {
        &self.bvh
    }

    fn corners(&self, t: u32) -> [V3; 3] {
        self.mesh.triangles[t as usize].map(|v| self.mesh.positions[v as usize])
    }
}

/// Squared distance and closest triangle of every point, in parallel (deterministic).
///
/// Queries are visited in Morton order (so each search starts from the previous query's
/// triangle), in fixed chunks with a fresh workspace each.
fn query_points(target: &DistanceMesh, points: &[V3]) -> Vec<(f64, u32)> {
    let order = occupancy::order::morton_order(points);
    let sorted: Vec<(f64, u32)> = order
        .par_chunks(CHUNK)
        .flat_map_iter(|idx| {
            let mut ws = Workspace::new();
            idx.iter()
                .map(|&i| {
                    let c = target.bvh.closest_point(points[i as usize], &mut ws);
                    (c.squared_distance, c.triangle)
                })
                .collect::<Vec<_>>()
        })
        .collect();
    let mut out = vec![(0.0, 0u32); points.len()];
    for (r, &i) in sorted.iter().zip(&order) {
        out[i as usize] = *r;
    }
    out
}

/// libigl's `igl::hausdorff(VA, FA, VB, FB)`: `sqrt(max(max_i d²(VA_i, B), max_j d²(VB_j, A)))`
/// over every vertex (referenced or not), mesh units.
///
/// # Errors
/// As [`check_mesh`] (`a` is named "A", `b` "B").
pub fn hausdorff_libigl(a: &TriMesh, b: &TriMesh) -> Result<f64, MetricsError> {
    let (da, db) = rayon::join(
        || DistanceMesh::with_preset(a, "A", BvhPreset::VeryFast),
        || DistanceMesh::with_preset(b, "B", BvhPreset::VeryFast),
    );
    Ok(libigl_of(&da?, &db?))
}

/// [`hausdorff_libigl`] on prepared meshes.
pub fn libigl_of(a: &DistanceMesh, b: &DistanceMesh) -> f64 {
    let ab = query_points(b, &a.mesh.positions).iter().fold(0.0f64, |m, r| m.max(r.0));
    let ba = query_points(a, &b.mesh.positions).iter().fold(0.0f64, |m, r| m.max(r.0));
    ab.max(ba).sqrt()
}

/// Which one-sided distances to certify.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sides {
    /// `max(h(A, B), h(B, A))`: the Hausdorff distance.
    Both,
    /// `h(A, B) = max_{x ∈ A} d(x, B)` only.
    AToB,
}

/// Certified interval of the symmetric Hausdorff distance between the surfaces of `a` and
/// `b` (see the module doc for the algorithm and the rounding guarantee).
///
/// # Errors
/// As [`check_mesh`], and [`MetricsError::BadOption`].
pub fn hausdorff_certified(
    a: &TriMesh,
    b: &TriMesh,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    certified(a, b, Sides::Both, opts)
}

/// Certified interval of the one-sided distance `h(A, B) = max_{x ∈ A} d(x, B)`.
///
/// # Errors
/// As [`hausdorff_certified`].
pub fn directed_hausdorff_certified(
    a: &TriMesh,
    b: &TriMesh,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    certified(a, b, Sides::AToB, opts)
}

/// Prepares both meshes in parallel and certifies `sides`, timing the whole call.
fn certified(
    a: &TriMesh,
    b: &TriMesh,
    sides: Sides,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    let t0 = Instant::now();
    opts.validate()?;
    let (da, db) = rayon::join(
        || DistanceMesh::with_preset(a, "A", BvhPreset::VeryFast),
        || DistanceMesh::with_preset(b, "B", BvhPreset::VeryFast),
    );
    let mut r = certify(&da?, &db?, sides, opts)?;
    r.seconds = t0.elapsed().as_secs_f64();
    Ok(r)
}

/// [`hausdorff_certified`] on prepared meshes (`seconds` left at 0).
///
/// # Errors
/// [`MetricsError::BadOption`].
pub fn certify_prepared(
    a: &DistanceMesh,
    b: &DistanceMesh,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    certify(a, b, Sides::Both, opts)
}

/// Corners, barycentric corners, distances and closest triangles of a child cell.
type ChildSpec = ([V3; 3], [[f64; 2]; 3], [f64; 3], [u32; 3]);

/// An unsettled source triangle after pass A: (bound so far, direction, triangle).
type Pending = (f64, u8, u32);

/// Output of pass A on one chunk: cells with all corners exact, pending triangles, largest
/// discarded bound.
type PassA = (Vec<Cell>, Vec<Pending>, f64);

/// Output of pass B on a group of pending triangles.
#[derive(Default)]
struct PassB {
    cells: Vec<Cell>,
    max_discarded: f64,
    /// Largest new exact distance per direction, with its point.
    witness: [(f64, V3); 2],
    queries: u64,
}

/// Exact distances (and closest triangles) of source vertices queried by one group of
/// pending triangles, keyed by (direction, vertex).
type VertexCache = std::collections::HashMap<(u8, u32), (f64, u32)>;

/// Cells probed greedily for a better lower bound before pass B's bulk.
const PROBE_CELLS: usize = 32;

/// Pass B first settles this many pending triangles with the largest bounds.
const TOP_PENDING: usize = 1024;

/// Barycentric corners of a whole triangle.
const UNIT_BARY: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];

/// Phase 1 queries every VERTEX_STRIDE-th vertex of a large source exactly.
const VERTEX_STRIDE: usize = 16;

/// One sub-triangle of a source triangle.
#[derive(Clone, Copy, Debug)]
struct Cell {
    /// Direction: 0 = A → B, 1 = B → A.
    dir: u8,
    /// Source triangle.
    tri: u32,
    /// Dyadic barycentric coordinates `(u, v)` of the corners: `x = a + u (b − a) + v (c − a)`.
    bary: [[f64; 2]; 3],
    /// Distances of the corners to the target mesh.
    d: [f64; 3],
    /// Closest target triangle of each corner.
    t: [u32; 3],
    /// Upper bound of the distance over the cell.
    ub: f64,
}

#[inline]
fn at(tri: &[V3; 3], uv: [f64; 2]) -> V3 {
    let [a, b, c] = tri;
    [0, 1, 2].map(|k| a[k] + uv[0] * (b[k] - a[k]) + uv[1] * (c[k] - a[k]))
}

#[inline]
fn dist(p: V3, q: V3) -> f64 {
    ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
}

/// Covering radius of a triangle by its corners: the largest distance from a point of the
/// triangle to its nearest corner, slightly enlarged. Acute: the circumradius. Right or
/// obtuse (longest edge `c` opposite the obtuse corner, other edges `a`, `b`): the larger of
/// the distances at which the perpendicular bisectors of `a` and `b` meet `c`,
/// `b²c / (b² + c² − a²)` and `a²c / (a² + c² − b²)` (each ≤ c/2); half the longest edge
/// for needles, where those formulas lose accuracy.
fn covering_radius(x: &[V3; 3]) -> f64 {
    let mut s = [dist(x[1], x[2]), dist(x[2], x[0]), dist(x[0], x[1])];
    s.sort_by(f64::total_cmp);
    let (a, b, c) = (s[0], s[1], s[2]);
    let r = if c * c >= a * a + b * b {
        if a < 1e-3 * c {
            0.5 * c
        } else {
            let (a2, b2, c2) = (a * a, b * b, c * c);
            let r1 = b2 * c / (b2 + c2 - a2);
            let r2 = a2 * c / (a2 + c2 - b2);
            (r1.max(r2) * (1.0 + 1e-9)).min(0.5 * c)
        }
    } else {
        // Heron, stable form (Kahan), a <= b <= c.
        let p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
        if p > 0.0 {
            (a * b * c / p.sqrt()).max(0.5 * c)
        } else {
            c
        }
    };
    r * (1.0 + 1e-12)
}

/// `max over λ in the barycentric simplex of min_i Σ_j λ_j rows[i][j]`: the largest value
/// of the lower envelope of up to three affine functions over a triangle, given by their
/// values at the corners.
///
/// Why it bounds the distance: for a target triangle `t`, `d(·, t)` is convex, so on the
/// cell it lies below the affine interpolation of its corner values (Jensen); `d(·, B)` is
/// at most the smallest of these. The lower envelope is concave and piecewise affine, so its
/// maximum over the triangle is at a corner, where two functions cross on an edge, or where
/// three are equal inside; all such points are evaluated. Unlike the maximum over the
/// corners, this is exact where the closest feature is a face plane on each side of a
/// crease, so cells at a ridge of `d(·, B)` settle after a few splits.
fn max_of_min_affine(rows: &[[f64; 3]]) -> f64 {
    let eval = |l: [f64; 3]| rows.iter().map(|r| r[0] * l[0] + r[1] * l[1] + r[2] * l[2]).fold(f64::INFINITY, f64::min);
    let mut best = f64::NEG_INFINITY;
    for j in 0..3 {
        let mut l = [0.0; 3];
        l[j] = 1.0;
        best = best.max(eval(l));
    }
    for (j, k) in [(0, 1), (1, 2), (2, 0)] {
        for a in 0..rows.len() {
            for b in a + 1..rows.len() {
                let denom = (rows[a][k] - rows[a][j]) - (rows[b][k] - rows[b][j]);
                if denom != 0.0 {
                    let s = (rows[b][j] - rows[a][j]) / denom;
                    if s > 0.0 && s < 1.0 {
                        let mut l = [0.0; 3];
                        l[j] = 1.0 - s;
                        l[k] = s;
                        best = best.max(eval(l));
                    }
                }
            }
        }
    }
    if rows.len() == 3 {
        // λ·(r0 − r1) = 0, λ·(r0 − r2) = 0, λ·1 = 1 by Cramer's rule.
        let m = [
            [rows[0][0] - rows[1][0], rows[0][1] - rows[1][1], rows[0][2] - rows[1][2]],
            [rows[0][0] - rows[2][0], rows[0][1] - rows[2][1], rows[0][2] - rows[2][2]],
            [1.0, 1.0, 1.0],
        ];
        let det3 = |m: &[[f64; 3]; 3]| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let det = det3(&m);
        if det != 0.0 && det.is_finite() {
            let mut l = [0.0; 3];
            for (c, lc) in l.iter_mut().enumerate() {
                let mut mc = m;
                for (r, row) in mc.iter_mut().enumerate() {
                    row[c] = if r == 2 { 1.0 } else { 0.0 };
                }
                *lc = det3(&mc) / det;
            }
            if l.iter().all(|&x| (0.0..=1.0).contains(&x)) {
                best = best.max(eval(l));
            }
        }
    }
    best
}

struct Engine<'a> {
    src: [&'a DistanceMesh<'a>; 2],
    tgt: [&'a DistanceMesh<'a>; 2],
}

impl Engine<'_> {
    /// Upper bound of `d(·, target)` over the cell with the given corners: the smaller of
    /// the Lipschitz bound and the convexity bound (see `max_of_min_affine`) over the
    /// corners' closest target triangles.
    fn upper_bound(&self, dir: u8, x: &[V3; 3], d: &[f64; 3], t: &[u32; 3]) -> f64 {
        let dmax = d[0].max(d[1]).max(d[2]);
        if t[0] == t[1] && t[1] == t[2] {
            // One closest triangle for all corners: d(·, B) ≤ d(·, t) ≤ max_j d_j.
            return dmax;
        }
        let lipschitz = dmax + covering_radius(x);
        let tgt = self.tgt[dir as usize];
        let mut rows = [[0.0f64; 3]; 3];
        let mut k = 0;
        for i in 0..3 {
            if (i == 1 && t[1] == t[0]) || (i == 2 && (t[2] == t[0] || t[2] == t[1])) {
                continue;
            }
            let tri = tgt.corners(t[i]);
            for j in 0..3 {
                rows[k][j] =
                    if t[j] == t[i] { d[j] } else { dist(x[j], closest_point_triangle(x[j], tri[0], tri[1], tri[2])) };
            }
            k += 1;
        }
        lipschitz.min(max_of_min_affine(&rows[..k]) * (1.0 + 1e-12))
    }

    /// Splits a cell 4-to-1 at its edge midpoints; returns the children and the largest
    /// midpoint distance with its point.
    fn split(&self, c: &Cell, ws: &mut Workspace) -> ([Cell; 4], f64, V3) {
        let src_tri = self.src[c.dir as usize].corners(c.tri);
        let tgt = self.tgt[c.dir as usize];
        let b = c.bary;
        let mid = |i: usize, j: usize| [0.5 * (b[i][0] + b[j][0]), 0.5 * (b[i][1] + b[j][1])];
        let mb = [mid(0, 1), mid(1, 2), mid(2, 0)];
        let mut md = [0.0; 3];
        let mut mt = [0u32; 3];
        let mut mx = [[0.0; 3]; 3];
        let mut best = (f64::NEG_INFINITY, [0.0; 3]);
        for k in 0..3 {
            mx[k] = at(&src_tri, mb[k]);
            let cp = tgt.bvh.closest_point(mx[k], ws);
            md[k] = cp.squared_distance.sqrt();
            mt[k] = cp.triangle;
            if md[k] > best.0 {
                best = (md[k], mx[k]);
            }
        }
        let cx = b.map(|uv| at(&src_tri, uv));
        // Children: three corner cells and the middle one.
        let spec: [ChildSpec; 4] = [
            ([cx[0], mx[0], mx[2]], [b[0], mb[0], mb[2]], [c.d[0], md[0], md[2]], [c.t[0], mt[0], mt[2]]),
            ([mx[0], cx[1], mx[1]], [mb[0], b[1], mb[1]], [md[0], c.d[1], md[1]], [mt[0], c.t[1], mt[1]]),
            ([mx[2], mx[1], cx[2]], [mb[2], mb[1], b[2]], [md[2], md[1], c.d[2]], [mt[2], mt[1], c.t[2]]),
            ([mx[0], mx[1], mx[2]], mb, md, mt),
        ];
        let children = spec.map(|(x, bary, d, t)| Cell {
            dir: c.dir,
            tri: c.tri,
            bary,
            d,
            t,
            ub: self.upper_bound(c.dir, &x, &d, &t),
        });
        (children, best.0, best.1)
    }
}

/// The branch and bound (see the module doc).
pub(crate) fn certify(
    a: &DistanceMesh,
    b: &DistanceMesh,
    sides: Sides,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    opts.validate()?;
    let engine = Engine { src: [a, b], tgt: [b, a] };
    let dirs: &[u8] = match sides {
        Sides::Both => &[0, 1],
        Sides::AToB => &[0],
    };
    // Scale: bounding box of the referenced vertices of both meshes, largest coordinate.
    let mut lo_box = [f64::INFINITY; 3];
    let mut hi_box = [f64::NEG_INFINITY; 3];
    let mut max_abs = 0.0f64;
    for m in [a, b] {
        for t in &m.mesh.triangles {
            for &v in t {
                let p = m.mesh.positions[v as usize];
                for k in 0..3 {
                    lo_box[k] = lo_box[k].min(p[k]);
                    hi_box[k] = hi_box[k].max(p[k]);
                    max_abs = max_abs.max(p[k].abs());
                }
            }
        }
    }
    let diagonal = dist(lo_box, hi_box);
    let rounding_margin = 128.0 * f64::EPSILON * max_abs;
    let tolerance = opts.rel_tolerance * diagonal;
    // Internal tolerance: the final width includes both margins.
    let tol = (tolerance - 2.0 * rounding_margin).max(0.0);

    // Phase 1: exact distances of source vertices. Every vertex when asked (the libigl
    // value) or when the source is small next to the target; otherwise every
    // VERTEX_STRIDE-th referenced vertex, enough for a good first lower bound.
    let mut queries = 0u64;
    let mut libigl_sq = 0.0f64;
    let mut all_exact = true;
    let mut vert: [Vec<(f64, u32)>; 2] = [Vec::new(), Vec::new()];
    let mut witness = (f64::NEG_INFINITY, [0.0; 3], 0u8);
    let mut directed_witness = [0.0f64; 2];
    for &dir in dirs {
        let (src, tgt) = (engine.src[dir as usize], engine.tgt[dir as usize]);
        let nv = src.mesh.positions.len();
        let mut referenced = vec![false; nv];
        for t in &src.mesh.triangles {
            for &v in t {
                referenced[v as usize] = true;
            }
        }
        let full = opts.all_vertices || nv <= tgt.mesh.positions.len() / 4 || nv <= 4 * VERTEX_STRIDE;
        let idx: Vec<usize> = if full {
            (0..nv).collect()
        } else {
            all_exact = false;
            (0..nv).filter(|&v| referenced[v]).step_by(VERTEX_STRIDE).collect()
        };
        let pts: Vec<V3> = idx.iter().map(|&v| src.mesh.positions[v]).collect();
        let r = query_points(tgt, &pts);
        queries += r.len() as u64;
        let mut d = vec![(-1.0, 0u32); nv];
        for (&v, &(d2, t)) in idx.iter().zip(&r) {
            libigl_sq = libigl_sq.max(d2);
            let dv = d2.sqrt();
            d[v] = (dv, t);
            if referenced[v] {
                directed_witness[dir as usize] = directed_witness[dir as usize].max(dv);
                if dv > witness.0 {
                    witness = (dv, src.mesh.positions[v], dir);
                }
            }
        }
        vert[dir as usize] = d;
    }
    let libigl = if sides == Sides::Both && all_exact { Some(libigl_sq.sqrt()) } else { None };
    let mut lo = witness.0;

    // Phase 2, pass A (no BVH query): every source triangle, in Morton order of its
    // centroid. With all three corners exact, its full upper bound; otherwise the convexity
    // bound against the closest target triangle of the nearest exactly known corner seen so
    // far in its chunk (three point-triangle distances), which settles most triangles.
    let mut cells_evaluated = 0u64;
    let mut max_discarded = f64::NEG_INFINITY;
    let mut active: Vec<Cell> = Vec::new();
    let mut pending: Vec<Pending> = Vec::new();
    let lo0 = lo;
    for &dir in dirs {
        let (src, tgt) = (engine.src[dir as usize], engine.tgt[dir as usize]);
        let vd = &vert[dir as usize];
        let centroids: Vec<V3> = src
            .mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| src.mesh.positions[v as usize]);
                [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
            })
            .collect();
        let order = occupancy::order::morton_order(&centroids);
        let parts: Vec<PassA> = order
            .par_chunks(CHUNK)
            .map(|idx| {
                let mut cells = Vec::new();
                let mut pend = Vec::new();
                let mut disc = f64::NEG_INFINITY;
                let mut last_t: Option<u32> = None;
                for &ti in idx {
                    let tri = src.mesh.triangles[ti as usize];
                    let x = tri.map(|v| src.mesh.positions[v as usize]);
                    let known = tri.map(|v| vd[v as usize]);
                    if let Some(k) = known.iter().find(|k| k.0 >= 0.0) {
                        last_t = Some(k.1);
                    }
                    if known.iter().all(|k| k.0 >= 0.0) {
                        let (d, t) = (known.map(|k| k.0), known.map(|k| k.1));
                        let ub = engine.upper_bound(dir, &x, &d, &t);
                        if ub > lo0 + tol {
                            cells.push(Cell { dir, tri: ti, bary: UNIT_BARY, d, t, ub });
                        } else {
                            disc = disc.max(ub);
                        }
                        continue;
                    }
                    let m = match last_t {
                        Some(t) => {
                            let tc = tgt.corners(t);
                            x.iter().fold(0.0f64, |m, xj| {
                                m.max(dist(*xj, closest_point_triangle(*xj, tc[0], tc[1], tc[2])))
                            })
                        }
                        None => f64::INFINITY,
                    };
                    if m > lo0 + tol {
                        pend.push((m, dir, ti));
                    } else {
                        disc = disc.max(m);
                    }
                }
                (cells, pend, disc)
            })
            .collect();
        cells_evaluated += src.mesh.triangles.len() as u64;
        for (cells, pend, disc) in parts {
            active.extend(cells);
            pending.extend(pend);
            max_discarded = max_discarded.max(disc);
        }
    }

    // Pass B: the unsettled triangles. First the TOP_PENDING with the largest bounds, whose
    // exact corner distances raise the lower bound; then the rest in Morton order, each
    // first tested against the closest target triangle of the previous exactly queried
    // corner in its chunk, and only then queried exactly.
    let mut top: Vec<usize> = (0..pending.len()).collect();
    let k = TOP_PENDING.min(top.len());
    if k < top.len() {
        top.select_nth_unstable_by(k, |&a, &b| pending[b].0.total_cmp(&pending[a].0).then(a.cmp(&b)));
    }
    top.truncate(k);
    top.sort_unstable();
    let mut done = vec![false; pending.len()];
    for &i in &top {
        done[i] = true;
    }
    // Exact corner distances of a pending triangle (from phase 1, the group's cache of
    // vertices already queried, or a BVH query) and its full bound.
    let exact_cell = |dir: u8, ti: u32, m: f64, ws: &mut Workspace, out: &mut PassB, cache: &mut VertexCache| {
        let (src, tgt) = (engine.src[dir as usize], engine.tgt[dir as usize]);
        let vd = &vert[dir as usize];
        let tri = src.mesh.triangles[ti as usize];
        let x = tri.map(|v| src.mesh.positions[v as usize]);
        let mut d = [0.0; 3];
        let mut t = [0u32; 3];
        for j in 0..3 {
            let (dv, tv) = vd[tri[j] as usize];
            if dv >= 0.0 {
                (d[j], t[j]) = (dv, tv);
            } else if let Some(&(dc, tc)) = cache.get(&(dir, tri[j])) {
                (d[j], t[j]) = (dc, tc);
            } else {
                let c = tgt.bvh.closest_point(x[j], ws);
                out.queries += 1;
                (d[j], t[j]) = (c.squared_distance.sqrt(), c.triangle);
                cache.insert((dir, tri[j]), (d[j], t[j]));
                if d[j] > out.witness[dir as usize].0 {
                    out.witness[dir as usize] = (d[j], x[j]);
                }
            }
        }
        let ub = engine.upper_bound(dir, &x, &d, &t).min(m);
        (Cell { dir, tri: ti, bary: UNIT_BARY, d, t, ub }, t[0])
    };
    macro_rules! merge {
        ($out:expr) => {{
            let out: PassB = $out;
            queries += out.queries;
            for (dir, w) in out.witness.into_iter().enumerate() {
                directed_witness[dir] = directed_witness[dir].max(w.0);
                if w.0 > lo {
                    lo = w.0;
                    witness = (w.0, w.1, dir as u8);
                }
            }
            active.extend(out.cells);
            max_discarded = max_discarded.max(out.max_discarded);
        }};
    }
    let top_out: Vec<PassB> = top
        .par_chunks(64)
        .map(|part| {
            let mut ws = Workspace::new();
            let mut out = PassB::default();
            let mut cache = VertexCache::default();
            for &i in part {
                let (m, dir, ti) = pending[i];
                let (cell, _) = exact_cell(dir, ti, m, &mut ws, &mut out, &mut cache);
                out.cells.push(cell);
            }
            out
        })
        .collect();
    for out in top_out {
        merge!(out);
    }
    // Probe: from the cells with the largest bounds so far, descend greedily into the child
    // with the largest bound; the midpoints met on the way are real distances near the
    // likely maximiser, which raise the lower bound before the bulk of the work.
    let mut order: Vec<usize> = (0..active.len()).collect();
    order.sort_unstable_by(|&i, &j| active[j].ub.total_cmp(&active[i].ub).then(i.cmp(&j)));
    order.truncate(PROBE_CELLS);
    let probes: Vec<(f64, V3, u8, u64)> = order
        .par_iter()
        .map(|&i| {
            let mut ws = Workspace::new();
            let mut cur = active[i];
            let mut best = (f64::NEG_INFINITY, [0.0; 3], cur.dir, 0u64);
            for _ in 0..opts.max_depth {
                if cur.ub <= lo + tol || cur.ub <= best.0 + tol {
                    break;
                }
                let (children, md, mx) = engine.split(&cur, &mut ws);
                best.3 += 3;
                if md > best.0 {
                    (best.0, best.1) = (md, mx);
                }
                cur = children.into_iter().max_by(|a, b| a.ub.total_cmp(&b.ub)).unwrap_or(cur);
            }
            best
        })
        .collect();
    for (w, x, dir, nq) in probes {
        queries += nq;
        directed_witness[dir as usize] = directed_witness[dir as usize].max(w);
        if w > lo {
            lo = w;
            witness = (w, x, dir);
        }
    }
    let lo1 = lo;
    let rest: Vec<usize> = (0..pending.len()).filter(|&i| !done[i]).collect();
    let rest_out: Vec<PassB> = rest
        .par_chunks(CHUNK)
        .map(|part| {
            let mut ws = Workspace::new();
            let mut out = PassB::default();
            let mut cache = VertexCache::default();
            let mut local_lo = lo1;
            let mut last_t: Option<(u8, u32)> = None;
            for &i in part {
                let (m, dir, ti) = pending[i];
                if m <= local_lo + tol {
                    out.max_discarded = out.max_discarded.max(m);
                    continue;
                }
                let (src, tgt) = (engine.src[dir as usize], engine.tgt[dir as usize]);
                if let Some((_, t)) = last_t.filter(|l| l.0 == dir) {
                    let tri = src.mesh.triangles[ti as usize];
                    let tc = tgt.corners(t);
                    let mut mm = 0.0f64;
                    for v in tri {
                        let xj = src.mesh.positions[v as usize];
                        mm = mm.max(dist(xj, closest_point_triangle(xj, tc[0], tc[1], tc[2])));
                        if mm > local_lo + tol {
                            break;
                        }
                    }
                    if mm <= local_lo + tol {
                        out.max_discarded = out.max_discarded.max(mm);
                        continue;
                    }
                }
                let (cell, t0) = exact_cell(dir, ti, m, &mut ws, &mut out, &mut cache);
                local_lo = local_lo.max(out.witness[dir as usize].0);
                last_t = Some((dir, t0));
                if cell.ub > local_lo + tol {
                    out.cells.push(cell);
                } else {
                    out.max_discarded = out.max_discarded.max(cell.ub);
                }
            }
            out
        })
        .collect();
    for out in rest_out {
        merge!(out);
    }
    // Cells kept against an older (smaller) lower bound.
    active.retain(|c| {
        let keep = c.ub > lo + tol;
        if !keep {
            max_discarded = max_discarded.max(c.ub);
        }
        keep
    });

    let mut depth = 0u32;
    let mut converged = true;
    while !active.is_empty() {
        if depth >= opts.max_depth || active.len().saturating_mul(4) > opts.max_active_cells {
            converged = false;
            break;
        }
        depth += 1;
        let split: Vec<Vec<([Cell; 4], f64, V3)>> = active
            .par_chunks(CHUNK / 4)
            .map(|chunk| {
                let mut ws = Workspace::new();
                chunk.iter().map(|c| engine.split(c, &mut ws)).collect()
            })
            .collect();
        queries += 3 * active.len() as u64;
        cells_evaluated += 4 * active.len() as u64;
        for (s, c) in split.iter().flatten().zip(&active) {
            if s.1 > lo {
                lo = s.1;
                witness = (s.1, s.2, c.dir);
            }
            directed_witness[c.dir as usize] = directed_witness[c.dir as usize].max(s.1);
        }
        let mut next = Vec::new();
        for s in split.into_iter().flatten() {
            for child in s.0 {
                if child.ub > lo + tol {
                    next.push(child);
                } else {
                    max_discarded = max_discarded.max(child.ub);
                }
            }
        }
        active = next;
    }
    let mut hi = lo.max(max_discarded);
    for c in &active {
        hi = hi.max(c.ub);
    }
    Ok(HausdorffInterval {
        lo: (lo - rounding_margin).max(0.0),
        hi: hi + rounding_margin,
        witness: lo,
        witness_point: witness.1,
        witness_direction: witness.2,
        directed_witness,
        libigl,
        tolerance,
        diagonal,
        rounding_margin,
        converged,
        depth,
        cells_evaluated,
        queries,
        seconds: 0.0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over a fine barycentric grid (a lower bound of the true maximum).
    fn grid_max(rows: &[[f64; 3]], n: usize) -> f64 {
        let mut best = f64::NEG_INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let l = [i as f64 / n as f64, j as f64 / n as f64, (n - i - j) as f64 / n as f64];
                let v = rows.iter().map(|r| r[0] * l[0] + r[1] * l[1] + r[2] * l[2]).fold(f64::INFINITY, f64::min);
                best = best.max(v);
            }
        }
        best
    }

    #[test]
    fn max_of_min_affine_matches_a_dense_grid() {
        let mut state = 12345u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..3000 {
            let k = 1 + case % 3;
            let rows: Vec<[f64; 3]> = (0..k).map(|_| [rnd() * 2.0, rnd() * 2.0, rnd() * 2.0]).collect();
            let got = max_of_min_affine(&rows);
            let grid = grid_max(&rows, 300);
            // Never below what the grid sees; the grid's spacing bounds the other side.
            assert!(got >= grid - 1e-12, "case {case}: {got} < grid {grid} for {rows:?}");
            assert!(got <= grid + 2.0 * 2.0 / 300.0 + 1e-12, "case {case}: {got} >> grid {grid} for {rows:?}");
        }
        // A ridge: two planes crossing inside the triangle; the envelope peaks on the crossing.
        let rows = [[0.0, 1.0, 1.0], [1.0, 0.0, 1.0]];
        assert!((max_of_min_affine(&rows) - 1.0).abs() < 1e-15);
        let rows = [[0.0, 2.0, 0.0], [2.0, 0.0, 0.0]];
        assert!((max_of_min_affine(&rows) - 1.0).abs() < 1e-15);
        // Three-way interior peak.
        let rows = [[3.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 3.0]];
        assert!((max_of_min_affine(&rows) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn covering_radius_bounds_the_distance_to_the_nearest_corner() {
        let mut state = 99u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut tris = vec![
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.8, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.05, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
        ];
        for _ in 0..200 {
            tris.push([[rnd(), rnd(), rnd()], [rnd(), rnd(), rnd()], [rnd(), rnd(), rnd()]]);
        }
        for x in tris {
            let r = covering_radius(&x);
            let n = 200;
            let mut worst = 0.0f64;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let uv = [i as f64 / n as f64, j as f64 / n as f64];
                    let p = at(&x, uv);
                    worst = worst.max(dist(p, x[0]).min(dist(p, x[1])).min(dist(p, x[2])));
                }
            }
            assert!(worst <= r, "{x:?}: {worst} > {r}");
            assert!(r <= worst * 1.05 + 0.01, "{x:?}: {r} loose vs {worst}");
        }
    }
}
