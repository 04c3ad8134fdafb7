//! The binary's error type: every failure is the user's input (exit 2), a stopped run
//! (exit 130, after its checkpoint) or something else (exit 1), and prints as one
//! paragraph.
//!
//! Each library crate's error converts with `?`, classified by [`InputFault`]: whether
//! the input (a file, an argument) is at fault. [`InFile::in_file`] adds the file's name
//! to errors that do not carry it.

use std::fmt;
use std::path::Path;

/// An error that ends the program.
pub enum CliError {
    /// The input files or arguments are wrong: exit code 2.
    BadInput(anyhow::Error),
    /// A run stopped on request (Ctrl-C) after saving its checkpoint; the message says how
    /// to continue: exit code 130.
    Interrupted(String),
    /// Anything else (an output that cannot be written, an internal failure): exit code 1.
    Failure(anyhow::Error),
}

impl CliError {
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::BadInput(_) => 2,
            CliError::Interrupted(_) => 130,
            CliError::Failure(_) => 1,
        }
    }

    /// An error in the arguments or inputs, from a message.
    pub fn input(message: impl fmt::Display) -> Self {
        CliError::BadInput(anyhow::anyhow!("{message}"))
    }

    /// An error in the input file `path`, from a message (printed after the file's name).
    pub fn input_in(path: &Path, message: impl fmt::Display) -> Self {
        CliError::input(format!("{}: {message}", path.display()))
    }

    /// An error that is not the input's fault, from a message.
    pub fn failure(message: impl fmt::Display) -> Self {
        CliError::Failure(anyhow::anyhow!("{message}"))
    }
}

/// Whether an error is the input's fault (exit 2) or not (exit 1).
pub trait InputFault {
    fn is_input_fault(&self) -> bool;
}

/// Reading a mesh: the input's fault, except failing to write.
impl InputFault for mesh_io::MeshError {
    fn is_input_fault(&self) -> bool {
        self.kind != mesh_io::ErrorKind::Write
    }
}

/// The oracle and samplers reject meshes, queries and settings; all come from the input.
impl InputFault for occupancy::OccupancyError {
    fn is_input_fault(&self) -> bool {
        !matches!(self, occupancy::OccupancyError::OutputLength { .. })
    }
}

/// Delaunay fails on unusable points (non-finite, too few, out of range).
impl InputFault for delaunay3::DelaunayError {
    fn is_input_fault(&self) -> bool {
        true
    }
}

/// The crust rejects sites; an internal error is ours.
impl InputFault for crust::CrustError {
    fn is_input_fault(&self) -> bool {
        !matches!(self, crust::CrustError::Internal(_))
    }
}

/// A sites file that cannot be read is the input's; one that cannot be written is not.
impl InputFault for crust::SitesFileError {
    fn is_input_fault(&self) -> bool {
        !matches!(self, crust::SitesFileError::Write(_))
    }
}

/// Metrics reject meshes and options; a failing oracle inside them is classified as its own.
impl InputFault for metrics::MetricsError {
    fn is_input_fault(&self) -> bool {
        match self {
            metrics::MetricsError::Occupancy(e) => e.is_input_fault(),
            _ => true,
        }
    }
}

impl InputFault for fit::FitError {
    fn is_input_fault(&self) -> bool {
        fit::FitError::is_input_fault(self)
    }
}

impl InputFault for vf_common::npz::NpzError {
    fn is_input_fault(&self) -> bool {
        false
    }
}

impl InputFault for baselines::BaselineError {
    fn is_input_fault(&self) -> bool {
        false
    }
}

impl InputFault for study::StudyError {
    fn is_input_fault(&self) -> bool {
        study::StudyError::is_input_fault(self)
    }
}

impl<E: InputFault + std::error::Error + Send + Sync + 'static> From<E> for CliError {
    fn from(e: E) -> Self {
        if e.is_input_fault() {
            CliError::BadInput(e.into())
        } else {
            CliError::Failure(e.into())
        }
    }
}

impl From<anyhow::Error> for CliError {
    fn from(e: anyhow::Error) -> Self {
        CliError::Failure(e)
    }
}

/// Prefixes an error with the file it concerns, keeping its classification.
pub trait InFile<T> {
    fn in_file(self, path: &Path) -> Result<T, CliError>;
}

impl<T, E: InputFault + fmt::Display> InFile<T> for Result<T, E> {
    fn in_file(self, path: &Path) -> Result<T, CliError> {
        self.map_err(|e| {
            let message = format!("{}: {e}", path.display());
            if e.is_input_fault() {
                CliError::input(message)
            } else {
                CliError::failure(message)
            }
        })
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = match self {
            CliError::BadInput(e) | CliError::Failure(e) => e,
            CliError::Interrupted(m) => return write!(f, "{m}"),
        };
        // One paragraph: the error, then its causes, joined.
        write!(f, "{e}")?;
        for cause in e.chain().skip(1) {
            let c = cause.to_string();
            if !e.to_string().contains(&c) {
                write!(f, " ({c})")?;
            }
        }
        Ok(())
    }
}
