//! Training: minibatches of images, each with its own training points (the same points
//! for every method: they depend only on the seed, the epoch and the image), Adam on the
//! encoder and decoder together, checkpoints that resume bit for bit.
//!
//! Determinism: a batch is cut into fixed chunks of [`CHUNK_IMAGES`] images processed in
//! parallel, each into its own gradient buffer, and the buffers are summed in chunk order,
//! so a run gives the same bits for any thread count.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use vf_common::{AdamParams, ChunkRng, SplitMix64, Stream};

use crate::digit::Digit;
use crate::error::MnistError;
use crate::idx::DigitSet;
use crate::model::{
    pixels_to_input, sites_of, voronoi_loss_grad, LossParts, Method, Model, VoronoiLoss, LATENT, SITES,
};
use crate::net::{occnet_loss_grad, OccNetScratch, Tape};

/// Images per parallel chunk (fixed: the reduction order depends on it).
pub const CHUNK_IMAGES: usize = 16;

/// Everything that determines a training run (with the data and the method).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainSettings {
    /// Passes over the training images.
    pub epochs: usize,
    /// Images per step.
    pub batch: usize,
    /// Training points per image and epoch (half uniform, half near the boundary).
    pub points: usize,
    /// Adam's learning rate (constant).
    pub lr: f64,
    /// Adam's constants.
    pub adam: AdamParams,
    /// The Voronoi decoder's loss (its `beta` is the final β).
    pub voronoi: VoronoiLoss,
    /// β annealing: β rises geometrically from this value at the first step to
    /// `voronoi.beta` at the last (`None`: `voronoi.beta` throughout).
    #[serde(default)]
    pub beta_start: Option<f64>,
    /// Seed of the weights, the image order and the points.
    pub seed: u64,
    /// Training images used (the first this many of the set).
    pub train_images: usize,
}

impl TrainSettings {
    /// β at 0-based step `t` of a run of `total` steps.
    pub fn beta_at(&self, t: u64, total: u64) -> f64 {
        match self.beta_start {
            None => self.voronoi.beta,
            Some(b0) => {
                let x = if total > 1 { (t as f64 / (total - 1) as f64).min(1.0) } else { 1.0 };
                b0 * (self.voronoi.beta / b0).powf(x)
            }
        }
    }

    /// Steps of the whole run.
    pub fn total_steps(&self) -> u64 {
        (self.epochs * self.train_images.div_ceil(self.batch)) as u64
    }

    /// The full run's settings, the same for every method: 15 epochs over the 10,000
    /// training digits (chosen so the four methods train, evaluate and embed in under an
    /// hour on 2 cores), batches of 32 images with 256 points each, Adam at 1e-3.
    ///
    /// The Voronoi decoder's loss: the seed's four terms with the signed-distance weight at
    /// 10, and β = 100, not the seed's 10,000 (`--beta 10000` gives it). Measured on the
    /// 10,000 training digits (docs/mnist.md): at β = 10,000 the reconstruction gradient only
    /// exists within ~1/β of the crust, is zero for a wrongly labelled point farther away,
    /// and comes in rare spikes of size ~β that dominate Adam's second moment; the decoder
    /// then learns almost nothing (103.6 mismatched pixels after 5 epochs, about an empty
    /// shape). β = 100 (a pixel is 1/28 of the square) with a signed-distance weight of 10
    /// (the one dense, per-image signal: each site pulled to its side of the digit) reaches
    /// 61.7 after 2 epochs; annealing from 100 to 10,000 over those 2 epochs ends at
    /// 106.8. The hard Voronoi occupancy that is evaluated does not depend on β.
    pub fn full() -> Self {
        TrainSettings {
            epochs: 15,
            batch: 32,
            points: 256,
            lr: 1e-3,
            adam: AdamParams::default(),
            voronoi: VoronoiLoss { beta: 100.0, signed_distance: 10.0, ..VoronoiLoss::default() },
            beta_start: None,
            seed: 0,
            train_images: 10_000,
        }
    }

    /// A quick run for CI: 1,000 images, 2 epochs.
    pub fn quick() -> Self {
        TrainSettings { epochs: 2, train_images: 1_000, ..Self::full() }
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`MnistError::Config`] naming the setting.
    pub fn validate(&self) -> Result<(), MnistError> {
        let bad = |m: String| Err(MnistError::Config(m));
        if self.epochs == 0 || self.epochs > 10_000 {
            return bad(format!("epochs = {} must be in 1..=10000", self.epochs));
        }
        if self.batch == 0 || self.batch > 4096 {
            return bad(format!("batch = {} must be in 1..=4096", self.batch));
        }
        if self.points < 2 || self.points > 100_000 {
            return bad(format!("points = {} must be in 2..=100000", self.points));
        }
        if !(self.lr.is_finite() && self.lr > 0.0 && self.lr < 1.0) {
            return bad(format!("lr = {} must be in (0, 1)", self.lr));
        }
        if self.train_images == 0 {
            return bad("train_images must be at least 1".into());
        }
        let v = &self.voronoi;
        if !(v.beta.is_finite() && v.beta > 0.0) || self.beta_start.is_some_and(|b| !(b.is_finite() && b > 0.0)) {
            return bad(format!("beta = {} (start {:?}) must be finite and > 0", v.beta, self.beta_start));
        }
        for (n, w) in [
            ("reconstruction", v.reconstruction),
            ("bounds", v.bounds),
            ("signed_distance", v.signed_distance),
            ("centroidal", v.centroidal),
        ] {
            if !(w.is_finite() && w >= 0.0) {
                return bad(format!("weight {n} = {w} must be finite and >= 0"));
            }
        }
        self.adam.validate().map_err(MnistError::Config)
    }
}

/// One point of the training curve: the mean loss of an epoch's steps.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint {
    /// 1-based epoch.
    pub epoch: usize,
    /// Steps done at its end.
    pub step: u64,
    /// Mean training loss over the epoch.
    pub loss: f64,
    /// Mean of each Voronoi term (zeros for OccNet).
    pub parts: LossParts,
    /// Wall seconds of training so far.
    pub seconds: f64,
}

/// A run in progress: the model, Adam's moments, where it is, the curve.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainState {
    /// The model being trained.
    pub model: Model,
    /// The run's settings.
    pub settings: TrainSettings,
    m: Vec<f32>,
    v: Vec<f32>,
    /// Adam steps done.
    pub step: u64,
    /// 0-based epoch in progress.
    pub epoch: usize,
    /// Batches of that epoch done.
    pub batch_in_epoch: usize,
    /// Sums over the epoch in progress (loss, parts, count).
    epoch_sum: (f64, LossParts, u64),
    /// Finished epochs.
    pub curve: Vec<CurvePoint>,
    /// Training seconds before this process.
    pub seconds: f64,
}

/// Progress of a step.
#[derive(Clone, Copy, Debug)]
pub struct Progress {
    /// 0-based epoch in progress.
    pub epoch: usize,
    /// Epochs of the run.
    pub epochs: usize,
    /// Batches of this epoch done (1-based: the step just taken).
    pub batch: usize,
    /// Batches per epoch.
    pub batches: usize,
    /// The step's mean loss.
    pub loss: f64,
}

#[derive(Serialize, Deserialize)]
struct Meta {
    format: u32,
    method: Method,
    settings: TrainSettings,
    pixels: usize,
    step: u64,
    epoch: usize,
    batch_in_epoch: usize,
    epoch_sum: (f64, LossParts, u64),
    curve: Vec<CurvePoint>,
    seconds: f64,
}

impl TrainState {
    /// A fresh run.
    pub fn new(method: Method, pixels: usize, settings: TrainSettings) -> Self {
        let model = Model::new(method, pixels, settings.seed);
        let n = model.encoder.params.len() + model.decoder.params.len();
        TrainState {
            model,
            settings,
            m: vec![0.0; n],
            v: vec![0.0; n],
            step: 0,
            epoch: 0,
            batch_in_epoch: 0,
            epoch_sum: (0.0, LossParts::default(), 0),
            curve: Vec::new(),
            seconds: 0.0,
        }
    }

    /// Whether every epoch is done.
    pub fn finished(&self) -> bool {
        self.epoch >= self.settings.epochs
    }

    /// Batches per epoch.
    pub fn batches_per_epoch(&self) -> usize {
        self.settings.train_images.div_ceil(self.settings.batch)
    }

    /// The image order of epoch `e`: a seeded Fisher–Yates shuffle.
    fn order(&self, e: usize) -> Vec<u32> {
        let n = self.settings.train_images;
        let mut idx: Vec<u32> = (0..n as u32).collect();
        let mut rng = SplitMix64::new(self.settings.seed ^ (e as u64).wrapping_mul(0x9E37_79B9), Stream::MnistShuffle);
        for i in (1..n).rev() {
            idx.swap(i, rng.below(i + 1));
        }
        idx
    }

    /// Runs until the end, or until `stop` is set (then returns
    /// [`MnistError::Interrupted`] after a checkpoint). Checkpoints to `checkpoint` every
    /// `checkpoint_every` steps and at the end of every epoch.
    ///
    /// # Errors
    /// Bad data (fewer images than the settings use), a non-finite loss, a checkpoint that
    /// cannot be written, or the interruption.
    pub fn run(
        &mut self,
        data: &DigitSet,
        checkpoint: Option<&Path>,
        checkpoint_every: usize,
        stop: &AtomicBool,
        mut progress: impl FnMut(&Progress),
    ) -> Result<(), MnistError> {
        if data.len() < self.settings.train_images {
            return Err(MnistError::Config(format!(
                "{} has {} images; the settings use {}",
                data.source.display(),
                data.len(),
                self.settings.train_images
            )));
        }
        let pixels = data.images.rows * data.images.cols;
        if pixels != self.model.encoder.n_in() {
            return Err(MnistError::Config(format!(
                "{} has {}×{} images; the model takes {} pixels",
                data.source.display(),
                data.images.rows,
                data.images.cols,
                self.model.encoder.n_in()
            )));
        }
        let started = Instant::now();
        let base_seconds = self.seconds;
        while !self.finished() {
            let order = self.order(self.epoch);
            let batches = self.batches_per_epoch();
            while self.batch_in_epoch < batches {
                if stop.load(Ordering::Relaxed) {
                    if let Some(p) = checkpoint {
                        self.seconds = base_seconds + started.elapsed().as_secs_f64();
                        self.save(p)?;
                    }
                    return Err(MnistError::Interrupted);
                }
                let b = self.batch_in_epoch;
                let idx = &order[b * self.settings.batch..((b + 1) * self.settings.batch).min(order.len())];
                let (loss, parts) = self.step(data, idx)?;
                self.epoch_sum.0 += loss;
                add_parts(&mut self.epoch_sum.1, &parts, 1.0);
                self.epoch_sum.2 += 1;
                self.batch_in_epoch += 1;
                progress(&Progress {
                    epoch: self.epoch,
                    epochs: self.settings.epochs,
                    batch: self.batch_in_epoch,
                    batches,
                    loss,
                });
                if checkpoint_every > 0 && self.step.is_multiple_of(checkpoint_every as u64) {
                    if let Some(p) = checkpoint {
                        self.seconds = base_seconds + started.elapsed().as_secs_f64();
                        self.save(p)?;
                    }
                }
            }
            let n = self.epoch_sum.2.max(1) as f64;
            let mut parts = LossParts::default();
            add_parts(&mut parts, &self.epoch_sum.1, 1.0 / n);
            self.seconds = base_seconds + started.elapsed().as_secs_f64();
            self.curve.push(CurvePoint {
                epoch: self.epoch + 1,
                step: self.step,
                loss: self.epoch_sum.0 / n,
                parts,
                seconds: self.seconds,
            });
            self.epoch += 1;
            self.batch_in_epoch = 0;
            self.epoch_sum = (0.0, LossParts::default(), 0);
            if let Some(p) = checkpoint {
                self.save(p)?;
            }
        }
        Ok(())
    }

    /// One Adam step on the images `idx` of `data`; returns the batch's mean loss and its
    /// mean Voronoi terms.
    pub fn step(&mut self, data: &DigitSet, idx: &[u32]) -> Result<(f64, LossParts), MnistError> {
        let beta = self.settings.beta_at(self.step, self.settings.total_steps());
        let (loss, parts, grad) = loss_and_grad(&self.model, &self.settings, beta, data, idx, self.epoch)?;
        if !loss.is_finite() {
            return Err(MnistError::Config(format!(
                "the training loss became {loss} at step {}; lower the learning rate (--lr)",
                self.step + 1
            )));
        }
        self.step += 1;
        let adam = self.settings.adam.at::<f32>(self.step, self.settings.lr);
        let ne = self.model.encoder.params.len();
        let (me, md) = self.m.split_at_mut(ne);
        let (ve, vd) = self.v.split_at_mut(ne);
        let (ge, gd) = grad.split_at(ne);
        adam_update(&adam, &mut self.model.encoder.params, me, ve, ge);
        adam_update(&adam, &mut self.model.decoder.params, md, vd, gd);
        Ok((loss, parts))
    }

    /// Writes the checkpoint atomically (`.npz`: parameters, Adam's moments, and the
    /// position and settings as JSON).
    ///
    /// # Errors
    /// [`MnistError::Write`].
    pub fn save(&self, path: &Path) -> Result<(), MnistError> {
        let meta = Meta {
            format: 1,
            method: self.model.method,
            settings: self.settings.clone(),
            pixels: self.model.encoder.n_in(),
            step: self.step,
            epoch: self.epoch,
            batch_in_epoch: self.batch_in_epoch,
            epoch_sum: self.epoch_sum,
            curve: self.curve.clone(),
            seconds: self.seconds,
        };
        let json = serde_json::to_vec(&meta).map_err(|e| MnistError::Write(e.to_string()))?;
        let mut npz = vf_common::npz::NpzOut::new();
        npz.add_vec("meta_json", json)?;
        npz.add_vec("encoder", self.model.encoder.params.clone())?;
        npz.add_vec("decoder", self.model.decoder.params.clone())?;
        npz.add_vec("adam_m", self.m.clone())?;
        npz.add_vec("adam_v", self.v.clone())?;
        npz.write(path)?;
        Ok(())
    }

    /// Reads a checkpoint written by [`TrainState::save`].
    ///
    /// # Errors
    /// [`MnistError::Checkpoint`] naming the file and what is wrong.
    pub fn load(path: &Path) -> Result<Self, MnistError> {
        let bad = |m: String| MnistError::Checkpoint { path: path.to_path_buf(), message: m };
        let file = std::fs::File::open(path).map_err(|e| bad(format!("cannot open ({e})")))?;
        let mut npz = ndarray_npy::NpzReader::new(file).map_err(|e| bad(format!("not an .npz file ({e})")))?;
        let mut vec_u8 = |name: &str| -> Result<Vec<u8>, MnistError> {
            let a: ndarray::Array1<u8> = npz.by_name(name).map_err(|e| bad(format!("no array {name} ({e})")))?;
            Ok(a.to_vec())
        };
        let meta: Meta =
            serde_json::from_slice(&vec_u8("meta_json")?).map_err(|e| bad(format!("malformed metadata ({e})")))?;
        if meta.format != 1 {
            return Err(bad(format!("format {} is not one this version reads (1)", meta.format)));
        }
        let mut f32s = |name: &str| -> Result<Vec<f32>, MnistError> {
            let a: ndarray::Array1<f32> = npz.by_name(name).map_err(|e| bad(format!("no array {name} ({e})")))?;
            Ok(a.to_vec())
        };
        let mut state = TrainState::new(meta.method, meta.pixels, meta.settings.clone());
        let (enc, dec, m, v) = (f32s("encoder")?, f32s("decoder")?, f32s("adam_m")?, f32s("adam_v")?);
        if enc.len() != state.model.encoder.params.len()
            || dec.len() != state.model.decoder.params.len()
            || m.len() != state.m.len()
            || v.len() != state.v.len()
        {
            return Err(bad("array sizes do not match the model the metadata describes".into()));
        }
        if enc.iter().chain(&dec).any(|x| !x.is_finite()) {
            return Err(bad("the parameters contain NaN or infinity".into()));
        }
        state.model.encoder.params = enc;
        state.model.decoder.params = dec;
        state.m = m;
        state.v = v;
        state.step = meta.step;
        state.epoch = meta.epoch;
        state.batch_in_epoch = meta.batch_in_epoch;
        state.epoch_sum = meta.epoch_sum;
        state.curve = meta.curve;
        state.seconds = meta.seconds;
        Ok(state)
    }
}

/// One Adam step over `params` in parallel blocks.
fn adam_update(adam: &vf_common::adam::AdamStep<f32>, params: &mut [f32], m: &mut [f32], v: &mut [f32], g: &[f32]) {
    const BLOCK: usize = 1 << 14;
    params
        .par_chunks_mut(BLOCK)
        .zip(m.par_chunks_mut(BLOCK))
        .zip(v.par_chunks_mut(BLOCK))
        .zip(g.par_chunks(BLOCK))
        .for_each(|(((p, m), v), g)| {
            adam.apply(p, g, m, v);
        });
}

fn add_parts(acc: &mut LossParts, p: &LossParts, f: f64) {
    acc.total += f * p.total;
    acc.reconstruction += f * p.reconstruction;
    acc.bounds += f * p.bounds;
    acc.signed_distance += f * p.signed_distance;
    acc.centroidal += f * p.centroidal;
}

/// The training points of image `i` in epoch `epoch` (the same for every method).
pub fn training_points(
    settings: &TrainSettings,
    digit: &Digit,
    boundary: &[[f64; 2]],
    i: u32,
    epoch: usize,
) -> (Vec<[f64; 2]>, Vec<bool>) {
    let mut rng = ChunkRng::for_chunk(settings.seed, Stream::MnistPoints, (epoch as u64) << 32 | u64::from(i));
    digit.sample(boundary, settings.points, &mut rng)
}

/// Mean loss over the images `idx` (the Voronoi decoder's at temperature `beta`), the
/// mean Voronoi terms, and the gradient (encoder parameters then decoder parameters).
pub fn loss_and_grad(
    model: &Model,
    settings: &TrainSettings,
    beta: f64,
    data: &DigitSet,
    idx: &[u32],
    epoch: usize,
) -> Result<(f64, LossParts, Vec<f32>), MnistError> {
    let (rows, cols) = (data.images.rows, data.images.cols);
    let ne = model.encoder.params.len();
    let nd = model.decoder.params.len();
    let scale = 1.0 / idx.len().max(1) as f64;
    let vloss = VoronoiLoss { beta, ..settings.voronoi };
    let parts: Vec<(f64, LossParts, Vec<f32>)> = idx
        .par_chunks(CHUNK_IMAGES)
        .map(|chunk| {
            let mut grad = vec![0.0f32; ne + nd];
            let (ge, gd) = grad.split_at_mut(ne);
            let images: Vec<&[u8]> = chunk.iter().map(|&i| data.images.image(i as usize)).collect();
            let x = pixels_to_input(&images);
            let mut te = Tape::default();
            model.encoder.forward(&x, chunk.len(), &mut te);
            let z = te.output().to_vec();
            let mut d_z = vec![0.0f32; chunk.len() * LATENT];
            let mut loss = 0.0;
            let mut sum_parts = LossParts::default();
            match model.method {
                Method::Voronoi => {
                    let mut td = Tape::default();
                    model.decoder.forward(&z, chunk.len(), &mut td);
                    let mut d_out = vec![0.0f32; chunk.len() * 2 * SITES];
                    for (k, &i) in chunk.iter().enumerate() {
                        let digit = Digit::new(images[k], rows, cols);
                        let boundary = digit.boundary();
                        let (pts, occ) = training_points(settings, &digit, &boundary, i, epoch);
                        let sites = sites_of(&td.output()[k * 2 * SITES..(k + 1) * 2 * SITES]);
                        let mut g = vec![[0.0f64; 2]; SITES];
                        let p = voronoi_loss_grad(&vloss, &digit, &boundary, &sites, &pts, &occ, &mut g);
                        loss += p.total;
                        add_parts(&mut sum_parts, &p, 1.0);
                        for (s, gs) in g.iter().enumerate() {
                            d_out[k * 2 * SITES + 2 * s] = (gs[0] * scale) as f32;
                            d_out[k * 2 * SITES + 2 * s + 1] = (gs[1] * scale) as f32;
                        }
                    }
                    model.decoder.backward(&td, &d_out, gd, Some(&mut d_z));
                }
                Method::OccNet { hidden } => {
                    let mut s = OccNetScratch::new(hidden);
                    for (k, &i) in chunk.iter().enumerate() {
                        let digit = Digit::new(images[k], rows, cols);
                        let boundary = digit.boundary();
                        let (pts, occ) = training_points(settings, &digit, &boundary, i, epoch);
                        let l = occnet_loss_grad(
                            &model.decoder,
                            &z[k * LATENT..(k + 1) * LATENT],
                            &pts,
                            &occ,
                            scale as f32,
                            &mut s,
                            gd,
                            &mut d_z[k * LATENT..(k + 1) * LATENT],
                        );
                        loss += l;
                        sum_parts.total += l;
                    }
                }
            }
            model.encoder.backward(&te, &d_z, ge, None);
            (loss, sum_parts, grad)
        })
        .collect();
    let mut grad = vec![0.0f32; ne + nd];
    let mut loss = 0.0;
    let mut sum_parts = LossParts::default();
    // Sum the chunks' buffers in chunk order, in parallel over blocks of parameters.
    const BLOCK: usize = 1 << 14;
    grad.par_chunks_mut(BLOCK).enumerate().for_each(|(bi, g)| {
        let off = bi * BLOCK;
        let len = g.len();
        for (_, _, part) in &parts {
            for (a, &b) in g.iter_mut().zip(&part[off..off + len]) {
                *a += b;
            }
        }
    });
    for (l, p, _) in &parts {
        loss += l;
        add_parts(&mut sum_parts, p, 1.0);
    }
    let mut mean = LossParts::default();
    add_parts(&mut mean, &sum_parts, scale);
    Ok((loss * scale, mean, grad))
}
