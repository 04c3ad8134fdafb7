//! Training throughput: images per second of forward + backward + Adam, per method.

use std::time::Instant;

use serde::Serialize;

use super::{DataSource, Report};
use crate::error::MnistError;
use crate::model::Method;
use crate::train::{TrainSettings, TrainState};

/// Options of the benchmark.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchOptions {
    /// The methods timed, in order.
    pub methods: Vec<Method>,
    /// Images per step.
    pub batch: usize,
    /// Training points per image.
    pub points: usize,
    /// Timed steps per method (after 2 warm-up steps).
    pub steps: usize,
}

impl Default for BenchOptions {
    /// All four methods, batches of 32 images with 256 points, 20 timed steps.
    fn default() -> Self {
        BenchOptions { methods: Method::all(), batch: 32, points: 256, steps: 20 }
    }
}

/// One method's throughput.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BenchRow {
    /// The method's short name.
    pub method: String,
    /// Images per step.
    pub batch: usize,
    /// Training points per image.
    pub points: usize,
    /// Timed steps.
    pub steps: usize,
    /// Seconds of the timed steps.
    pub seconds: f64,
    /// Training images per second.
    pub images_per_second: f64,
    /// Decoder parameters.
    pub decoder_params: usize,
    /// Encoder parameters.
    pub encoder_params: usize,
    /// Rayon threads.
    pub threads: usize,
}

/// The `mnist bench` command: for each method, a fresh model takes 2 warm-up steps and
/// `opts.steps` timed steps on consecutive batches of the training set.
///
/// # Errors
/// Those of [`DataSource::load`]; [`MnistError::Config`] for a batch or point count out
/// of range or a non-finite loss.
pub fn bench(opts: &BenchOptions, data: &DataSource, report: &mut dyn Report) -> Result<Vec<BenchRow>, MnistError> {
    let train = data.load(false)?;
    let mut rows = Vec::new();
    for &m in &opts.methods {
        let settings = TrainSettings {
            batch: opts.batch,
            points: opts.points,
            train_images: train.len(),
            ..TrainSettings::full()
        };
        settings.validate()?;
        let mut state = TrainState::new(m, train.images.rows * train.images.cols, settings);
        let n = train.len() as u32;
        let batch =
            |k: usize| -> Vec<u32> { (0..opts.batch as u32).map(|i| (k as u32 * opts.batch as u32 + i) % n).collect() };
        for k in 0..2 {
            state.step(&train, &batch(k))?;
        }
        let t = Instant::now();
        for k in 0..opts.steps {
            state.step(&train, &batch(k + 2))?;
        }
        let seconds = t.elapsed().as_secs_f64();
        let row = BenchRow {
            method: m.name(),
            batch: opts.batch,
            points: opts.points,
            steps: opts.steps,
            seconds,
            images_per_second: (opts.steps * opts.batch) as f64 / seconds,
            decoder_params: state.model.decoder.params.len(),
            encoder_params: state.model.encoder.params.len(),
            threads: rayon::current_num_threads(),
        };
        report.bench_done(&row);
        rows.push(row);
    }
    Ok(rows)
}
