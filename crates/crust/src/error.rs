//! The crate's error type.

/// Why a crust could not be built.
#[derive(Debug, thiserror::Error)]
pub enum CrustError {
    /// `sites` and `labels` differ in length.
    #[error("{num_sites} sites but {num_labels} labels; give one label per site")]
    LengthMismatch {
        /// Sites given.
        num_sites: usize,
        /// Labels given.
        num_labels: usize,
    },
    /// A site coordinate is NaN or infinite.
    #[error("site {index} is {position:?}, not finite; remove or repair it")]
    NonFinite {
        /// The site's index.
        index: usize,
        /// Its coordinates as given.
        position: [f64; 3],
    },
    /// A site is not strictly inside the domain box.
    #[error("site {index} at {position:?} is not strictly inside the domain box {lo:?}..{hi:?}; move it inside (training clamps sites) or enlarge the box")]
    OutsideBox {
        /// The site's index.
        index: usize,
        /// Its coordinates.
        position: [f64; 3],
        /// The box's lower corner.
        lo: [f64; 3],
        /// The box's upper corner.
        hi: [f64; 3],
    },
    /// The domain box is empty or not finite.
    #[error("the domain box {lo:?}..{hi:?} is empty or not finite")]
    BadBox {
        /// The box's lower corner.
        lo: [f64; 3],
        /// The box's upper corner.
        hi: [f64; 3],
    },
    /// The Delaunay tetrahedralization failed.
    #[error("Delaunay tetrahedralization of the sites failed: {0}")]
    Delaunay(#[from] delaunay3::DelaunayError),
    /// The crust cannot be written as asked: the map to the output frame or the output's
    /// precision cannot hold it ([`crate::output::finalize`]).
    #[error("the crust cannot be written in the output's frame and precision: {0}")]
    Unwritable(String),
    /// Planar sites that cannot make a diagram ([`crate::planar::planar_diagram`]).
    #[error("planar sites: {0}")]
    Planar(String),
    /// A guarantee failed to hold: a bug, reported rather than written out.
    #[error("internal error, the crust would not be valid: {0}")]
    Internal(String),
}

/// Why a sites file could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum SitesFileError {
    /// The file cannot be read.
    #[error("{path}: cannot read the file ({source})")]
    Io {
        /// The sites file.
        path: String,
        /// What the system said.
        source: std::io::Error,
    },
    /// The file's contents are not a sites file (missing or malformed arrays).
    #[error("{path}: {message}")]
    Invalid {
        /// The sites file.
        path: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// Writing the file failed.
    #[error(transparent)]
    Write(#[from] mesh_io::MeshError),
}
