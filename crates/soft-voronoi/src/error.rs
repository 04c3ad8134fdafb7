//! Errors of training and checkpoints.

/// What can go wrong while training or reading a checkpoint.
#[derive(Debug, thiserror::Error)]
pub enum TrainError {
    /// A setting is out of range; the message names it and the accepted range.
    #[error("invalid training setting: {0}")]
    Config(String),
    /// The training data is unusable (empty, non-finite, one class only...).
    #[error("invalid training data: {0}")]
    Data(String),
    /// The Delaunay graph of the sites could not be built.
    #[error("Delaunay graph of the sites: {0}")]
    Delaunay(#[from] delaunay3::DelaunayError),
    /// A site or a loss became non-finite.
    #[error("training diverged at step {step}: {what}; lower the learning rate (--lr)")]
    Diverged {
        /// Step at which it was noticed.
        step: usize,
        /// What became non-finite.
        what: String,
    },
    /// A checkpoint could not be read, written, or does not match this run.
    #[error("checkpoint {path}: {message}")]
    Checkpoint {
        /// The checkpoint file.
        path: String,
        /// What is wrong and how to fix it.
        message: String,
    },
}
