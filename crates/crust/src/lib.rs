//! Watertight Voronoi crust and convex cells from labelled sites.
//!
//! Entry points: [`Crust::extract`] (the crust, the set of Voronoi faces between an inside
//! and an outside site, as a closed oriented manifold [`mesh_io::TriMesh`]),
//! [`Crust::cells`] (every inside cell as a closed convex polyhedron), [`check::check_crust`]
//! (the exact checker of the guarantees), [`output::finalize`] (the crust exactly as a file
//! in the mesh frame and the format's precision will hold it, repaired or refused, and
//! checked), and [`SitesFile`] (the `.npz` sites format shared with training).
//!
//! The surface is "the boundary of (union of inside cells) ∩ box" of the VoronoiNet paper
//! (Williams, Panozzo, Yi, Tagliasacchi), read off an exact Delaunay tetrahedralization
//! ([`delaunay3`]): each Delaunay edge with opposite labels is dual to a Voronoi face whose
//! corners are the circumcentres of the tetrahedra around the edge.

// Index loops read like the formulas here; `!(x > 0.0)` is deliberate: it is true for NaN.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod check;
pub mod circumcenter;
mod error;
mod extract;
mod manifold;
pub mod output;
pub mod planar;
pub mod prune;
mod resolve;
mod sites_file;

pub use error::{CrustError, SitesFileError};
pub use extract::{Crust, CrustConfig, CrustStats};
pub use sites_file::SitesFile;
