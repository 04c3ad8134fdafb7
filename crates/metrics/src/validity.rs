//! Validity of a reconstruction, from the mesh layer's topology report and the crust's
//! exact self-intersection checker.

use mesh_io::{TopologyReport, TriMesh};
use serde::Serialize;

/// Is the mesh a valid solid boundary?
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Validity {
    /// Closed, manifold, consistently oriented and free of self-intersections.
    pub is_valid_solid: bool,
    /// Every edge in exactly two faces (see [`TopologyReport::is_closed`]).
    pub is_closed: bool,
    /// Edge- and vertex-manifold.
    pub is_manifold: bool,
    /// Every edge used once in each direction.
    pub is_orientation_consistent: bool,
    /// Whether two triangles that share no vertex position intersect (exact test,
    /// [`crust::check::self_intersections`]).
    pub self_intersecting: bool,
    /// The first intersecting pair (smallest indices), if any.
    pub first_self_intersection: Option<[usize; 2]>,
    /// Connected components.
    pub num_components: usize,
    /// Total genus (`None` unless closed, manifold and oriented).
    pub genus: Option<i64>,
    /// Faces with a repeated vertex or collinear corners.
    pub num_degenerate_faces: usize,
    /// Enclosed volume for a closed, consistently oriented mesh.
    pub signed_volume: f64,
}

/// Validity report of `mesh` (no error: any mesh can be reported on).
///
/// # Complexity
/// O(F log F) for the report plus the grid broad phase of the intersection test.
pub fn validity(mesh: &TriMesh) -> Validity {
    let r = TopologyReport::of(mesh);
    let (_, hit) = crust::check::self_intersections(mesh, true);
    Validity {
        is_valid_solid: r.is_closed
            && r.is_manifold
            && r.is_orientation_consistent
            && hit.is_none()
            && !mesh.triangles.is_empty(),
        is_closed: r.is_closed,
        is_manifold: r.is_manifold,
        is_orientation_consistent: r.is_orientation_consistent,
        self_intersecting: hit.is_some(),
        first_self_intersection: hit.map(|(a, b)| [a, b]),
        num_components: r.num_components,
        genus: r.genus,
        num_degenerate_faces: r.num_degenerate_faces,
        signed_volume: r.signed_volume,
    }
}
