//! Exact 3D Delaunay tetrahedralization.
//!
//! Entry type: [`Delaunay3`] (`Delaunay3::new(&points)?`, then [`Delaunay3::validate`],
//! [`Delaunay3::finite_tets`], [`Delaunay3::edges`], [`Delaunay3::tets_around_edge`]).
//!
//! - Exact: Shewchuk's adaptive predicates (Shewchuk 1997, via the `robust` crate)
//!   behind an inlined stage-A filter; symbolic perturbation (Edelsbrunner & Mücke 1990,
//!   on the lifted coordinate as in Devillers & Teillaud 2011) so lattices, cospherical
//!   and coplanar sets get a valid, unique, order-independent result.
//! - Inputs are checked once and rescaled by an exact power of two into the range where
//!   the predicates cannot overflow or underflow ([`normalize::SafeRange`]).
//! - Incremental Bowyer–Watson insertion with an infinite vertex, BRIO + Hilbert order,
//!   remembering stochastic walk, compact `[u32; 4]` arrays.

mod build;
mod edges;
mod error;
mod fp;
pub mod normalize;
pub mod predicates;
mod spatial_sort;
mod triangulation;
mod validate;

pub use build::INFINITE;
pub use edges::{Edge, VertexTets};
pub use error::{DelaunayError, ValidationError};
pub use triangulation::{Delaunay3, MAX_POINTS};
