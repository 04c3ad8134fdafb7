//! The samplers' generators live in `vf_common::rng` (one home for the workspace's RNGs
//! and its table of named streams); re-exported here for the samplers' callers.

pub use vf_common::rng::{splitmix64, ChunkRng, Stream};
