//! Training: minibatch loss and gradient over fixed chunks in parallel, a fixed-order
//! reduction, Adam.
//!
//! Determinism: the batch is cut into chunks of `chunk_rows` rows whatever the thread
//! count; each chunk's gradient is computed on its own (rayon over chunks), and chunk
//! gradients are summed element by element in chunk order. Results are bit-identical
//! across runs and thread counts for the same seed, data and configuration (they do depend
//! on `chunk_rows`, which fixes the summation order).
//!
//! Memory: every buffer (one workspace per chunk, the summed gradient, Adam's moments, the
//! batch permutation) is allocated in [`Trainer::new`]; a step allocates nothing itself.
//! The GEMM backend (matrixmultiply, through ndarray) allocates one packing buffer per
//! matrix product internally; `tests/alloc.rs` counts exactly that.

use std::ops::ControlFlow;
use std::time::Instant;

use rayon::prelude::*;

use crate::error::{config_err, BaselineError, Result};
use crate::mlp::{DecoderKind, Mlp, Workspace};
use crate::scalar::Real;
use vf_common::rng::{SplitMix64, Stream};
use vf_common::AdamParams;

/// Training samples: points with occupancy (OccNet) and/or signed-distance (DeepSDF)
/// targets, one per point. Make them with the `occupancy` crate's samplers and oracle, or
/// analytically (the sphere study).
#[derive(Clone, Debug, Default)]
pub struct TrainingData {
    /// The sample points.
    pub points: Vec<[f64; 3]>,
    /// Occupancy in [0, 1] (1 inside), for OccNet.
    pub occupancy: Option<Vec<f64>>,
    /// Signed distance (negative inside), for DeepSDF.
    pub sdf: Option<Vec<f64>>,
}

impl TrainingData {
    /// The targets `kind` trains on, checked: present, one per point, finite (occupancy in
    /// [0, 1]), and every point finite.
    pub fn targets(&self, kind: DecoderKind) -> Result<&[f64]> {
        let (name, t) = match kind {
            DecoderKind::OccNet => ("occupancy", self.occupancy.as_deref()),
            DecoderKind::DeepSdf => ("sdf", self.sdf.as_deref()),
        };
        let t =
            t.ok_or_else(|| BaselineError::Data(format!("{kind:?} trains on `{name}` targets, which are missing")))?;
        if self.points.is_empty() {
            return Err(BaselineError::Data("no training points".into()));
        }
        if self.points.len() > u32::MAX as usize {
            return Err(BaselineError::Data("more than 2^32 − 1 training points".into()));
        }
        if t.len() != self.points.len() {
            return Err(BaselineError::Data(format!("{} points but {} `{name}` targets", self.points.len(), t.len())));
        }
        if let Some(i) = self.points.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(BaselineError::Data(format!("point {i} is not finite: {:?}", self.points[i])));
        }
        let bad = |v: f64| !v.is_finite() || (kind == DecoderKind::OccNet && !(0.0..=1.0).contains(&v));
        if let Some(i) = t.iter().position(|&v| bad(v)) {
            return Err(BaselineError::Data(format!(
                "`{name}` target {i} is {} (must be finite{})",
                t[i],
                match kind {
                    DecoderKind::OccNet => ", in [0, 1]",
                    DecoderKind::DeepSdf => "",
                }
            )));
        }
        Ok(t)
    }
}

/// Learning-rate schedule over the steps `0..steps`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Schedule {
    /// `lr` throughout.
    Constant,
    /// Multiply by `factor` every `every` steps (DeepSDF: 0.5 every 500 epochs).
    Step {
        /// Steps between reductions.
        every: usize,
        /// Factor of each reduction.
        factor: f64,
    },
    /// Cosine from `lr` down to `min_lr` at the last step.
    Cosine {
        /// The rate at the last step.
        min_lr: f64,
    },
}

/// How to train.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainConfig {
    /// Steps (one Adam update each).
    pub steps: usize,
    /// Points per step; a batch at least as large as the data set uses all of it every
    /// step, otherwise batches are consecutive slices of a seeded permutation redrawn every
    /// epoch (the remainder of an epoch is dropped).
    pub batch: usize,
    /// Adam's initial learning rate.
    pub lr: f64,
    /// How the rate changes over the steps.
    pub schedule: Schedule,
    /// Seed of the batch permutations.
    pub seed: u64,
    /// Rows per parallel chunk (fixes the summation order; 4,096 by default).
    pub chunk_rows: usize,
    /// Adam's constants.
    pub adam: AdamParams,
}

impl Default for TrainConfig {
    fn default() -> Self {
        TrainConfig {
            steps: 1000,
            batch: 16_384,
            lr: 1e-3,
            schedule: Schedule::Constant,
            seed: 0,
            chunk_rows: 4096,
            adam: AdamParams::default(),
        }
    }
}

impl TrainConfig {
    /// Checks the settings.
    ///
    /// # Errors
    /// [`BaselineError::Config`] naming the setting.
    pub fn validate(&self) -> Result<()> {
        if self.batch == 0 {
            return config_err("batch", self.batch, "a batch needs at least one point");
        }
        if self.chunk_rows == 0 {
            return config_err("chunk_rows", self.chunk_rows, "a chunk needs at least one row");
        }
        if !(self.lr.is_finite() && self.lr > 0.0) {
            return config_err("lr", self.lr, "the learning rate must be finite and positive");
        }
        let a = &self.adam;
        if !(0.0..1.0).contains(&a.beta1) {
            return config_err("adam.beta1", a.beta1, "must be in [0, 1)");
        }
        if !(0.0..1.0).contains(&a.beta2) {
            return config_err("adam.beta2", a.beta2, "must be in [0, 1)");
        }
        if !(a.eps.is_finite() && a.eps > 0.0) {
            return config_err("adam.eps", a.eps, "must be finite and positive");
        }
        match self.schedule {
            Schedule::Constant => {}
            Schedule::Step { every, factor } => {
                if every == 0 {
                    return config_err("schedule.every", every, "must be at least 1");
                }
                if !(factor.is_finite() && factor > 0.0) {
                    return config_err("schedule.factor", factor, "must be finite and positive");
                }
            }
            Schedule::Cosine { min_lr } => {
                if !(min_lr.is_finite() && min_lr >= 0.0) {
                    return config_err("schedule.min_lr", min_lr, "must be finite and non-negative");
                }
            }
        }
        Ok(())
    }

    /// Learning rate at `step` (0-based).
    pub fn lr_at(&self, step: usize) -> f64 {
        match self.schedule {
            Schedule::Constant => self.lr,
            Schedule::Step { every, factor } => self.lr * factor.powi((step / every.max(1)) as i32),
            Schedule::Cosine { min_lr } => {
                let t = if self.steps > 1 { step as f64 / (self.steps - 1) as f64 } else { 1.0 };
                min_lr + 0.5 * (self.lr - min_lr) * (1.0 + (std::f64::consts::PI * t.min(1.0)).cos())
            }
        }
    }
}

/// One step's record, passed to the progress callback.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepRecord {
    /// 0-based.
    pub step: usize,
    /// Mean loss over the step's batch, before the update.
    pub loss: f64,
    /// The learning rate of the step.
    pub lr: f64,
    /// Wall time of the step (batch gather, forward, backward, reduction, Adam).
    pub seconds: f64,
}

/// What [`train`] returns.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrainReport {
    /// Per step, in order.
    pub losses: Vec<f64>,
    /// Wall seconds per step, in order.
    pub step_seconds: Vec<f64>,
    /// Including setup (workspace allocation).
    pub total_seconds: f64,
    /// Steps run (fewer than configured when the callback broke off).
    pub steps_run: usize,
}

/// Loss and gradient of a decoder on a batch, over fixed chunks in parallel.
pub struct GradEngine<T: Real> {
    chunk_rows: usize,
    max_batch: usize,
    workspaces: Vec<Workspace<T>>,
    /// Gradient of the last batch, flat like the parameters.
    pub grad: Vec<T>,
}

impl<T: Real> GradEngine<T> {
    /// Buffers for batches of up to `max_batch` points.
    pub fn new(model: &Mlp<T>, max_batch: usize, chunk_rows: usize) -> Result<Self> {
        if max_batch == 0 {
            return config_err("batch", max_batch, "a batch needs at least one point");
        }
        if chunk_rows == 0 {
            return config_err("chunk_rows", chunk_rows, "a chunk needs at least one row");
        }
        let rows = chunk_rows.min(max_batch);
        let n_chunks = max_batch.div_ceil(rows);
        Ok(GradEngine {
            chunk_rows: rows,
            max_batch,
            workspaces: (0..n_chunks).map(|_| Workspace::new(model, rows, true)).collect(),
            grad: vec![T::zero(); model.num_params()],
        })
    }

    /// Mean loss over the points `indices` of `points` against `targets`, and its gradient
    /// into `self.grad`. Errors: more indices than the engine's batch size, none, an index
    /// out of range, `targets` not one per point, a model of another shape.
    pub fn loss_grad(&mut self, model: &Mlp<T>, points: &[[f64; 3]], targets: &[f64], indices: &[u32]) -> Result<f64> {
        let n = indices.len();
        let rows = self.chunk_rows;
        let n_chunks = n.div_ceil(rows);
        if n == 0 || n > self.max_batch || n_chunks > self.workspaces.len() {
            return Err(BaselineError::Data(format!(
                "a batch of {n} points; this engine takes 1 to {}",
                self.max_batch
            )));
        }
        if targets.len() != points.len() {
            return Err(BaselineError::Data(format!("{} points but {} targets", points.len(), targets.len())));
        }
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= points.len()) {
            return Err(BaselineError::Data(format!("index {i} out of range for {} points", points.len())));
        }
        if model.num_params() != self.grad.len() || model.layers.len() != self.workspaces[0].acts.len() {
            return Err(BaselineError::Data("the model's shape differs from the one the engine was built for".into()));
        }
        self.workspaces[..n_chunks].par_iter_mut().enumerate().for_each(|(c, ws)| {
            let idx = &indices[c * rows..((c + 1) * rows).min(n)];
            ws.load_points(model, idx.iter().map(|&i| points[i as usize]));
            ws.forward(model, idx.len());
            ws.backward(model, idx.len(), idx.iter().map(|&i| targets[i as usize]), n);
        });
        let ws = &self.workspaces[..n_chunks];
        const BLOCK: usize = 8192;
        self.grad.par_chunks_mut(BLOCK).enumerate().for_each(|(bi, g)| {
            let off = bi * BLOCK;
            let len = g.len();
            g.copy_from_slice(&ws[0].grad[off..off + len]);
            for w in &ws[1..] {
                for (a, &b) in g.iter_mut().zip(&w.grad[off..off + len]) {
                    *a = *a + b;
                }
            }
        });
        Ok(ws.iter().map(|w| w.loss).sum())
    }
}

/// Adam state.
struct Adam<T: Real> {
    m: Vec<T>,
    v: Vec<T>,
    t: u64,
    cfg: AdamParams,
}

impl<T: Real> Adam<T> {
    fn new(n: usize, cfg: AdamParams) -> Self {
        Adam { m: vec![T::zero(); n], v: vec![T::zero(); n], t: 0, cfg }
    }

    /// One step of Adam (`vf_common::adam`, PyTorch's form), in parallel blocks.
    fn update(&mut self, params: &mut [T], grad: &[T], lr: f64) {
        self.t += 1;
        let step = self.cfg.at::<T>(self.t, lr);
        const BLOCK: usize = 8192;
        params
            .par_chunks_mut(BLOCK)
            .zip(self.m.par_chunks_mut(BLOCK))
            .zip(self.v.par_chunks_mut(BLOCK))
            .zip(grad.par_chunks(BLOCK))
            .for_each(|(((p, m), v), g)| {
                step.apply(p, g, m, v);
            });
    }
}

/// Step-by-step training of one decoder on one data set (what [`train`] loops over).
pub struct Trainer<T: Real> {
    config: TrainConfig,
    engine: GradEngine<T>,
    adam: Adam<T>,
    n_data: usize,
    batch: usize,
    perm: Vec<u32>,
    pos: usize,
    rng: SplitMix64,
    step: usize,
    lr_factor: f64,
}

impl<T: Real> Trainer<T> {
    /// All buffers for training `model` on `n_data` points with `config`.
    pub fn new(model: &Mlp<T>, n_data: usize, config: &TrainConfig) -> Result<Self> {
        config.validate()?;
        if n_data == 0 || n_data > u32::MAX as usize {
            return Err(BaselineError::Data(format!("{n_data} training points (need 1 to 2^32 − 1)")));
        }
        let batch = config.batch.min(n_data);
        let mut t = Trainer {
            config: config.clone(),
            engine: GradEngine::new(model, batch, config.chunk_rows)?,
            adam: Adam::new(model.num_params(), config.adam),
            n_data,
            batch,
            perm: (0..n_data as u32).collect(),
            pos: 0,
            rng: SplitMix64::new(config.seed, Stream::MlpBatch),
            step: 0,
            lr_factor: 1.0,
        };
        if batch < n_data {
            t.shuffle();
        }
        Ok(t)
    }

    fn shuffle(&mut self) {
        for i in (1..self.perm.len()).rev() {
            let j = self.rng.below(i + 1);
            self.perm.swap(i, j);
        }
        self.pos = 0;
    }

    /// Multiplies every later step's learning rate (the schedule's value) by `factor`
    /// from now on: how a caller reduces the rate when the loss plateaus.
    pub fn set_lr_factor(&mut self, factor: f64) {
        self.lr_factor = factor;
    }

    /// The factor set by [`Trainer::set_lr_factor`] (1 at the start).
    pub fn lr_factor(&self) -> f64 {
        self.lr_factor
    }

    /// Steps taken so far.
    pub fn steps_done(&self) -> usize {
        self.step
    }

    /// One step: next batch, loss and gradient, Adam update. `data` must be the data set
    /// the trainer was built for (same length; checked).
    pub fn step(&mut self, model: &mut Mlp<T>, data: &TrainingData) -> Result<StepRecord> {
        let targets = data.targets(model.config().kind)?;
        self.step_unchecked(model, &data.points, targets)
    }

    /// [`Trainer::step`] on plain slices, validated only for length (for tight loops on
    /// data already checked with [`TrainingData::targets`]).
    pub fn step_unchecked(&mut self, model: &mut Mlp<T>, points: &[[f64; 3]], targets: &[f64]) -> Result<StepRecord> {
        if points.len() != self.n_data || targets.len() != self.n_data {
            return Err(BaselineError::Data(format!(
                "the trainer was built for {} points, got {} points and {} targets",
                self.n_data,
                points.len(),
                targets.len()
            )));
        }
        let t0 = Instant::now();
        if self.batch < self.n_data && self.pos + self.batch > self.n_data {
            self.shuffle();
        }
        let idx = &self.perm[self.pos..self.pos + self.batch];
        if self.batch < self.n_data {
            self.pos += self.batch;
        }
        let loss = self.engine.loss_grad(model, points, targets, idx)?;
        let lr = self.config.lr_at(self.step) * self.lr_factor;
        self.adam.update(&mut model.params, &self.engine.grad, lr);
        let rec = StepRecord { step: self.step, loss, lr, seconds: t0.elapsed().as_secs_f64() };
        self.step += 1;
        Ok(rec)
    }
}

/// Train `model` on `data` for `config.steps` steps, calling `progress` after each step;
/// the callback can stop early with `ControlFlow::Break(())`.
pub fn train<T: Real>(
    model: &mut Mlp<T>,
    data: &TrainingData,
    config: &TrainConfig,
    mut progress: impl FnMut(&StepRecord) -> ControlFlow<()>,
) -> Result<TrainReport> {
    let t0 = Instant::now();
    let targets = data.targets(model.config().kind)?;
    let mut trainer = Trainer::new(model, data.points.len(), config)?;
    let mut report = TrainReport {
        losses: Vec::with_capacity(config.steps),
        step_seconds: Vec::with_capacity(config.steps),
        ..Default::default()
    };
    for _ in 0..config.steps {
        let rec = trainer.step_unchecked(model, &data.points, targets)?;
        report.losses.push(rec.loss);
        report.step_seconds.push(rec.seconds);
        report.steps_run += 1;
        if progress(&rec).is_break() {
            break;
        }
    }
    report.total_seconds = t0.elapsed().as_secs_f64();
    Ok(report)
}

/// Mean loss and its gradient on all of `data` in one batch (`chunk_rows` 4,096): what the
/// finite-difference checks compare against.
pub fn loss_and_grad<T: Real>(model: &Mlp<T>, data: &TrainingData) -> Result<(f64, Vec<T>)> {
    let targets = data.targets(model.config().kind)?;
    let idx: Vec<u32> = (0..data.points.len() as u32).collect();
    let mut e = GradEngine::new(model, idx.len(), 4096)?;
    let loss = e.loss_grad(model, &data.points, targets, &idx)?;
    Ok((loss, e.grad))
}
