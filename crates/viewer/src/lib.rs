//! The viewer page of a fit and the main job's picture.
//!
//! - [`write_page`]: one self-contained HTML page (no network: three.js 0.180.0 from
//!   `assets/` is inlined, the meshes and points are embedded as base64) showing the input
//!   and the crust side by side or overlaid, the sites, the misclassified sample points,
//!   the convex cells, the loss curve and the stage timings. `voronoi-fit view`,
//!   `voronoi-fit fit --html` ([`write_fit_page`]) and Python's `voronoi_fit.view` call it.
//! - [`write_picture`]: OUT.png, the input (top row) and the crust (bottom row) from three
//!   sides, through [`plot::raster3d`].
//!
//! Files not given are looked for beside OUT.glb (OUT.sites.npz, OUT.report.json,
//! OUT.cells.glb; the input is the path the report names). A file given explicitly must
//! exist and be readable; one found beside OUT.glb must be well-formed; one that is simply
//! absent only leaves its part out of the page ([`Page::notes`] says which).

mod page;
mod picture;

use std::path::{Path, PathBuf};

pub use page::{write_fit_page, write_page, Page, PageOptions, DEFAULT_CHECK_SAMPLES};
pub use picture::{picture_path, write_picture, PictureFigures};

/// Why a page or picture could not be made. [`Error::is_input_fault`] tells the user's
/// inputs (exit 2 in the CLI, `InputError` in Python) from other failures.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An input file (or the page's path) is unusable: `path: message`.
    #[error("{}: {message}", path.display())]
    Input {
        /// The file at fault.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// Reading a mesh, or writing the page.
    #[error(transparent)]
    Mesh(Box<mesh_io::MeshError>),
    /// Reading the sites file.
    #[error(transparent)]
    Sites(Box<crust::SitesFileError>),
    /// Classifying fresh samples against the input.
    #[error(transparent)]
    Occupancy(Box<occupancy::OccupancyError>),
    /// Drawing the picture.
    #[error(transparent)]
    Plot(Box<plot::PlotError>),
    /// Writing the picture `path`.
    #[error("{}: {source}", path.display())]
    Picture {
        /// The picture's path.
        path: PathBuf,
        /// The plotting crate's error.
        source: Box<plot::PlotError>,
    },
    /// The page itself could not be put together (a template or vendored script that
    /// cannot be inlined): a bug, not the input's fault.
    #[error("{0}")]
    Page(String),
}

vf_common::boxed_from!(Error; Mesh: mesh_io::MeshError, Sites: crust::SitesFileError, Occupancy: occupancy::OccupancyError, Plot: plot::PlotError);

impl Error {
    /// An error in the input file `path`.
    pub fn input(path: &Path, message: impl std::fmt::Display) -> Self {
        Error::Input { path: path.to_path_buf(), message: message.to_string() }
    }

    /// Whether the inputs are at fault (a missing or malformed file) rather than the
    /// machine or this crate.
    pub fn is_input_fault(&self) -> bool {
        match self {
            Error::Input { .. } => true,
            Error::Mesh(e) => e.kind != mesh_io::ErrorKind::Write,
            Error::Sites(e) => !matches!(**e, crust::SitesFileError::Write(_)),
            Error::Occupancy(e) => !matches!(**e, occupancy::OccupancyError::OutputLength { .. }),
            Error::Plot(_) | Error::Picture { .. } | Error::Page(_) => false,
        }
    }
}

pub use vf_common::text::group;
