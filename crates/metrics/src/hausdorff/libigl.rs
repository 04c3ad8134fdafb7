//! The libigl-compatible Hausdorff distance (vertices only; see the module doc of
//! [`crate::hausdorff`]).

use mesh_io::TriMesh;
use occupancy::BvhPreset;

use super::mesh::{query_points, DistanceMesh};
use crate::MetricsError;

/// libigl's `igl::hausdorff(VA, FA, VB, FB)`: `sqrt(max(max_i d²(VA_i, B), max_j d²(VB_j, A)))`
/// over every vertex (referenced or not), mesh units.
///
/// # Errors
/// As [`check_mesh`](super::check_mesh) (`a` is named "A", `b` "B").
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
