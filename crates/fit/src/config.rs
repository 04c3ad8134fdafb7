//! What a fit needs besides the mesh: training settings, the sampling of the training and
//! evaluation pools, checkpointing and resuming.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use soft_voronoi::{checkpoint, TrainConfig, TrainState};

use crate::error::FitError;

/// Default number of trainable sites.
pub const DEFAULT_SITES: usize = 8192;

/// Empty space around the mesh in the unit cube (each side), as a fraction of the cube.
pub const MARGIN: f64 = 0.05;

/// The training pool: what a resumed run must reproduce besides the training settings
/// (stored in checkpoints as JSON, compared on resume).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sampling {
    /// Name of the input (the CLI: its path), for messages and the report.
    pub mesh: String,
    /// Size of the pool: half uniform in the unit cube, half near the surface.
    pub samples: usize,
    /// Seed of the pool (also the training seed).
    pub seed: u64,
    /// Near-surface spreads σ as fractions of the mesh's bounding-box diagonal (the
    /// near-surface half is split evenly between them).
    pub sigmas: Vec<f64>,
    /// Empty space around the mesh in the unit cube, each side.
    pub margin: f64,
}

/// The fresh evaluation pool (misclassification).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvalSampling {
    /// Size (half uniform, half near-surface).
    pub samples: usize,
    /// Near-surface spreads as fractions of the diagonal.
    pub sigmas: Vec<f64>,
}

/// Where and how often training writes its checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpointing {
    /// The checkpoint file (written atomically; each write replaces the last).
    pub path: PathBuf,
    /// Every this many steps (0: only when [`crate::Progress::should_stop`] asks).
    pub every: usize,
}

/// Everything that determines a fit of a given mesh.
#[derive(Clone, Debug)]
pub struct FitConfig {
    /// Training settings (sites, steps, learning rate, losses, seed).
    pub train: TrainConfig,
    /// Name of the settings preset, for the report (`default` or `paper`).
    pub preset: String,
    /// The training pool.
    pub sampling: Sampling,
    /// The evaluation pool.
    pub eval: EvalSampling,
    /// Checkpoints during training (`None`: none).
    pub checkpointing: Option<Checkpointing>,
    /// A saved state to continue from (see [`FitConfig::resume`]), with its path for
    /// messages.
    pub resume: Option<(TrainState, String)>,
    /// How the crust will be stored (f32 for glTF, f64 for OBJ/PLY): the crust is rounded
    /// to it and checked as rounded.
    pub output_precision: crust::output::Precision,
    /// Skip the metrics against the input (Hausdorff, Chamfer, IoU): for callers that
    /// measure themselves.
    pub skip_metrics: bool,
}

impl FitConfig {
    /// The default fit of `num_sites` sites ([`TrainConfig::default_for`]), seed 0,
    /// 1,000,000 training and evaluation samples, no checkpoints.
    pub fn new(mesh: &str, num_sites: usize) -> Self {
        FitConfig {
            train: TrainConfig::default_for(num_sites),
            preset: "default".into(),
            sampling: Sampling {
                mesh: mesh.to_string(),
                samples: 1_000_000,
                seed: 0,
                sigmas: vec![0.01, 0.003],
                margin: MARGIN,
            },
            eval: EvalSampling { samples: 1_000_000, sigmas: vec![0.01] },
            checkpointing: None,
            resume: None,
            output_precision: crust::output::Precision::F32,
            skip_metrics: false,
        }
    }

    /// Sets the seed of the pool, the initialisation and the batches.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.sampling.seed = seed;
        self.train.seed = seed;
        self
    }

    /// Continues the checkpoint at `path`: its training settings and sampling, with the
    /// evaluation settings of `self` (the checkpoint does not hold them).
    ///
    /// # Errors
    /// [`FitError::Input`] when the file is not a checkpoint of the main job.
    pub fn resume(mut self, path: &Path) -> Result<Self, FitError> {
        let (state, context) = checkpoint::read(path).map_err(|e| FitError::Input(e.to_string()))?;
        let sampling: Sampling = serde_json::from_str(&context).map_err(|e| {
            FitError::Input(format!("{}: not a checkpoint of `voronoi-fit MESH` ({e})", path.display()))
        })?;
        self.train = state.config.clone();
        self.sampling = sampling;
        self.resume = Some((state, path.display().to_string()));
        Ok(self)
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`FitError::Input`] naming the setting and its accepted range.
    pub fn validate(&self) -> Result<(), FitError> {
        self.train.validate().map_err(|e| FitError::Input(format!("{e}; see voronoi-fit --help")))?;
        let s = &self.sampling;
        if self.resume.is_none() && (!(1000..=100_000_000).contains(&s.samples) || self.train.num_sites > s.samples / 2)
        {
            return Err(FitError::Input(format!(
                "--samples {} must be in 1000..=100000000 and at least twice --sites {}",
                s.samples, self.train.num_sites
            )));
        }
        if self.eval.samples > 100_000_000 {
            return Err(FitError::Input(format!("--eval-samples {} must be at most 100000000", self.eval.samples)));
        }
        let good = |v: &[f64]| !v.is_empty() && v.iter().all(|x| x.is_finite() && *x > 0.0 && *x < 1.0);
        if !good(&s.sigmas) || !good(&self.eval.sigmas) {
            return Err(FitError::Input("near-surface spreads must be in (0, 1) of the diagonal".into()));
        }
        if !(s.margin.is_finite() && s.margin >= 0.0 && s.margin < 0.5) {
            return Err(FitError::Input(format!("margin {} must be in [0, 0.5)", s.margin)));
        }
        Ok(())
    }
}
