//! Certified Hausdorff distance between a triangle mesh and an analytic sphere
//! ([`mesh_io::shapes::Sphere`]): the reference surface of the sphere study.
//!
//! - mesh → sphere, exactly per triangle: `|‖x − c‖ − r|` is largest at a vertex for the
//!   outward part (`‖x − c‖` is convex) and at the triangle's closest point to `c` for the
//!   inward part, so `h₁ = max_T max(max_v ‖v − c‖ − r, r − d(c, T))`;
//! - sphere → mesh, best-first branch and bound over spherical triangles (an icosahedron's
//!   faces, split 4-way at the normalised edge midpoints): a patch's points lie within
//!   `R = r · max_i ‖ŝ − â_i‖` of its centre `ŝ`'s point (the farthest point of a small
//!   spherical triangle from its centre is a corner), so `d(y, M) ≤ d(s, M) + R` on it;
//!   `d(s, M)` itself is a lower bound. Patches whose bound exceeds the best lower bound
//!   by more than `tol` are split, the largest bound first, until none is left (or after
//!   20,000,000 evaluations, or the caller's limit; the interval is then valid but wider,
//!   and `converged` false). A surface about equally far from the sphere everywhere
//!   (marching cubes of its exact distance) needs patches everywhere as small as `tol`:
//!   such callers pass a limit ([`hausdorff_sphere_certified_limited`]).
//!
//! `d(·, M)` is the exact BVH closest-point distance of [`DistanceMesh`] (the occupancy
//! crate's, bit-identical to `MeshOracle::closest_point`).
//!
//! **Rounding.** Both ends are widened by `64 ε (max(1, M) + r + max(1, ‖c‖))`, `M` the
//! largest coordinate magnitude of the mesh's referenced vertices: a forward-error
//! estimate of the f64 distances, like the mesh-to-mesh margin (see [`crate::hausdorff`]).
//! For a mesh inside `[−1, 1]³` and a centre within 1 of the origin (the sphere study) it
//! is `64 ε (2 + r)`, the margin the study has always used.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use mesh_io::shapes::Sphere;
use mesh_io::TriMesh;
use occupancy::distance::closest_point_triangle::closest_point_triangle;
use occupancy::{Workspace, MAX_COORDINATE};
use rayon::prelude::*;
use serde::Serialize;
use vf_common::vec3::{distance, normalize};

use super::mesh::DistanceMesh;
use super::V3;
use crate::MetricsError;

/// Most child patches evaluated before the sphere → mesh search gives up.
const MAX_EVALUATIONS: usize = 20_000_000;

/// An interval containing the Hausdorff distance between a mesh and a sphere.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SphereInterval {
    /// Lower bound, mesh units (at least 0).
    pub lo: f64,
    /// Upper bound, mesh units.
    pub hi: f64,
    /// `h(mesh → sphere)`, the largest distance from a point of the mesh to the sphere
    /// (exact up to rounding; not widened).
    pub mesh_to_sphere: f64,
    /// The largest distance from an evaluated point of the sphere to the mesh: a lower
    /// bound of `h(sphere → mesh)` (not widened).
    pub sphere_to_mesh: f64,
    /// The tolerance asked for, mesh units.
    pub tolerance: f64,
    /// Widening applied on each side for f64 rounding, mesh units (see the module doc).
    pub rounding_margin: f64,
    /// Whether `hi − lo ≤ tolerance + 2 rounding_margin` was reached within the evaluation
    /// limit.
    pub converged: bool,
    /// Spherical patches whose bounds were evaluated (the 20 starting faces included).
    pub patches_evaluated: u64,
}

/// Certified interval `[lo, hi]` of the Hausdorff distance between the surface of `mesh`
/// and `sphere`, with `hi − lo ≤ tol + 2 × rounding_margin` (see the module doc).
///
/// # Errors
/// As [`check_mesh`](super::check_mesh) (the mesh is named "mesh"); [`MetricsError::BadOption`]
/// for a sphere with a non-finite or huge centre or a radius that is not finite and > 0,
/// and for a `tol` that is NaN or negative.
pub fn hausdorff_sphere_certified(mesh: &TriMesh, sphere: &Sphere, tol: f64) -> Result<SphereInterval, MetricsError> {
    hausdorff_sphere_certified_limited(mesh, sphere, tol, MAX_EVALUATIONS)
}

/// [`hausdorff_sphere_certified`] that stops after `max_evaluations` patches (at most the
/// default 20,000,000): the interval stays certified, only wider when the limit is hit.
///
/// # Errors
/// As [`hausdorff_sphere_certified`].
pub fn hausdorff_sphere_certified_limited(
    mesh: &TriMesh,
    sphere: &Sphere,
    tol: f64,
    max_evaluations: usize,
) -> Result<SphereInterval, MetricsError> {
    let prepared = DistanceMesh::new(mesh, "mesh")?;
    check_sphere(sphere, tol)?;
    Ok(certify(&prepared, sphere, tol, max_evaluations.min(MAX_EVALUATIONS)))
}

/// [`hausdorff_sphere_certified`] on a prepared mesh.
///
/// # Errors
/// [`MetricsError::BadOption`], as [`hausdorff_sphere_certified`].
pub fn certify_sphere_prepared(mesh: &DistanceMesh, sphere: &Sphere, tol: f64) -> Result<SphereInterval, MetricsError> {
    check_sphere(sphere, tol)?;
    Ok(certify(mesh, sphere, tol, MAX_EVALUATIONS))
}

fn certify(mesh: &DistanceMesh, sphere: &Sphere, tol: f64, max_evaluations: usize) -> SphereInterval {
    let mesh_to_sphere = mesh_to_sphere(mesh.mesh(), sphere);
    let (lo2, hi2, evaluations, converged) = sphere_to_mesh(mesh, sphere, tol, max_evaluations);
    let margin = rounding_margin(mesh.mesh(), sphere);
    let lo = mesh_to_sphere.max(lo2) - margin;
    let hi = mesh_to_sphere.max(hi2) + margin;
    SphereInterval {
        lo: lo.max(0.0),
        hi,
        mesh_to_sphere,
        sphere_to_mesh: lo2,
        tolerance: tol,
        rounding_margin: margin,
        converged,
        patches_evaluated: evaluations,
    }
}

fn check_sphere(sphere: &Sphere, tol: f64) -> Result<(), MetricsError> {
    if !sphere.center.iter().all(|x| x.is_finite() && x.abs() <= MAX_COORDINATE) {
        return Err(MetricsError::BadOption(format!(
            "sphere center {:?} must be finite and at most {MAX_COORDINATE:e} in magnitude",
            sphere.center
        )));
    }
    if !(sphere.radius.is_finite() && sphere.radius > 0.0 && sphere.radius <= MAX_COORDINATE) {
        return Err(MetricsError::BadOption(format!(
            "sphere radius {} must be finite, > 0 and at most {MAX_COORDINATE:e}",
            sphere.radius
        )));
    }
    if tol.is_nan() || tol < 0.0 {
        return Err(MetricsError::BadOption(format!("tolerance {tol} must be a number ≥ 0")));
    }
    Ok(())
}

/// `64 ε (max(1, M) + r + max(1, ‖c‖))` (see the module doc).
fn rounding_margin(mesh: &TriMesh, sphere: &Sphere) -> f64 {
    let mut max_abs = 0.0f64;
    for t in &mesh.triangles {
        for &v in t {
            max_abs = mesh.positions[v as usize].iter().fold(max_abs, |m, x| m.max(x.abs()));
        }
    }
    let c = sphere.center;
    let center_norm = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    64.0 * f64::EPSILON * (1.0f64.max(max_abs) + sphere.radius + 1.0f64.max(center_norm))
}

/// `h(mesh → sphere)`: per triangle the larger of the outward part (at a vertex) and the
/// inward part (at the triangle's closest point to the centre), maximised over triangles.
fn mesh_to_sphere(mesh: &TriMesh, sphere: &Sphere) -> f64 {
    mesh.triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let out = [a, b, c].iter().map(|&v| sphere.distance(v)).fold(f64::NEG_INFINITY, f64::max);
            let inw = sphere.radius - sphere.center_distance(closest_point_triangle(sphere.center, a, b, c));
            out.max(inw)
        })
        .reduce(|| f64::NEG_INFINITY, f64::max)
}

/// A spherical triangle (unit-vector corners) with the upper bound of `d(·, mesh)` on it.
#[derive(PartialEq)]
struct Patch {
    ub: f64,
    corners: [V3; 3],
}

impl Eq for Patch {}

impl PartialOrd for Patch {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

impl Ord for Patch {
    fn cmp(&self, o: &Self) -> Ordering {
        self.ub.total_cmp(&o.ub)
    }
}

/// Lower and upper bound of `d(·, mesh)` on a patch: the distance at its centre's point,
/// and the least of two upper bounds. (1) Lipschitz: that distance plus the patch's radius
/// around it. (2) One triangle: the patch lies in the convex hull H of its corners'
/// points `c + r·aᵢ` and the same scaled by 1/m about the centre c (m: the distance from
/// the origin to the flat triangle of the unit corners aᵢ; every patch point is
/// `c + r·v/‖v‖` with v on that flat triangle, so ‖v‖ ≥ m), and the distance to the
/// triangle T nearest the centre's point is convex, so its maximum over H, reached at one
/// of H's six vertices, bounds `d(·, mesh) ≤ d(·, T)` on the patch. Bound (2) is tight
/// for a patch within one triangle's reach, so the search only needs small patches along
/// the mesh's edges, not everywhere (a surface about equally far from the sphere all over,
/// like marching cubes of its distance, would otherwise need patches as small as the
/// tolerance everywhere).
fn eval_patch(mesh: &DistanceMesh, sphere: &Sphere, corners: &[V3; 3], ws: &mut Workspace) -> (f64, f64) {
    let s = normalize([0, 1, 2].map(|k| corners[0][k] + corners[1][k] + corners[2][k]));
    let on_sphere = [0, 1, 2].map(|k| sphere.center[k] + sphere.radius * s[k]);
    let closest = mesh.bvh().closest_point(on_sphere, ws);
    let d = closest.squared_distance.sqrt();
    let r = corners.iter().map(|&a| distance(s, a)).fold(0.0, f64::max) * sphere.radius;
    let m = distance(closest_point_triangle([0.0; 3], corners[0], corners[1], corners[2]), [0.0; 3]);
    let mut one_triangle = f64::INFINITY;
    if m > 0.5 {
        let [ta, tb, tc] = mesh.corners(closest.triangle);
        one_triangle = 0.0;
        for scale in [sphere.radius, sphere.radius / m] {
            for a in corners {
                let p = [0, 1, 2].map(|k| sphere.center[k] + scale * a[k]);
                one_triangle = one_triangle.max(distance(p, closest_point_triangle(p, ta, tb, tc)));
            }
        }
    }
    (d, (d + r).min(one_triangle))
}

/// `h(sphere → mesh)` by best-first branch and bound (see the module doc): the largest
/// evaluated distance, the upper bound, the patches evaluated and whether the search
/// finished. Sequential: one workspace, so its closest-point hints are deterministic.
fn sphere_to_mesh(mesh: &DistanceMesh, sphere: &Sphere, tol: f64, max_evaluations: usize) -> (f64, f64, u64, bool) {
    // The starting patches: the icosahedron's faces (unit vectors, counter-clockwise).
    let icosahedron = mesh_io::shapes::icosphere(0);
    let mut ws = Workspace::new();
    let mut lo2: f64 = 0.0;
    let mut heap = BinaryHeap::new();
    for f in &icosahedron.triangles {
        let corners = f.map(|i| icosahedron.positions[i as usize]);
        let (lo, ub) = eval_patch(mesh, sphere, &corners, &mut ws);
        lo2 = lo2.max(lo);
        heap.push(Patch { ub, corners });
    }
    let mut evaluations = 0usize;
    while let Some(top) = heap.peek() {
        if top.ub <= lo2 + tol || evaluations > max_evaluations {
            break;
        }
        let Some(p) = heap.pop() else { break };
        let [a, b, c] = p.corners;
        let (ab, bc, ca) = (
            normalize([0, 1, 2].map(|k| a[k] + b[k])),
            normalize([0, 1, 2].map(|k| b[k] + c[k])),
            normalize([0, 1, 2].map(|k| c[k] + a[k])),
        );
        for corners in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
            let (lo, ub) = eval_patch(mesh, sphere, &corners, &mut ws);
            evaluations += 1;
            lo2 = lo2.max(lo);
            if ub > lo2 + tol {
                heap.push(Patch { ub, corners });
            }
        }
    }
    let converged = heap.peek().is_none_or(|p| p.ub <= lo2 + tol);
    let hi2 = heap.peek().map_or(lo2, |p| p.ub.max(lo2));
    (lo2, hi2, (icosahedron.triangles.len() + evaluations) as u64, converged)
}
