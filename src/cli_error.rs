//! The binary's error type: every failure is either the user's input (exit 2) or
//! something else (exit 1), and prints as one paragraph.

use std::fmt;

/// An error that ends the program.
pub enum CliError {
    /// The input files or arguments are wrong: exit code 2.
    BadInput(anyhow::Error),
    /// Anything else (an output that cannot be written, an internal failure): exit code 1.
    Failure(anyhow::Error),
}

impl CliError {
    pub fn exit_code(&self) -> i32 {
        match self {
            CliError::BadInput(_) => 2,
            CliError::Failure(_) => 1,
        }
    }
}

/// Errors from reading a mesh are the user's input, except failures to write.
impl From<mesh_io::MeshError> for CliError {
    fn from(e: mesh_io::MeshError) -> Self {
        if e.kind == mesh_io::ErrorKind::Write {
            CliError::Failure(e.into())
        } else {
            CliError::BadInput(e.into())
        }
    }
}

impl From<anyhow::Error> for CliError {
    fn from(e: anyhow::Error) -> Self {
        CliError::Failure(e)
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = match self {
            CliError::BadInput(e) | CliError::Failure(e) => e,
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

/// Mark an error as the user's input.
#[allow(dead_code)] // used by subcommands as they land
pub trait BadInputExt<T> {
    fn bad_input(self) -> Result<T, CliError>;
}

impl<T, E: Into<anyhow::Error>> BadInputExt<T> for Result<T, E> {
    fn bad_input(self) -> Result<T, CliError> {
        self.map_err(|e| CliError::BadInput(e.into()))
    }
}
