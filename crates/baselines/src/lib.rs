//! MLP baselines for the sphere overfitting study: OccNet- and DeepSDF-style implicit
//! decoders trained with Adam, and marching cubes to turn a decoder back into a mesh.
//!
//! Entry points: [`DecoderConfig`] → [`Decoder::new`] (`Mlp<f32>`), [`train()`] (or
//! [`Trainer`] step by step) on [`TrainingData`] with a [`TrainConfig`],
//! [`Mlp::eval_grid`], [`marching_cubes()`], [`extract_mesh`].
//!
//! # Why the network is written by hand
//!
//! The decoders are plain fully connected ReLU networks on ndarray with hand-written
//! backpropagation instead of a deep-learning framework: on this project's 2-core build
//! machine candle and burn measured 11 and 25 minute clean builds, and slower CPU steps
//! (figures from the issue); this crate adds only ndarray (matrixmultiply GEMM, pure Rust,
//! already in the tree) and num-traits. Every gradient is checked against central finite
//! differences in `tests/gradients.rs` (both decoders, with and without skip connection,
//! every parameter); all buffers are preallocated per batch size (the only allocations in a
//! step are matrixmultiply's packing buffers, one per matrix product, `tests/alloc.rs`);
//! results are bit-identical for a seed whatever the thread count (see
//! [the `train` module](mod@crate::train) for the fixed-order parallel reduction).
//! Step speed (forward + backward + Adam, 3→256×5→1, batch 65,536, f32, 2 cores): 1.33
//! steps/s against 0.70 for PyTorch 2.15's CPU step (1.9×) and 0.93 for numpy, timed in one
//! run by `benches/compare_mlp.py` (details in this crate's README).

pub mod error;
pub mod mc;
pub mod mlp;
pub mod scalar;
pub mod train;

pub use error::{BaselineError, Result};
pub use mc::{extract_mesh, marching_cubes, Ambiguity, Inside, McOptions, DEFAULT_GRID_RES};
pub use mlp::{Decoder, DecoderConfig, DecoderKind, Mlp};
pub use scalar::Real;
pub use train::{
    loss_and_grad, train, GradEngine, Schedule, StepRecord, TrainConfig, TrainReport, Trainer, TrainingData,
};
pub use vf_common::AdamParams;
