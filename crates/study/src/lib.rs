//! The sphere study, the seed paper's headline experiment: overfit a sphere (radius 0.35,
//! centred in the unit cube) with Voronoi sites and with OccNet- and DeepSDF-style MLP
//! decoders of many sizes, and compare the Hausdorff distance to the analytic sphere
//! against parameter count.
//!
//! Fairness: the Voronoi sites are fitted by the main job itself ([`fit::fit`] on a finely
//! triangulated sphere, default settings); the decoders train until their loss plateaus
//! ([`plateau`]), DeepSDF from SAL's geometric initialisation; every (method, size) runs
//! under each of the [`Budget`]'s seeds. Two reference lines: the crust of K sites placed
//! by construction (mirrored pairs on a Fibonacci lattice, no training) and marching cubes
//! of the exact signed distance on the decoders' grid. Surfaces: the Voronoi crust (exact,
//! watertight) and marching cubes of the decoders. Distances: a certified Hausdorff
//! interval to the analytic sphere ([`metrics::hausdorff_sphere_certified`]) and a sampled
//! Chamfer L1 distance ([`measure`]). [`run`] returns the [`Row`]s; [`write`](mod@write) writes
//! results.csv, summary.csv, the plot, table.md and budget.json atomically;
//! [`run_study`] does both into an output folder from [`StudyOptions`], as
//! `voronoi-fit study sphere` runs it.

pub mod budget;
mod command;
pub mod data;
pub mod measure;
pub mod plateau;
pub mod runs;
pub mod write;

pub use budget::Budget;
pub use command::{run_study, StudyOptions, StudyOutcome};
pub use runs::{num_units, run, Row, StudyProgress};

/// The study's sphere.
pub const SPHERE: mesh_io::shapes::Sphere = mesh_io::shapes::Sphere { center: [0.5; 3], radius: 0.35 };

/// Why the study stopped.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A run failed (the message names it).
    #[error("{0}")]
    Run(String),
    /// An output could not be written.
    #[error(transparent)]
    Write(#[from] mesh_io::MeshError),
    /// The output folder could not be created.
    #[error("{path}: cannot create the output directory ({message})", path = path.display())]
    CreateDir {
        /// The output folder.
        path: std::path::PathBuf,
        /// Why.
        message: String,
    },
    /// The options are out of range (the message names the command-line flag).
    #[error("{0}")]
    Options(String),
}

impl StudyError {
    /// Whether the input is at fault: the study reads no file, so only its options can be.
    pub fn is_input_fault(&self) -> bool {
        matches!(self, StudyError::Options(_))
    }
}
