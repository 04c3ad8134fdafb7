//! Reconstruction metrics for voronoi-fit: how far is a predicted mesh from a reference?
//!
//! Entry points:
//! - [`hausdorff_libigl`]: `igl::hausdorff`, bit for bit (vertex-to-mesh both ways; a lower
//!   bound of the true distance);
//! - [`hausdorff_certified`] / [`directed_hausdorff_certified`]: an interval `[lo, hi]`
//!   containing the true Hausdorff distance between the two surfaces, `hi − lo ≤ 1e-6 ×`
//!   the bounding-box diagonal by default (branch and bound over triangle subdivisions with
//!   BVH distance bounds, see [`hausdorff`]);
//! - [`hausdorff_sphere_certified`]: the same kind of interval between a mesh and an
//!   analytic [`mesh_io::shapes::Sphere`] (the sphere study's reference surface);
//! - [`surface_metrics`]: Chamfer L1 and L2, F-score at τ (default 0.3% of the reference
//!   diagonal), normal consistency on seeded area-weighted samples (100,000 per surface by
//!   default), see [`surface`];
//! - [`volumetric_iou`]: IoU of the two solids by generalized winding numbers on uniform
//!   samples, see [`iou`];
//! - [`solid_boundary`]: the reference's samples split into interior faces (the solid on
//!   both sides) and the solid's boundary, with their distances to the prediction, see
//!   [`boundary`];
//! - [`validity()`]: closed, manifold, oriented, self-intersections (exact), components,
//!   genus, from `mesh_io::TopologyReport` and `crust::check`;
//! - [`evaluate`]: all of the above in one [`EvalReport`] (`voronoi-fit eval`).
//!
//! Every function validates its meshes first ([`check_mesh`]): an empty mesh, a NaN,
//! infinite or huge coordinate, or an out-of-range index is a [`MetricsError`], never a
//! panic. Degenerate and duplicate triangles are accepted (they are part of the surface;
//! zero-area ones are never sampled). Distances use the occupancy crate's BVH and
//! point-triangle code; every parallel loop works in fixed chunks, so results do not depend
//! on the thread count.

pub mod boundary;
pub mod error;
pub mod eval;
pub mod hausdorff;
pub mod iou;
pub mod surface;
pub mod validity;

pub use boundary::{buried, solid_boundary, solid_boundary_with, SolidBoundary, BURIED_OFFSET, OWN_SOLID};
pub use error::MetricsError;
pub use eval::{evaluate, evaluate_with, EvalOptions, EvalReport};
pub use hausdorff::{
    check_mesh, directed_hausdorff_certified, hausdorff_certified, hausdorff_libigl, hausdorff_sphere_certified,
    hausdorff_sphere_certified_limited, CertifiedOptions, DistanceMesh, HausdorffInterval, SphereInterval,
};
pub use iou::{iou_of_labels, volumetric_iou, IouResult};
pub use surface::{surface_metrics, surface_metrics_of, SurfaceMetrics, SurfaceOptions};
pub use validity::{validity, Validity};
