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
//!
//! # Layout
//! - this file: the public API ([`hausdorff_certified`], [`directed_hausdorff_certified`],
//!   [`certify_prepared`], [`CertifiedOptions`], [`HausdorffInterval`], [`Sides`]);
//! - `mesh`: input checks ([`check_mesh`]), [`DistanceMesh`] and batched closest-point
//!   queries;
//! - `libigl`: [`hausdorff_libigl`] / [`libigl_of`];
//! - `bounds`: the geometric bounds (covering radius, maximum of the lower envelope of
//!   affine functions);
//! - `cell`: sub-triangle cells, their upper bound and the 4-to-1 split;
//! - `passes`: the phases before the first split (vertex queries, pass A, pass B and the
//!   greedy probe);
//! - `driver`: the branch and bound that runs them, the subdivision loop and the result;
//! - `sphere`: the certified distance between a mesh and an analytic sphere
//!   ([`hausdorff_sphere_certified`]).

mod bounds;
mod cell;
mod driver;
mod libigl;
mod mesh;
mod passes;
mod sphere;

use std::time::Instant;

use mesh_io::TriMesh;
use occupancy::BvhPreset;
use serde::Serialize;

use crate::MetricsError;

pub(crate) use driver::certify;
pub use libigl::{hausdorff_libigl, libigl_of};
pub use mesh::{check_mesh, DistanceMesh};
pub use sphere::{
    certify_sphere_prepared, hausdorff_sphere_certified, hausdorff_sphere_certified_limited, SphereInterval,
};

use vf_common::vec3::V3;

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

/// [`directed_hausdorff_certified`] on prepared meshes (`seconds` left at 0), for callers
/// that measure one mesh against many.
///
/// # Errors
/// [`MetricsError::BadOption`].
pub fn directed_certify_prepared(
    a: &DistanceMesh,
    b: &DistanceMesh,
    opts: &CertifiedOptions,
) -> Result<HausdorffInterval, MetricsError> {
    certify(a, b, Sides::AToB, opts)
}
