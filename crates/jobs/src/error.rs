//! The crate's one error type.

use std::path::PathBuf;

/// Why a job failed. [`Error::is_input_fault`] tells the user's inputs (exit 2 in the CLI)
/// from other failures (exit 1); [`Error::Interrupted`] is a run stopped on request.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The inputs or options are unusable: the message says why (and names the file).
    #[error("{0}")]
    Input(String),
    /// Training stopped on request (the interrupt flag, or `stop_after`) after writing its
    /// checkpoint.
    #[error("stopped at step {step} of {steps}; checkpoint {}", checkpoint.display())]
    Interrupted {
        /// Steps done.
        step: usize,
        /// Steps planned.
        steps: usize,
        /// The checkpoint to resume from.
        checkpoint: PathBuf,
        /// The input mesh.
        mesh: PathBuf,
        /// The crust that was to be written.
        output: PathBuf,
    },
    /// The fit.
    #[error(transparent)]
    Fit(Box<fit::FitError>),
    /// Reading or writing a mesh, or any atomic write.
    #[error(transparent)]
    Mesh(Box<mesh_io::MeshError>),
    /// Writing the sites file.
    #[error(transparent)]
    Sites(Box<crust::SitesFileError>),
    /// The picture or the viewer page.
    #[error(transparent)]
    Viewer(Box<viewer::Error>),
    /// Anything else that is not the input's fault (a folder that cannot be created or
    /// renamed, a panic in a fit): the message names the file.
    #[error("{0}")]
    Failure(String),
}

vf_common::boxed_from!(Error; Fit: fit::FitError, Mesh: mesh_io::MeshError, Sites: crust::SitesFileError, Viewer: viewer::Error);

impl Error {
    /// An error in the input file `path`: `path: message`.
    pub fn input_in(path: &std::path::Path, message: impl std::fmt::Display) -> Self {
        Error::Input(format!("{}: {message}", path.display()))
    }

    /// Whether the inputs (files, options) are at fault rather than the machine or a bug.
    pub fn is_input_fault(&self) -> bool {
        match self {
            Error::Input(_) => true,
            Error::Fit(e) => e.is_input_fault(),
            Error::Mesh(e) => e.kind != mesh_io::ErrorKind::Write,
            Error::Sites(e) => !matches!(**e, crust::SitesFileError::Write(_)),
            Error::Viewer(e) => e.is_input_fault(),
            Error::Interrupted { .. } | Error::Failure(_) => false,
        }
    }
}

/// An error and its causes as one paragraph: the error, then each cause its text does not
/// already contain, in parentheses (as the CLI prints errors and `summary.csv` records
/// them).
pub fn message_with_causes(e: &(dyn std::error::Error + 'static)) -> String {
    let mut out = e.to_string();
    let head = out.clone();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !head.contains(&text) {
            out.push_str(&format!(" ({text})"));
        }
        cause = c.source();
    }
    out
}
