//! The one error type of this crate.
//!
//! Every error names the file, where in it the problem is (a line for text formats, an
//! element index or byte offset for binary ones) and what the user can do about it.

use std::fmt;
use std::path::{Path, PathBuf};

/// What went wrong, for callers that branch on it (the CLI maps all of them except
/// [`ErrorKind::Write`] to "bad input").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ErrorKind {
    /// The file could not be opened or read.
    Io,
    /// The extension and the content match no supported format.
    UnknownFormat,
    /// Text or structure that does not parse.
    Syntax,
    /// A binary file ends before the data its header promises.
    Truncated,
    /// A coordinate is NaN or infinite.
    NonFinite,
    /// Finite, but outside the range this program handles: a coordinate beyond ±1e30, an
    /// extent below 1e-30, or float32 output that cannot resolve the mesh (see
    /// [`crate::limits`]).
    Unrepresentable,
    /// A face refers to a vertex that does not exist.
    IndexOutOfRange,
    /// The file parses but holds no triangle.
    Empty,
    /// Valid in its format, but a feature this program does not read.
    Unsupported,
    /// Writing an output failed (disk full, permissions, ...).
    Write,
}

/// Where in the file the problem is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// The whole file.
    File,
    /// A 1-based line of a text file.
    Line(usize),
    /// A byte offset into a binary file.
    Byte(u64),
    /// The `index`-th (0-based) element of a kind, such as `face 12` or `vertex 3`.
    Element {
        /// The element's kind, such as `face` or `vertex`.
        kind: &'static str,
        /// Its 0-based index.
        index: usize,
    },
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::File => Ok(()),
            Location::Line(n) => write!(f, ", line {n}"),
            Location::Byte(b) => write!(f, ", byte {b}"),
            Location::Element { kind, index } => write!(f, ", {kind} {index}"),
        }
    }
}

/// An error reading or writing a mesh file.
///
/// Displayed as one paragraph: `FILE, LOCATION: what is wrong. What to do.`
#[derive(Debug)]
pub struct MeshError {
    /// What class of problem it is (it decides the default hint and the exit code).
    pub kind: ErrorKind,
    /// The file.
    pub path: PathBuf,
    /// Where in the file.
    pub location: Location,
    /// What is wrong, without the file name.
    pub message: String,
    /// How to fix it, as one sentence (may be empty).
    pub hint: String,
    source: Option<std::io::Error>,
}

impl MeshError {
    /// An error of `kind` at `location` in `path`, with the kind's default hint.
    pub fn new(kind: ErrorKind, path: &Path, location: Location, message: impl Into<String>) -> Self {
        MeshError {
            kind,
            path: path.to_path_buf(),
            location,
            message: message.into(),
            hint: default_hint(kind).to_string(),
            source: None,
        }
    }

    /// Replace the default hint for the error kind.
    pub fn hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = hint.into();
        self
    }

    /// The file cannot be read.
    pub fn io(path: &Path, err: std::io::Error) -> Self {
        let message = format!("cannot read the file ({err})");
        let mut e = MeshError::new(ErrorKind::Io, path, Location::File, message);
        e.source = Some(err);
        e
    }

    /// The file cannot be written.
    pub fn write(path: &Path, err: std::io::Error) -> Self {
        let message = format!("cannot write the file ({err})");
        let mut e = MeshError::new(ErrorKind::Write, path, Location::File, message);
        e.source = Some(err);
        e
    }
}

fn default_hint(kind: ErrorKind) -> &'static str {
    match kind {
        ErrorKind::Io => "Check that the path exists and is readable.",
        ErrorKind::UnknownFormat => {
            "Supported inputs are .obj, .stl, .ply, .off, .gltf and .glb; convert the file to one of them."
        }
        ErrorKind::Syntax => "The file is malformed; re-export it from the program that made it.",
        ErrorKind::Truncated => "The file is cut short (an interrupted copy or download?); re-export or copy it again.",
        ErrorKind::NonFinite => {
            "Every coordinate must be a finite number; remove or repair the vertex in the program that made the file."
        }
        ErrorKind::Unrepresentable => "Rescale the mesh in the program that made it.",
        ErrorKind::IndexOutOfRange => {
            "Faces may only refer to vertices the file defines; re-export the mesh or remove the face."
        }
        ErrorKind::Empty => "The mesh needs at least one triangle; check that the right file was given.",
        ErrorKind::Unsupported => "Convert the file to plain triangles (for example with Blender or meshlab).",
        ErrorKind::Write => "Check that the output folder exists, is writable and has free space.",
    }
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}{}: {}.", self.path.display(), self.location, self.message)?;
        if !self.hint.is_empty() {
            write!(f, " {}", self.hint)?;
        }
        Ok(())
    }
}

impl std::error::Error for MeshError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source.as_ref().map(|e| e as _)
    }
}

/// Shorthand used by the readers.
pub(crate) type Result<T> = std::result::Result<T, MeshError>;
