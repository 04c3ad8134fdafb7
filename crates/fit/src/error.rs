//! The fit's error, one variant per source. Whether it is the input's fault
//! ([`FitError::is_input_fault`]) decides the CLI's exit code (2 or 1).

use std::path::PathBuf;

use crust::CrustError;
use metrics::MetricsError;
use occupancy::OccupancyError;
use soft_voronoi::TrainError;

/// Why a fit did not finish.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The input mesh cannot be fitted (input fault).
    #[error("{mesh}: {fault}")]
    Mesh {
        /// The mesh's name (the CLI: its path).
        mesh: String,
        /// What is wrong with it.
        #[source]
        fault: MeshFault,
    },
    /// A setting is out of range or contradicts another; the message names it and what it
    /// accepts (input fault).
    #[error("{0}")]
    Settings(String),
    /// A training or polish setting was refused by the trainer's own check (input fault).
    #[error("{0}; see voronoi-fit --help")]
    TrainSettings(#[source] TrainError),
    /// The checkpoint to resume from cannot be read (its message names the file; input
    /// fault).
    #[error("{source}")]
    CheckpointRead {
        /// The checkpoint file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: TrainError,
    },
    /// The checkpoint's settings (its context JSON) are not those of the main job (input
    /// fault).
    #[error("{}: {what} ({source})", path.display())]
    CheckpointSettings {
        /// The checkpoint file.
        path: PathBuf,
        /// Which part of the settings.
        what: &'static str,
        /// The parse error.
        #[source]
        source: serde_json::Error,
    },
    /// The settings to store in a checkpoint could not be serialised.
    #[error("checkpoint settings: {0}")]
    CheckpointContext(#[source] serde_json::Error),
    /// The checkpoint could not be written (its message names the file).
    #[error("{source}")]
    CheckpointWrite {
        /// The checkpoint file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        source: TrainError,
    },
    /// Training cannot start from this data, these sites or this checkpoint (input fault).
    #[error("{0}")]
    TrainStart(#[source] TrainError),
    /// A training step failed (a diverging loss, a Delaunay failure).
    #[error("{0}")]
    Training(#[source] TrainError),
    /// The polish failed.
    #[error("{0}")]
    Polish(#[source] TrainError),
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
    /// Training was stopped on request with no checkpoint to write.
    #[error("stopped at step {step} of {steps} without a checkpoint")]
    StoppedTraining {
        /// Steps done.
        step: usize,
        /// Steps planned.
        steps: usize,
    },
    /// The polish was stopped on request with no checkpoint to write.
    #[error("stopped in the polish after {step} of {steps} steps")]
    StoppedPolish {
        /// Polish steps done.
        step: usize,
        /// Polish steps planned.
        steps: usize,
    },
    /// A crust could not be extracted or checked.
    #[error("{during}: {source}")]
    Crust {
        /// The stage (`crust of the trained sites`, `crust while carving`, …).
        during: &'static str,
        /// The crust's error.
        #[source]
        source: CrustError,
    },
    /// The crust cannot be made valid in the output's precision (coordinates beyond
    /// float32, Voronoi features finer than it holds; input fault).
    #[error("the crust as written: {0}")]
    OutputPrecision(#[source] CrustError),
    /// An occupancy query (winding numbers, closest points, sampling) failed.
    #[error("{during}: {source}")]
    Occupancy {
        /// The stage (`sampling`, `cap samples`, …).
        during: &'static str,
        /// The oracle's error.
        #[source]
        source: OccupancyError,
    },
    /// A distance to the input could not be measured (carving, the thin shell's band).
    #[error("{during}: {source}")]
    Metrics {
        /// The stage.
        during: &'static str,
        /// The metrics' error.
        #[source]
        source: MetricsError,
    },
    /// The metrics against the input failed where they decide (the accuracy target).
    #[error("measuring the fit: {0}")]
    Measuring(String),
    /// A stage broke its own contract (a bug).
    #[error("{0}")]
    Internal(&'static str),
}

/// What is wrong with the input mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshFault {
    /// No triangles are left once unreferenced vertices are dropped.
    #[error("the mesh has no triangles; nothing to fit")]
    NoTriangles,
    /// The bounding box is a point, or a coordinate is not finite.
    #[error("the mesh has no extent (all vertices coincide) or non-finite coordinates")]
    NoExtent,
    /// The occupancy oracle refuses the mesh.
    #[error("{0}")]
    Oracle(#[source] OccupancyError),
    /// The surface sampler refuses the mesh: its triangles have no area.
    #[error("{0} (the mesh has no area to sample)")]
    NoArea(#[source] OccupancyError),
    /// The winding-number solid holds none of the training samples.
    #[error(
        "no training sample is inside the mesh (|winding number| < 0.5 everywhere): it encloses no volume. Close \
         the surface (fill its holes), or fit a thin shell around it with --solid shell"
    )]
    NothingInside,
    /// After training and relabelling, no site stands inside the winding-number solid: its
    /// parts are thinner than the sites' spacing, so the crust would be empty. Under
    /// `--solid auto` the fit then fits a thin shell instead ([`crate::fit`]).
    #[error(
        "no site stands inside the winding-number solid after training: its parts are thinner than the sites' \
         spacing. Fit a thin shell around the surface with --solid shell, or give more sites"
    )]
    NoSiteInside,
}

impl FitError {
    /// Whether the input (mesh, settings, checkpoint to resume, a crust the output's
    /// precision cannot hold) is at fault.
    pub fn is_input_fault(&self) -> bool {
        match self {
            FitError::Mesh { .. }
            | FitError::Settings(_)
            | FitError::TrainSettings(_)
            | FitError::CheckpointRead { .. }
            | FitError::CheckpointSettings { .. }
            | FitError::TrainStart(_)
            | FitError::OutputPrecision(_) => true,
            FitError::CheckpointContext(_)
            | FitError::CheckpointWrite { .. }
            | FitError::Training(_)
            | FitError::Polish(_)
            | FitError::Interrupted { .. }
            | FitError::StoppedTraining { .. }
            | FitError::StoppedPolish { .. }
            | FitError::Crust { .. }
            | FitError::Occupancy { .. }
            | FitError::Metrics { .. }
            | FitError::Measuring(_)
            | FitError::Internal(_) => false,
        }
    }
}
