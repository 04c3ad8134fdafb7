//! The one error enum of this crate.

use thiserror::Error;

/// Everything that can go wrong when building an oracle or answering queries.
///
/// Messages say how to fix the input.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum OccupancyError {
    /// The mesh has no triangles.
    #[error("the mesh has no triangles; the oracle needs at least one triangle")]
    NoTriangles,
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {vertex} but the mesh has {num_vertices} vertices")]
    VertexOutOfRange {
        /// The triangle's index.
        triangle: usize,
        /// The vertex's index (or, for a triangle, the index it refers to).
        vertex: u32,
        /// Vertices in the mesh.
        num_vertices: usize,
    },
    /// A vertex coordinate is NaN, infinite or too large.
    #[error(
        "vertex {vertex} has coordinate {value} which is not finite or exceeds {limit:e} in magnitude; \
         rescale or repair the mesh"
    )]
    BadVertex {
        /// The vertex's index (or, for a triangle, the index it refers to).
        vertex: usize,
        /// The offending coordinate.
        value: f64,
        /// The largest magnitude accepted.
        limit: f64,
    },
    /// A query point coordinate is NaN, infinite or too large.
    #[error("query point {index} has coordinate {value} which is not finite or exceeds {limit:e} in magnitude")]
    BadQuery {
        /// The query point's index.
        index: usize,
        /// The offending coordinate.
        value: f64,
        /// The largest magnitude accepted.
        limit: f64,
    },
    /// A configuration field is out of its documented range.
    #[error("invalid configuration: {0}")]
    BadConfig(String),
    /// A sampler was asked for something impossible.
    #[error("invalid sampler request: {0}")]
    BadSampler(String),
    /// Output buffer length does not match the number of queries.
    #[error("output buffer has length {got} but {expected} queries were given")]
    OutputLength {
        /// Queries given.
        expected: usize,
        /// The buffer's length.
        got: usize,
    },
}
