//! The fit's error: whether it is the input's fault decides the CLI's exit code (2 or 1).

use std::path::PathBuf;

/// Why a fit did not finish.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The input mesh or the settings are unusable; the message says how to fix them.
    #[error("{0}")]
    Input(String),
    /// Training was stopped on request after writing its checkpoint.
    #[error("stopped at step {step} of {steps}; checkpoint {}", checkpoint.display())]
    Interrupted {
        /// Steps done.
        step: usize,
        /// Steps planned.
        steps: usize,
        /// Where the state was saved.
        checkpoint: PathBuf,
    },
    /// Anything else (a failure while training, a crust that fails its check, a file that
    /// cannot be written).
    #[error("{0}")]
    Failure(String),
}

impl FitError {
    /// Whether the input (mesh, settings, checkpoint) is at fault.
    pub fn is_input_fault(&self) -> bool {
        matches!(self, FitError::Input(_))
    }
}
