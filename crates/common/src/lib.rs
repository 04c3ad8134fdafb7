//! Helpers that several voronoi-fit crates need, each with one home:
//!
//! - [`rng`]: SplitMix64 and xoshiro256++ generators and the table of named random
//!   streams ([`rng::Stream`]) every crate draws from, so no two places pick the same
//!   number by hand;
//! - [`adam`]: the Adam optimiser's settings and update, used by the soft-Voronoi
//!   trainer (f64 sites) and the MLP baselines (f32/f64 weights);
//! - [`vec3`]: the f64 vector helpers on `[f64; 3]` (sub, dot, cross, norm, …) the
//!   crates share, each in one fixed evaluation order;
//! - [`text`]: thousands separators and the boxed-`From` macro of the error types;
//! - [`npz`] (feature `npz`, on by default): an uncompressed `.npz` built in memory and
//!   written atomically (sites files, checkpoints, CLI outputs).

pub mod adam;
#[cfg(feature = "npz")]
pub mod npz;
pub mod rng;
pub mod text;
pub mod vec3;

pub use adam::AdamParams;
pub use rng::{ChunkRng, SplitMix64, Stream};
