//! The crate's error type.

use std::path::PathBuf;

use crate::model::Method;

/// What went wrong.
#[derive(Debug, thiserror::Error)]
pub enum MnistError {
    /// An IDX file is unreadable or malformed.
    #[error("{path}: {message}", path = path.display())]
    Idx {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// An image and a label file disagree.
    #[error("{images} and {labels}: {message}", images = images.display(), labels = labels.display())]
    Mismatch {
        /// The images file.
        images: PathBuf,
        /// The labels file.
        labels: PathBuf,
        /// How they disagree.
        message: String,
    },
    /// The data folder lacks a set.
    #[error("{dir}: {message}", dir = dir.display())]
    Missing {
        /// The folder.
        dir: PathBuf,
        /// What is missing.
        message: String,
    },
    /// A setting is out of range.
    #[error("{0}")]
    Config(String),
    /// A checkpoint or model file is missing, unreadable, malformed, or from another
    /// setting.
    #[error("{path}: {message}", path = path.display())]
    Checkpoint {
        /// The checkpoint.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// The [`pipeline`](crate::pipeline)'s options do not fit the data or each other (no
    /// data given, a malformed pair, a method missing, images of another size); the
    /// message names the file or the command-line flag.
    #[error("{0}")]
    Options(String),
    /// Writing an output failed (nothing half-written is left).
    #[error("{0}")]
    Write(String),
    /// The run was interrupted (the last checkpoint is kept).
    #[error("interrupted; the last checkpoint is kept and the run resumes from it")]
    Interrupted,
    /// [`pipeline::train_methods`](crate::pipeline::train_methods) was interrupted while
    /// training `method`; its checkpoint is saved.
    #[error(
        "interrupted while training {}; the checkpoint {} is saved: run the same command again to resume",
        method.name(),
        checkpoint.display()
    )]
    TrainingInterrupted {
        /// The method in training.
        method: Method,
        /// Its checkpoint, from which training resumes.
        checkpoint: PathBuf,
    },
}

impl MnistError {
    /// Whether the input (the data, a checkpoint, a setting or an option) is at fault, as
    /// opposed to an output that cannot be written or an interruption.
    pub fn is_input_fault(&self) -> bool {
        matches!(
            self,
            MnistError::Idx { .. }
                | MnistError::Mismatch { .. }
                | MnistError::Missing { .. }
                | MnistError::Config(_)
                | MnistError::Checkpoint { .. }
                | MnistError::Options(_)
        )
    }
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
