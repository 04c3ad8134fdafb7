//! `voronoi-fit mnist train | eval | tsne | interpolate | run | bench`: the arguments of
//! the seed's MNIST autoencoder experiment, run by `mnist::pipeline` (crates/mnist), with
//! progress bars, Ctrl-C, and a closing summary.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use mnist::eval::MethodResult;
use mnist::pipeline::{self, BenchRow, DataSource, Experiment, InterpolationReport, Report, TsneReport};
use mnist::train::Progress;
use mnist::{Method, MnistError};

use crate::cli_error::{CliError, InputFault};

impl InputFault for MnistError {
    fn is_input_fault(&self) -> bool {
        MnistError::is_input_fault(self)
    }
}

/// An interrupted training run exits 130 with its message; every other error by its
/// classification.
fn cli_error(e: MnistError) -> CliError {
    match e {
        MnistError::TrainingInterrupted { .. } => CliError::Interrupted(e.to_string()),
        e => e.into(),
    }
}

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(subcommand)]
    pub command: Sub,
}

#[derive(clap::Subcommand, Debug)]
pub enum Sub {
    /// Train the autoencoders (resumes from OUT/METHOD/checkpoint.npz).
    Train(TrainArgs),
    /// The table on the test set: mismatched pixels per image and IoU (OUT/table.md,
    /// results.json, results.csv).
    Eval(EvalArgs),
    /// tSNE of the test codes, coloured by class (OUT/tsne_METHOD.png/.svg/.npz).
    Tsne(TsneArgs),
    /// Latent interpolation between encoded digits (OUT/interpolation.png/.svg).
    Interpolate(InterpArgs),
    /// Everything: train, eval, tsne, interpolate, reconstructions, curves.
    Run(RunArgs),
    /// Training throughput (images per second, forward + backward) of each method.
    Bench(BenchArgs),
}

#[derive(clap::Args, Debug, Clone)]
pub struct Data {
    /// Folder with the MNIST IDX files (gzip or raw): train-images-idx3-ubyte (the
    /// official 60,000) or train10k-images-idx3-ubyte, and t10k-images-idx3-ubyte, each
    /// with its labels file.
    #[arg(long)]
    pub data: Option<PathBuf>,
    /// Training images file (instead of --data's).
    #[arg(long, requires = "train_labels")]
    pub train_images: Option<PathBuf>,
    /// Training labels file.
    #[arg(long, requires = "train_images")]
    pub train_labels: Option<PathBuf>,
    /// Test images file (instead of --data's).
    #[arg(long, requires = "test_labels")]
    pub test_images: Option<PathBuf>,
    /// Test labels file.
    #[arg(long, requires = "test_images")]
    pub test_labels: Option<PathBuf>,
}

impl Data {
    fn source(&self) -> DataSource {
        DataSource {
            dir: self.data.clone(),
            train: self.train_images.clone().zip(self.train_labels.clone()),
            test: self.test_images.clone().zip(self.test_labels.clone()),
        }
    }
}

#[derive(clap::Args, Debug, Clone)]
pub struct Common {
    #[command(flatten)]
    pub data: Data,
    /// Output folder (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// The CI-sized run: 1,000 training images, 2 epochs, 1,000 test images, 500 codes
    /// in the tSNE.
    #[arg(long)]
    pub quick: bool,
    /// Methods, comma-separated (default: occnet128,occnet512,occnet16k,voronoi).
    #[arg(long, value_delimiter = ',')]
    pub methods: Option<Vec<Method>>,
    /// No progress bars.
    #[arg(long)]
    pub quiet: bool,
}

impl Common {
    fn experiment(&self) -> Experiment {
        Experiment { out: self.out.clone(), quick: self.quick, methods: methods_or_all(&self.methods) }
    }
}

/// The methods given, or all four.
fn methods_or_all(methods: &Option<Vec<Method>>) -> Vec<Method> {
    methods.clone().filter(|m| !m.is_empty()).unwrap_or_else(Method::all)
}

#[derive(clap::Args, Debug, Clone)]
pub struct TrainOptions {
    /// Epochs (default: 12, --quick 2).
    #[arg(long)]
    pub epochs: Option<usize>,
    /// Training images used, the first N of the set (default: 10,000, --quick 1,000).
    #[arg(long)]
    pub images: Option<usize>,
    /// Images per step.
    #[arg(long)]
    pub batch: Option<usize>,
    /// Training points per image and epoch.
    #[arg(long)]
    pub points: Option<usize>,
    /// Adam's learning rate.
    #[arg(long)]
    pub lr: Option<f64>,
    /// β of the soft-Voronoi, in 1/unit-square lengths (default 100; the seed's is 10,000,
    /// see docs/mnist.md).
    #[arg(long)]
    pub beta: Option<f64>,
    /// Anneal β geometrically from this value at the first step to --beta at the last.
    #[arg(long)]
    pub beta_start: Option<f64>,
    /// Seed of the weights, the image order and the training points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Start over even if a checkpoint exists.
    #[arg(long)]
    pub restart: bool,
    /// Checkpoint every this many steps (and after every epoch).
    #[arg(long, default_value_t = 100)]
    pub checkpoint_every: usize,
}

impl TrainOptions {
    fn options(&self) -> pipeline::TrainOptions {
        pipeline::TrainOptions {
            epochs: self.epochs,
            images: self.images,
            batch: self.batch,
            points: self.points,
            lr: self.lr,
            beta: self.beta,
            beta_start: self.beta_start,
            seed: self.seed,
            restart: self.restart,
            checkpoint_every: self.checkpoint_every,
        }
    }
}

#[derive(clap::Args, Debug)]
pub struct TrainArgs {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub train: TrainOptions,
}

#[derive(clap::Args, Debug)]
pub struct EvalArgs {
    #[command(flatten)]
    pub common: Common,
    /// Test images evaluated, the first N (default: all, --quick 1,000).
    #[arg(long)]
    pub test_count: Option<usize>,
}

#[derive(clap::Args, Debug)]
pub struct TsneArgs {
    #[command(flatten)]
    pub common: Common,
    /// Test codes embedded, the first N (default: 10,000, --quick 500).
    #[arg(long)]
    pub count: Option<usize>,
    /// Iterations (default 1,000).
    #[arg(long)]
    pub iterations: Option<usize>,
}

#[derive(clap::Args, Debug)]
pub struct InterpArgs {
    #[command(flatten)]
    pub common: Common,
    /// Digit pairs A:B (the first test digit of each class), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "3:5,9:6")]
    pub pairs: Vec<String>,
    /// Interpolation steps, both ends included.
    #[arg(long, default_value_t = 8)]
    pub steps: usize,
}

#[derive(clap::Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub common: Common,
    #[command(flatten)]
    pub train: TrainOptions,
}

#[derive(clap::Args, Debug)]
pub struct BenchArgs {
    #[command(flatten)]
    pub data: Data,
    /// Methods, comma-separated (default: all four).
    #[arg(long, value_delimiter = ',')]
    pub methods: Option<Vec<Method>>,
    /// Images per step.
    #[arg(long, default_value_t = 32)]
    pub batch: usize,
    /// Training points per image.
    #[arg(long, default_value_t = 256)]
    pub points: usize,
    /// Timed steps per method (after 2 warm-up steps).
    #[arg(long, default_value_t = 20)]
    pub steps: usize,
}

pub fn run(args: Args) -> Result<(), CliError> {
    let mut term = Terminal::new(match &args.command {
        Sub::Train(a) => a.common.quiet,
        Sub::Eval(a) => a.common.quiet,
        Sub::Tsne(a) => a.common.quiet,
        Sub::Interpolate(a) => a.common.quiet,
        Sub::Run(a) => a.common.quiet,
        Sub::Bench(_) => false,
    });
    match args.command {
        Sub::Train(a) => {
            let exp = a.common.experiment();
            let opts = a.train.options();
            let stop = term.stop.clone();
            let trained = pipeline::train(&exp, &opts, &a.common.data.source(), &stop, &mut term).map_err(cli_error)?;
            crate::output::out!(
                "mnist train: {} trained on {} images in {:.0} s; checkpoints in {}/METHOD/checkpoint.npz.",
                exp.methods.iter().map(|m| m.name()).collect::<Vec<_>>().join(", "),
                opts.settings(exp.quick).train_images,
                trained.seconds,
                exp.out.display()
            );
        }
        Sub::Eval(a) => {
            let exp = a.common.experiment();
            let opts = pipeline::EvalOptions { test_count: a.test_count };
            let results = pipeline::evaluate(&exp, &opts, &a.common.data.source(), &mut term).map_err(cli_error)?;
            print_table_summary(&results, &exp.out);
        }
        Sub::Tsne(a) => {
            let opts = pipeline::TsneOptions { count: a.count, iterations: a.iterations };
            pipeline::tsne(&a.common.experiment(), &opts, &a.common.data.source(), &mut term).map_err(cli_error)?;
        }
        Sub::Interpolate(a) => {
            let opts = pipeline::InterpolateOptions { pairs: a.pairs, steps: a.steps };
            pipeline::interpolate(&a.common.experiment(), &opts, &a.common.data.source(), &mut term)
                .map_err(cli_error)?;
        }
        Sub::Run(a) => {
            let exp = a.common.experiment();
            let stop = term.stop.clone();
            let r = pipeline::run(&exp, &a.train.options(), &a.common.data.source(), &stop, &mut term)
                .map_err(cli_error)?;
            print_table_summary(&r.results, &exp.out);
            let settings = r.trained.states.first().map(|s| &s.settings);
            crate::output::out!(
                "mnist run ({}): {} methods trained on {} images for {} epochs, evaluated on {} test digits, tSNE and interpolation drawn, in {:.0} s; everything is in {} (run.json has the settings and times).",
                if exp.quick { "quick" } else { "full" },
                r.trained.states.len(),
                settings.map_or(0, |s| s.train_images),
                settings.map_or(0, |s| s.epochs),
                r.results.first().map_or(0, |r| r.images),
                r.seconds,
                exp.out.display()
            );
        }
        Sub::Bench(a) => {
            let opts = pipeline::BenchOptions {
                methods: methods_or_all(&a.methods),
                batch: a.batch,
                points: a.points,
                steps: a.steps,
            };
            let rows = pipeline::bench(&opts, &a.data.source(), &mut term).map_err(cli_error)?;
            // Through a `Value`: its keys come out sorted, as they always have.
            let json = serde_json::to_value(&rows).and_then(|v| serde_json::to_string_pretty(&v));
            println!("{}", json.map_err(anyhow::Error::from)?);
        }
    }
    Ok(())
}

fn print_table_summary(results: &[MethodResult], out: &Path) {
    let rows: Vec<String> = results
        .iter()
        .map(|r| format!("{} {:.1} pixels (IoU {:.3})", r.label, r.mismatched_pixels.mean, r.iou.mean))
        .collect();
    crate::output::out!(
        "mnist eval on {} test digits: mean mismatched pixels per image {}; wrote {}/table.md, results.json, results.csv.",
        results.first().map_or(0, |r| r.images),
        rows.join(", "),
        out.display()
    );
}

/// The pipeline's reports on the terminal: progress bars (none with `--quiet`) on stderr,
/// finished stages on stdout, and Ctrl-C, which stops training after a checkpoint.
struct Terminal {
    quiet: bool,
    bar: indicatif::ProgressBar,
    /// Set by Ctrl-C once training has started.
    stop: Arc<AtomicBool>,
    handler: bool,
}

impl Terminal {
    fn new(quiet: bool) -> Self {
        Terminal {
            quiet,
            bar: indicatif::ProgressBar::hidden(),
            stop: Arc::new(AtomicBool::new(false)),
            handler: false,
        }
    }

    /// A new bar of `len` steps (hidden with `--quiet`).
    fn bar(&mut self, len: u64, template: &str) {
        self.bar = if self.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(len) };
        self.bar.set_style(indicatif::ProgressStyle::with_template(template).expect("a valid progress template"));
    }
}

impl Report for Terminal {
    fn training_starts(&mut self) {
        if !self.handler {
            let f = self.stop.clone();
            let _ = ctrlc::set_handler(move || f.store(true, Ordering::SeqCst));
            self.handler = true;
        }
    }

    fn train_start(&mut self, method: Method, done: u64, total: u64) {
        self.bar(total, "{prefix:>11} {bar:30} {pos}/{len} steps, {msg}, {elapsed} (ETA {eta})");
        self.bar.set_prefix(method.name());
        self.bar.set_position(done);
    }

    fn train_progress(&mut self, _: Method, p: &Progress) {
        self.bar.set_position((p.epoch * p.batches + p.batch) as u64);
        self.bar.set_message(format!("epoch {}/{}, loss {:.4}", p.epoch + 1, p.epochs, p.loss));
    }

    fn train_end(&mut self, _: Method) {
        self.bar.finish_and_clear();
    }

    fn eval_start(&mut self, methods: usize) {
        self.bar(methods as u64, "eval {bar:30} {pos}/{len} methods, {msg}");
    }

    fn eval_method(&mut self, method: Method) {
        self.bar.set_message(method.name());
    }

    fn eval_method_done(&mut self, _: Method) {
        self.bar.inc(1);
    }

    fn eval_end(&mut self) {
        self.bar.finish_and_clear();
    }

    fn tsne_start(&mut self, method: Method, codes: usize) {
        if !self.quiet {
            eprintln!("voronoi-fit: tSNE of {codes} {} codes…", method.name());
        }
    }

    fn tsne_done(&mut self, r: &TsneReport) {
        crate::output::out!(
            "mnist tsne: {} codes of {} embedded in {:.1} s (bhtsne's cost estimate {:.3}); wrote {}.png/.svg/.npz.",
            r.codes,
            r.method.name(),
            r.seconds,
            r.bhtsne_cost,
            r.stem.display()
        );
    }

    fn interpolation_done(&mut self, r: &InterpolationReport) {
        crate::output::out!(
            "mnist interpolate: {} pair(s) in {} steps, {} beside {}; wrote {}/interpolation.png/.svg and reconstructions.png/.svg.",
            r.pairs,
            r.steps,
            r.voronoi.label(),
            r.occnet.label(),
            r.out.display()
        );
    }

    fn bench_done(&mut self, row: &BenchRow) {
        eprintln!(
            "voronoi-fit: {}: {:.0} images/s (forward + backward + Adam, batch {}, {} points)",
            row.method, row.images_per_second, row.batch, row.points
        );
    }

    fn warning(&mut self, message: &str) {
        eprintln!("voronoi-fit: {message}");
    }
}
