//! VoronoiNet as a network: the MNIST autoencoder of the seed paper.
//!
//! An encoder (four fully connected layers of 1,024 units → a 16-d code) maps a digit to a
//! code; a decoder maps the code to a shape in the unit square. The Voronoi decoder (three
//! layers of 1,024 → 128 sites, the first 64 inside) is trained through the soft-Voronoi
//! occupancy of the `soft_voronoi` crate in two dimensions (the same generic kernel and
//! losses as the 3D main job); the OccNet decoders (one hidden layer of 128, 512 or 16,384
//! units on [code; point]) with binary cross-entropy. Every method sees the same training
//! points. [`digit`] defines the occupancy of an image, [`idx`] reads the data as
//! published, [`eval`] makes the seed's table, [`figures`] the tSNE and interpolation
//! pictures. [`pipeline`] runs the experiment end to end as the `voronoi-fit mnist`
//! commands do: training with checkpoints that resume, evaluation, tSNE, interpolation and
//! the throughput benchmark, writing their files.

pub mod digit;
mod error;
pub mod eval;
pub mod figures;
pub mod idx;
pub mod model;
pub mod net;
pub mod pipeline;
pub mod train;
pub mod tsne;

pub use error::MnistError;
pub use idx::DigitSet;
pub use model::{Method, Model};
pub use train::{TrainSettings, TrainState};
