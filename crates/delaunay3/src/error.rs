//! The crate's error types.

/// Why [`crate::Delaunay3::new`] refused its input or could not finish.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DelaunayError {
    /// A coordinate is NaN or infinite.
    #[error(
        "point {index} has a non-finite coordinate {coords:?}; remove or repair NaN/infinite points before triangulating"
    )]
    NonFinite {
        /// Index of the offending point in the input slice.
        index: usize,
        /// Its coordinates as given.
        coords: [f64; 3],
    },
    /// The nonzero coordinates span more binary orders of magnitude than the exact
    /// predicates can handle even after power-of-two rescaling (see
    /// [`crate::normalize::SafeRange`]).
    #[error(
        "coordinates span too wide a range for exact predicates: the smallest nonzero |coordinate| is {min_abs:e} (point {min_index}) and the largest is {max_abs:e} (point {max_index}), a ratio of about 2^{span_bits}; at most 2^{max_span_bits} is supported. Snap tiny coordinates to 0 or drop far-away points"
    )]
    RangeTooWide {
        /// Smallest nonzero absolute coordinate.
        min_abs: f64,
        /// Point holding it.
        min_index: usize,
        /// Largest absolute coordinate.
        max_abs: f64,
        /// Point holding it.
        max_index: usize,
        /// floor(log2 max_abs) − floor(log2 min_abs).
        span_bits: i32,
        /// The supported maximum of `span_bits`.
        max_span_bits: i32,
    },
    /// Fewer than four affinely independent points: no tetrahedron exists.
    #[error(
        "need at least 4 affinely independent points, but the {num_points} input points (after merging {num_distinct} distinct) {shape}; a 3D Delaunay tetrahedralization does not exist"
    )]
    Degenerate {
        /// Number of input points.
        num_points: usize,
        /// Number of distinct points (counted up to the first 3 found).
        num_distinct: usize,
        /// Dimension of the affine hull: −1 (no points), 0, 1 or 2.
        dimension: i32,
        /// Human-readable description of the degeneracy.
        shape: &'static str,
    },
    /// More points than the u32 vertex ids allow.
    #[error("{num_points} points exceed the supported maximum of {max_points}")]
    TooManyPoints {
        /// Number of input points.
        num_points: usize,
        /// The supported maximum.
        max_points: usize,
    },
    /// The tetrahedralization outgrew the u32 tetrahedron ids (2^30 tetrahedra); this
    /// needs a pathological input (the Delaunay tetrahedralization of n points has up to
    /// O(n²) tetrahedra, e.g. points on two skew lines).
    #[error(
        "the tetrahedralization exceeded {max_tets} tetrahedra after inserting {num_inserted} points; the input is too large or too degenerate (e.g. points on two skew lines have quadratically many tetrahedra)"
    )]
    TooManyTets {
        /// The supported maximum of tetrahedra (finite and infinite).
        max_tets: usize,
        /// Points inserted before the limit was hit.
        num_inserted: usize,
    },
}

/// A broken invariant found by [`crate::Delaunay3::validate`]. Its message names the
/// tetrahedron, face and vertices concerned.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid Delaunay tetrahedralization: {0}")]
pub struct ValidationError(pub String);
