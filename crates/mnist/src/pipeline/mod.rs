//! The experiment end to end, as the `voronoi-fit mnist` commands run it: training with
//! checkpoints that resume ([`train`]), the table on the test set ([`evaluate`]), the tSNE
//! of the codes ([`tsne`]), the latent interpolation and reconstructions
//! ([`interpolate`]), all of them in one go ([`run`]), and the training throughput
//! ([`bench()`]).
//!
//! Each command takes plain option structs (no command-line parsing here), reads the data
//! through a [`DataSource`], writes its files into the [`Experiment`]'s output folder
//! atomically, reports progress and finished stages through a [`Report`] and returns what
//! it measured. The caller draws progress bars and prints; [`Silent`] reports nothing.
//!
//! Files in the output folder: `METHOD/checkpoint.npz` (one per method), `table.md`,
//! `results.json`, `results.csv`, `tsne_METHOD.png/.svg/.npz`, `interpolation.png/.svg`,
//! `reconstructions.png/.svg`, and from [`run`] also `curves.png/.svg` and `run.json`.
//!
//! Error messages name the options by their command-line flags (`--steps`, `--restart`),
//! which is how the CLI spells them.

mod bench;
mod pictures;
mod table;
mod training;

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

pub use bench::{bench, BenchOptions, BenchRow};
pub use pictures::{
    interpolate, interpolate_models, tsne, tsne_model, InterpolateOptions, InterpolationReport, TsneOptions, TsneReport,
};
pub use table::{check_sizes, evaluate, evaluate_models, write_results, EvalOptions, FINE_IMAGES};
pub use training::{checkpoint_path, load_models, train, train_methods, TrainOptions, Trained};

use crate::error::MnistError;
use crate::eval::MethodResult;
use crate::figures;
use crate::idx::{self, DigitSet};
use crate::model::{Method, Model};
use crate::train::{CurvePoint, Progress};

/// What every command shares: where the outputs go, the quick (CI-sized) or the full
/// run, and the methods.
#[derive(Clone, Debug, PartialEq)]
pub struct Experiment {
    /// Output folder (created if missing); checkpoints go to `out/METHOD/checkpoint.npz`.
    pub out: PathBuf,
    /// The CI-sized run: 1,000 training images, 2 epochs, 1,000 test images, 500 codes
    /// in the tSNE (each overridable by the commands' options).
    pub quick: bool,
    /// The methods, in order.
    pub methods: Vec<Method>,
}

/// Where the digits are: a folder of the MNIST IDX files ([`idx::find_set`]), or explicit
/// image and label files for either set (which take precedence over the folder).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DataSource {
    /// Folder with the IDX files (gzip or raw).
    pub dir: Option<PathBuf>,
    /// Training images and labels files.
    pub train: Option<(PathBuf, PathBuf)>,
    /// Test images and labels files.
    pub test: Option<(PathBuf, PathBuf)>,
}

impl DataSource {
    /// Reads the training set (`test` false) or the test set.
    ///
    /// # Errors
    /// [`MnistError::Options`] when neither a folder nor files are given; the errors of
    /// [`idx::find_set`] and [`idx::read_set`].
    pub fn load(&self, test: bool) -> Result<DigitSet, MnistError> {
        let explicit = if test { &self.test } else { &self.train };
        let (im, lb) = match explicit {
            Some((i, l)) => (i.clone(), l.clone()),
            None => {
                let dir = self.dir.as_ref().ok_or_else(|| {
                    MnistError::Options(format!(
                        "no {} data: give --data DIR (the folder of the MNIST IDX files, e.g. ../shared/mnist) or --{}-images/--{}-labels",
                        if test { "test" } else { "training" },
                        if test { "test" } else { "train" },
                        if test { "test" } else { "train" }
                    ))
                })?;
                idx::find_set(dir, test)?
            }
        };
        idx::read_set(&im, &lb)
    }
}

/// Progress and finished stages of a command, for the caller to show. Every method does
/// nothing by default.
pub trait Report {
    /// Training is about to start (once per [`train_methods`], before the first method;
    /// the CLI installs its Ctrl-C handler here).
    fn training_starts(&mut self) {}
    /// `method` starts training at step `done` of `total` (more than 0 when it resumes).
    fn train_start(&mut self, method: Method, done: u64, total: u64) {
        let _ = (method, done, total);
    }
    /// A training step of `method` is done.
    fn train_progress(&mut self, method: Method, progress: &Progress) {
        let _ = (method, progress);
    }
    /// `method` stopped training (finished, interrupted or failed).
    fn train_end(&mut self, method: Method) {
        let _ = method;
    }
    /// The evaluation of `methods` models starts.
    fn eval_start(&mut self, methods: usize) {
        let _ = methods;
    }
    /// `method`'s evaluation starts.
    fn eval_method(&mut self, method: Method) {
        let _ = method;
    }
    /// `method`'s evaluation is done.
    fn eval_method_done(&mut self, method: Method) {
        let _ = method;
    }
    /// Every model is evaluated (the result files are written next).
    fn eval_end(&mut self) {}
    /// The tSNE of `codes` codes of `method`'s encoder starts.
    fn tsne_start(&mut self, method: Method, codes: usize) {
        let _ = (method, codes);
    }
    /// A tSNE is done and its files are written.
    fn tsne_done(&mut self, report: &TsneReport) {
        let _ = report;
    }
    /// The interpolation and reconstruction figures are written.
    fn interpolation_done(&mut self, report: &InterpolationReport) {
        let _ = report;
    }
    /// One method's throughput is measured.
    fn bench_done(&mut self, row: &BenchRow) {
        let _ = row;
    }
    /// Something the user should know that does not stop the command (a checkpoint used
    /// before its last epoch).
    fn warning(&mut self, message: &str) {
        let _ = message;
    }
}

/// A [`Report`] that shows nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Silent;

impl Report for Silent {}

/// What [`run`] did.
#[derive(Clone, Debug)]
pub struct RunReport {
    /// The trained states and the training time of this process.
    pub trained: Trained,
    /// The table's rows (also in `results.json`).
    pub results: Vec<MethodResult>,
    /// Seconds of the evaluation.
    pub eval_seconds: f64,
    /// Seconds of the Voronoi model's tSNE.
    pub tsne_seconds: f64,
    /// Seconds of the whole run.
    pub seconds: f64,
}

/// Everything (`mnist run`): trains every method (resuming), draws the training curves
/// (`curves.png/.svg`), evaluates on the test set (the first 1,000 digits when quick, else
/// all), embeds the Voronoi model's codes with tSNE, draws the interpolation of 3 → 5 and
/// 9 → 6 in 8 steps and the reconstructions, and writes `run.json` (settings and times).
///
/// # Errors
/// [`MnistError::Options`] when the methods lack voronoi or an OccNet, or the two sets'
/// image sizes differ; the errors of the steps.
pub fn run(
    exp: &Experiment,
    opts: &TrainOptions,
    data: &DataSource,
    stop: &AtomicBool,
    report: &mut dyn Report,
) -> Result<RunReport, MnistError> {
    let t0 = Instant::now();
    if !exp.methods.contains(&Method::Voronoi) || !exp.methods.iter().any(|m| matches!(m, Method::OccNet { .. })) {
        return Err(MnistError::Options(
            "`mnist run` needs voronoi and at least one OccNet method in --methods".into(),
        ));
    }
    let train = data.load(false)?;
    let test = data.load(true)?;
    if (test.images.rows, test.images.cols) != (train.images.rows, train.images.cols) {
        return Err(MnistError::Options(format!(
            "{} has {}×{} images but {} has {}×{}; the two sets must have one image size",
            test.source.display(),
            test.images.rows,
            test.images.cols,
            train.source.display(),
            train.images.rows,
            train.images.cols
        )));
    }
    let trained = train_methods(exp, opts, &train, stop, report)?;
    let curves: Vec<(String, Vec<CurvePoint>)> =
        trained.states.iter().map(|s| (s.model.method.label(), s.curve.clone())).collect();
    let chart = figures::curves_chart(&curves);
    chart.write_svg(&exp.out.join("curves.svg"))?;
    chart.write_png(&exp.out.join("curves.png"))?;
    let models: Vec<Model> = trained.states.iter().map(|s| s.model.clone()).collect();
    check_sizes(&models, &test)?;
    let t_eval = Instant::now();
    let n = if exp.quick { 1000 } else { usize::MAX };
    let results = evaluate_models(exp, &models, &test, n, report)?;
    let eval_seconds = t_eval.elapsed().as_secs_f64();
    let voronoi = models.iter().find(|m| m.method == Method::Voronoi).expect("checked above");
    let tsne_seconds = tsne_model(exp, voronoi, &test, &TsneOptions::default(), report)?.seconds;
    interpolate_models(exp, &models, &test, &InterpolateOptions::default(), report)?;
    let total = t0.elapsed().as_secs_f64();
    let run = serde_json::json!({
        "quick": exp.quick,
        "train_data": train.source.display().to_string(),
        "test_data": test.source.display().to_string(),
        "settings": trained.states.first().map(|s| s.settings.clone()),
        "training_seconds_per_method": trained.states.iter().map(|s| (s.model.method.name(), s.seconds)).collect::<std::collections::BTreeMap<_, _>>(),
        "seconds": { "train_this_process": trained.seconds, "eval": eval_seconds, "tsne": tsne_seconds, "total": total },
        "threads": rayon::current_num_threads(),
    });
    write_text(
        &exp.out.join("run.json"),
        &serde_json::to_string_pretty(&run).map_err(|e| MnistError::Write(e.to_string()))?,
    )?;
    Ok(RunReport { trained, results, eval_seconds, tsne_seconds, seconds: total })
}

/// Writes `s` to `path` atomically.
fn write_text(path: &Path, s: &str) -> Result<(), MnistError> {
    mesh_io::atomic_write(path, |w| w.write_all(s.as_bytes()))?;
    Ok(())
}
