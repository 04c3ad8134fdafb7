//! Ground-truth occupancy for voronoi-fit: generalized winding numbers, closest points,
//! signed distances and training samplers for triangle meshes that may be open, soups or
//! non-manifold.
//!
//! Entry type: [`MeshOracle`] (build once from positions and triangles, then query with a
//! per-thread [`Workspace`] or with the parallel batch functions). Samplers:
//! [`sample::uniform_in_box`], [`sample::SurfaceSampler`], [`sample::near_surface`].
//!
//! Algorithms:
//! - generalized winding number, exact: Jacobson, Kavan, Sorkine-Hornung 2013, with solid
//!   angles by Van Oosterom–Strackee 1983, summed hierarchically over a BVH with boundary
//!   caps ([`winding::exact`]);
//! - fast winding number: Barill, Dickson, Schmidt, Levin, Jacobson 2018, order-2 dipole
//!   expansion with accuracy β ([`winding::fast`]);
//! - closest point: Ericson 2005 point-triangle regions, BVH branch-and-bound
//!   ([`distance`]).
//!
//! The BVH is obvhs' `Bvh2` (PLOC build, no spatial splits) with this crate's f64 data in
//! parallel arrays ([`bvh`]).

pub mod bvh;
pub mod config;
pub mod distance;
pub mod error;
pub mod flood;
pub mod oracle;
pub mod order;
pub mod sample;
pub mod winding;
mod workspace;

pub use config::{BvhPreset, Config, MAX_COORDINATE};
pub use distance::ClosestPoint;
pub use error::OccupancyError;
pub use flood::FloodGrid;
pub use oracle::{validate_queries, MeshOracle, QueryBatch, QUERY_CHUNK};
pub use winding::WindingMode;
pub use workspace::Workspace;
