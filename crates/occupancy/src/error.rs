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
    VertexOutOfRange { triangle: usize, vertex: u32, num_vertices: usize },
    /// A vertex coordinate is NaN, infinite or too large.
    #[error(
        "vertex {vertex} has coordinate {value} which is not finite or exceeds {limit:e} in magnitude; \
         rescale or repair the mesh"
    )]
    BadVertex { vertex: usize, value: f64, limit: f64 },
    /// A query point coordinate is NaN, infinite or too large.
    #[error("query point {index} has coordinate {value} which is not finite or exceeds {limit:e} in magnitude")]
    BadQuery { index: usize, value: f64, limit: f64 },
    /// A configuration field is out of its documented range.
    #[error("invalid configuration: {0}")]
    BadConfig(String),
    /// A sampler was asked for something impossible.
    #[error("invalid sampler request: {0}")]
    BadSampler(String),
    /// Output buffer length does not match the number of queries.
    #[error("output buffer has length {got} but {expected} queries were given")]
    OutputLength { expected: usize, got: usize },
}
