//! The one error type of this crate.

use thiserror::Error;

/// Everything that can go wrong when measuring two meshes.
///
/// `mesh` names the mesh as the caller passed it (`"reference"`, `"prediction"`, `"A"`,
/// `"B"`); messages say how to fix the input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MetricsError {
    /// The mesh has no triangles (or no vertices).
    #[error("the {mesh} mesh has no triangles; every metric needs at least one triangle")]
    Empty {
        /// Which mesh: "reference" or "prediction".
        mesh: &'static str,
    },
    /// A vertex coordinate is NaN, infinite or larger than the occupancy crate accepts.
    #[error(
        "vertex {vertex} of the {mesh} mesh has coordinate {value}, which is not finite or exceeds {limit:e} in \
         magnitude; repair or rescale the mesh"
    )]
    BadVertex {
        /// Which mesh: "reference" or "prediction".
        mesh: &'static str,
        /// The vertex's index (or, for a triangle, the index it refers to).
        vertex: usize,
        /// The offending coordinate.
        value: f64,
        /// The largest magnitude accepted.
        limit: f64,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "triangle {triangle} of the {mesh} mesh refers to vertex {vertex}, but the mesh has {num_vertices} vertices"
    )]
    VertexOutOfRange {
        /// Which mesh: "reference" or "prediction".
        mesh: &'static str,
        /// The triangle's index.
        triangle: usize,
        /// The vertex's index (or, for a triangle, the index it refers to).
        vertex: u32,
        /// Vertices in the mesh.
        num_vertices: usize,
    },
    /// Surface sampling needs a positive total area.
    #[error(
        "the {mesh} mesh has total surface area {area}; surface sampling (Chamfer, F-score, normal consistency) \
         needs a positive, finite area"
    )]
    ZeroArea {
        /// Which mesh: "reference" or "prediction".
        mesh: &'static str,
        /// Its total surface area.
        area: f64,
    },
    /// An option is out of its documented range.
    #[error("invalid metrics option: {0}")]
    BadOption(String),
    /// An error of the occupancy oracle (should not happen on validated input).
    #[error("occupancy oracle: {0}")]
    Occupancy(#[from] occupancy::OccupancyError),
}
