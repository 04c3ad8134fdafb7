//! Differentiable soft-Voronoi occupancy (VoronoiNet: Williams, Panozzo, Yi, Tagliasacchi)
//! and its training.
//!
//! A shape is K sites in the unit cube with fixed inside/outside labels, plus fixed outside
//! sites on the cube's faces. Its occupancy is the label of the nearest site; training
//! replaces the argmin by a softmax of −β·distance ([`kernel`]) and moves the sites with
//! Adam (`vf_common::adam`) on four losses ([`losses`]): reconstruction E|O − V|, bounds, signed
//! distance of each site to its side of the surface, and centroidal ‖L p‖² on the
//! Delaunay graph of the sites. [`Trainer`] runs it step by step and [`checkpoint`] saves
//! and restores its state bit-exactly.
//!
//! The kernel is sparse: a k-d tree over the sites (kiddo) gives each sample its nearest
//! site and the few sites within τ/β of it, instead of the dense N×K softmax.

pub mod checkpoint;
pub mod config;
pub mod data;
pub mod dense;
pub mod error;
pub mod grid;
pub mod init;
pub mod kernel;
pub mod knn;
pub mod losses;
pub mod polish;
pub mod solid;
pub mod train;

pub use config::{Density, Init, TrainConfig, Weights};
pub use error::TrainError;
pub use kernel::{Kernel, SiteIndex};
pub use losses::{Located, SiteGraph, Solid};
pub use polish::{PolishConfig, PolishReport};
pub use solid::{FloodSolid, MeshSolid, ShellSolid, Sphere, SurfaceSide};
pub use train::{classify, soft_values, BestIterate, StepStats, TrainState, Trainer, TrainingData};
pub use vf_common::AdamParams;
