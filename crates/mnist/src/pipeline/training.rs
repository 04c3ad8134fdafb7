//! Training every method with checkpoints that resume, and loading the trained models.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use super::{DataSource, Experiment, Report};
use crate::error::MnistError;
use crate::idx::DigitSet;
use crate::model::{Method, Model};
use crate::train::{TrainSettings, TrainState};

/// How to train: overrides of the quick or full [`TrainSettings`], and the checkpoints.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainOptions {
    /// Epochs (default: 15, quick 2).
    pub epochs: Option<usize>,
    /// Training images used, the first N of the set (default: 10,000, quick 1,000; an
    /// explicit count larger than the set is an error, the default is cut to the set).
    pub images: Option<usize>,
    /// Images per step.
    pub batch: Option<usize>,
    /// Training points per image and epoch.
    pub points: Option<usize>,
    /// Adam's learning rate.
    pub lr: Option<f64>,
    /// The soft-Voronoi's final β.
    pub beta: Option<f64>,
    /// β at the first step, annealed geometrically to `beta` at the last.
    pub beta_start: Option<f64>,
    /// Seed of the weights, the image order and the training points.
    pub seed: u64,
    /// Start over even if a checkpoint exists.
    pub restart: bool,
    /// Checkpoint every this many steps (and after every epoch; 0: only after epochs).
    pub checkpoint_every: usize,
}

impl Default for TrainOptions {
    fn default() -> Self {
        TrainOptions {
            epochs: None,
            images: None,
            batch: None,
            points: None,
            lr: None,
            beta: None,
            beta_start: None,
            seed: 0,
            restart: false,
            checkpoint_every: 100,
        }
    }
}

impl TrainOptions {
    /// The settings these options give: [`TrainSettings::quick`] or
    /// [`TrainSettings::full`] with the overrides applied (not yet validated, and before
    /// [`train_methods`] cuts the default image count to the set).
    pub fn settings(&self, quick: bool) -> TrainSettings {
        let mut s = if quick { TrainSettings::quick() } else { TrainSettings::full() };
        if let Some(e) = self.epochs {
            s.epochs = e;
        }
        if let Some(n) = self.images {
            s.train_images = n;
        }
        if let Some(b) = self.batch {
            s.batch = b;
        }
        if let Some(p) = self.points {
            s.points = p;
        }
        if let Some(lr) = self.lr {
            s.lr = lr;
        }
        if let Some(b) = self.beta {
            s.voronoi.beta = b;
        }
        if self.beta_start.is_some() {
            s.beta_start = self.beta_start;
        }
        s.seed = self.seed;
        s
    }
}

/// The trained methods.
#[derive(Clone, Debug)]
pub struct Trained {
    /// One finished state per method, in the experiment's order.
    pub states: Vec<TrainState>,
    /// Seconds this process spent (resumed or finished checkpoints take less).
    pub seconds: f64,
}

/// Where `method`'s checkpoint is: `out/METHOD/checkpoint.npz`.
pub fn checkpoint_path(out: &Path, method: Method) -> PathBuf {
    out.join(method.name()).join("checkpoint.npz")
}

/// The `mnist train` command: reads the training set and runs [`train_methods`].
///
/// # Errors
/// Those of [`DataSource::load`] and [`train_methods`].
pub fn train(
    exp: &Experiment,
    opts: &TrainOptions,
    data: &DataSource,
    stop: &AtomicBool,
    report: &mut dyn Report,
) -> Result<Trained, MnistError> {
    let set = data.load(false)?;
    train_methods(exp, opts, &set, stop, report)
}

/// Trains every method of `exp` on `train`, each from its checkpoint when one exists
/// (unless `opts.restart`), checkpointing as it goes; stops after a checkpoint when `stop`
/// is set.
///
/// # Errors
/// [`MnistError::Config`] for settings out of range, [`MnistError::Options`] for more
/// `--images` than the set has, [`MnistError::Checkpoint`] for a checkpoint that is
/// unreadable or was trained with other settings, [`MnistError::Write`] when the folder or
/// a checkpoint cannot be written, [`MnistError::TrainingInterrupted`] when `stop` was set.
pub fn train_methods(
    exp: &Experiment,
    opts: &TrainOptions,
    train: &DigitSet,
    stop: &AtomicBool,
    report: &mut dyn Report,
) -> Result<Trained, MnistError> {
    let started = Instant::now();
    let mut settings = opts.settings(exp.quick);
    settings.validate()?;
    if settings.train_images > train.len() {
        if opts.images.is_some() {
            return Err(MnistError::Options(format!(
                "--images {}: {} has only {} images",
                settings.train_images,
                train.source.display(),
                train.len()
            )));
        }
        settings.train_images = train.len();
    }
    let pixels = train.images.rows * train.images.cols;
    report.training_starts();
    let mut states = Vec::new();
    for &m in &exp.methods {
        let path = checkpoint_path(&exp.out, m);
        std::fs::create_dir_all(path.parent().expect("a folder"))
            .map_err(|e| MnistError::Write(format!("{}: cannot create the folder ({e})", exp.out.display())))?;
        let mut state = if path.exists() && !opts.restart {
            let s = TrainState::load(&path)?;
            if s.settings != settings || s.model.method != m || s.model.encoder.n_in() != pixels {
                return Err(MnistError::Checkpoint {
                    message: format!(
                        "this checkpoint was trained with other settings ({}); give --restart to start over, or another --out",
                        serde_json::to_string(&s.settings).unwrap_or_default()
                    ),
                    path,
                });
            }
            s
        } else {
            TrainState::new(m, pixels, settings.clone())
        };
        let per_epoch = state.batches_per_epoch();
        report.train_start(
            m,
            (state.epoch * per_epoch + state.batch_in_epoch) as u64,
            (state.settings.epochs * per_epoch) as u64,
        );
        let result = state.run(train, Some(&path), opts.checkpoint_every, stop, |p| report.train_progress(m, p));
        report.train_end(m);
        match result {
            Ok(()) => {}
            Err(MnistError::Interrupted) => {
                return Err(MnistError::TrainingInterrupted { method: m, checkpoint: path })
            }
            Err(e) => return Err(e),
        }
        states.push(state);
    }
    Ok(Trained { states, seconds: started.elapsed().as_secs_f64() })
}

/// The trained model of every method of `exp`, from its checkpoint; a checkpoint before
/// its last epoch is used as it is, with a [`Report::warning`].
///
/// # Errors
/// [`MnistError::Checkpoint`] for a missing or unreadable checkpoint.
pub fn load_models(exp: &Experiment, report: &mut dyn Report) -> Result<Vec<Model>, MnistError> {
    let mut out = Vec::new();
    for &m in &exp.methods {
        let path = checkpoint_path(&exp.out, m);
        if !path.exists() {
            return Err(MnistError::Checkpoint {
                message: format!(
                    "no trained {} model; run `voronoi-fit mnist train --out {}` first",
                    m.name(),
                    exp.out.display()
                ),
                path,
            });
        }
        let s = TrainState::load(&path)?;
        if !s.finished() {
            report.warning(&format!(
                "{} is at epoch {} of {}; using it as it is",
                path.display(),
                s.epoch,
                s.settings.epochs
            ));
        }
        out.push(s.model);
    }
    Ok(out)
}
