//! The crate's error type.

use std::path::PathBuf;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum MnistError {
    /// An IDX file is unreadable or malformed.
    #[error("{path}: {message}", path = path.display())]
    Idx { path: PathBuf, message: String },
    /// An image and a label file disagree.
    #[error("{images} and {labels}: {message}", images = images.display(), labels = labels.display())]
    Mismatch { images: PathBuf, labels: PathBuf, message: String },
    /// The data folder lacks a set.
    #[error("{dir}: {message}", dir = dir.display())]
    Missing { dir: PathBuf, message: String },
    /// A setting is out of range.
    #[error("{0}")]
    Config(String),
    /// A checkpoint or model file is unreadable, malformed, or from another setting.
    #[error("{path}: {message}", path = path.display())]
    Checkpoint { path: PathBuf, message: String },
    /// Writing an output failed (nothing half-written is left).
    #[error("{0}")]
    Write(String),
    /// The run was interrupted (the last checkpoint is kept).
    #[error("interrupted; the last checkpoint is kept and the run resumes from it")]
    Interrupted,
}

impl From<mesh_io::MeshError> for MnistError {
    fn from(e: mesh_io::MeshError) -> Self {
        MnistError::Write(e.to_string())
    }
}

impl From<plot::PlotError> for MnistError {
    fn from(e: plot::PlotError) -> Self {
        MnistError::Write(e.to_string())
    }
}

impl From<vf_common::npz::NpzError> for MnistError {
    fn from(e: vf_common::npz::NpzError) -> Self {
        MnistError::Write(e.to_string())
    }
}
