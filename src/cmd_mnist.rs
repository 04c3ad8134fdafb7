//! `voronoi-fit mnist train | eval | tsne | interpolate | run | bench`: the seed's MNIST
//! autoencoder experiment (crates/mnist) with progress bars, checkpoints that resume,
//! and a closing summary.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use mnist::eval::{self, MethodResult};
use mnist::figures::{self, Interpolation};
use mnist::tsne::{self, TsneSettings};
use mnist::{idx, DigitSet, Method, MnistError, Model, TrainSettings, TrainState};

use crate::cli_error::{CliError, InputFault};

impl InputFault for MnistError {
    fn is_input_fault(&self) -> bool {
        matches!(
            self,
            MnistError::Idx { .. }
                | MnistError::Mismatch { .. }
                | MnistError::Missing { .. }
                | MnistError::Config(_)
                | MnistError::Checkpoint { .. }
        )
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
    fn load(&self, test: bool) -> Result<DigitSet, CliError> {
        let explicit =
            if test { (&self.test_images, &self.test_labels) } else { (&self.train_images, &self.train_labels) };
        let (im, lb) = match explicit {
            (Some(i), Some(l)) => (i.clone(), l.clone()),
            _ => {
                let dir = self.data.as_ref().ok_or_else(|| {
                    CliError::input(format!(
                        "no {} data: give --data DIR (the folder of the MNIST IDX files, e.g. ../shared/mnist) or --{}-images/--{}-labels",
                        if test { "test" } else { "training" },
                        if test { "test" } else { "train" },
                        if test { "test" } else { "train" }
                    ))
                })?;
                idx::find_set(dir, test)?
            }
        };
        Ok(idx::read_set(&im, &lb)?)
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
    fn methods(&self) -> Vec<Method> {
        self.methods.clone().filter(|m| !m.is_empty()).unwrap_or_else(Method::all)
    }
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
    /// see the README).
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

/// Test images in the 112 × 112 IoU (16× the work of the 28 × 28 grid; OccNet 16k takes
/// about 40 ms an image there).
const FINE_IMAGES: usize = 1000;

pub fn run(args: Args) -> Result<(), CliError> {
    match args.command {
        Sub::Train(a) => {
            let train = a.common.data.load(false)?;
            let (_, secs) = train_all(&a.common, &a.train, &train)?;
            crate::output::out!(
                "mnist train: {} trained on {} images in {:.0} s; checkpoints in {}/METHOD/checkpoint.npz.",
                a.common.methods().iter().map(|m| m.name()).collect::<Vec<_>>().join(", "),
                settings_for(&a.common, &a.train).train_images,
                secs,
                a.common.out.display()
            );
            Ok(())
        }
        Sub::Eval(a) => {
            let test = a.common.data.load(true)?;
            let models = load_models(&a.common)?;
            check_sizes(&models, &test)?;
            let n = a.test_count.unwrap_or(if a.common.quick { 1000 } else { usize::MAX });
            let results = eval_all(&a.common, &models, &test, n)?;
            print_table_summary(&results, &a.common.out);
            Ok(())
        }
        Sub::Tsne(a) => {
            let test = a.common.data.load(true)?;
            let models = load_models(&a.common)?;
            check_sizes(&models, &test)?;
            for m in &models {
                tsne_one(&a.common, m, &test, a.count, a.iterations)?;
            }
            Ok(())
        }
        Sub::Interpolate(a) => {
            let test = a.common.data.load(true)?;
            let models = load_models(&a.common)?;
            check_sizes(&models, &test)?;
            interpolate(&a.common, &models, &test, &a.pairs, a.steps)?;
            Ok(())
        }
        Sub::Run(a) => run_all(a),
        Sub::Bench(a) => bench(a),
    }
}

fn settings_for(c: &Common, t: &TrainOptions) -> TrainSettings {
    let mut s = if c.quick { TrainSettings::quick() } else { TrainSettings::full() };
    if let Some(e) = t.epochs {
        s.epochs = e;
    }
    if let Some(n) = t.images {
        s.train_images = n;
    }
    if let Some(b) = t.batch {
        s.batch = b;
    }
    if let Some(p) = t.points {
        s.points = p;
    }
    if let Some(lr) = t.lr {
        s.lr = lr;
    }
    if let Some(b) = t.beta {
        s.voronoi.beta = b;
    }
    if t.beta_start.is_some() {
        s.beta_start = t.beta_start;
    }
    s.seed = t.seed;
    s
}

fn checkpoint_path(out: &Path, m: Method) -> PathBuf {
    out.join(m.name()).join("checkpoint.npz")
}

fn interrupt_flag() -> Arc<AtomicBool> {
    let flag = Arc::new(AtomicBool::new(false));
    let f = flag.clone();
    let _ = ctrlc::set_handler(move || f.store(true, Ordering::SeqCst));
    flag
}

/// Trains every method (resuming), returns the finished states and the seconds spent.
fn train_all(c: &Common, t: &TrainOptions, train: &DigitSet) -> Result<(Vec<TrainState>, f64), CliError> {
    let started = Instant::now();
    let mut settings = settings_for(c, t);
    settings.validate()?;
    if settings.train_images > train.len() {
        if t.images.is_some() {
            return Err(CliError::input(format!(
                "--images {}: {} has only {} images",
                settings.train_images,
                train.source.display(),
                train.len()
            )));
        }
        settings.train_images = train.len();
    }
    let pixels = train.images.rows * train.images.cols;
    let stop = interrupt_flag();
    let mut states = Vec::new();
    for m in c.methods() {
        let path = checkpoint_path(&c.out, m);
        std::fs::create_dir_all(path.parent().expect("a folder"))
            .map_err(|e| CliError::failure(format!("{}: cannot create the folder ({e})", c.out.display())))?;
        let mut state = if path.exists() && !t.restart {
            let s = TrainState::load(&path)?;
            if s.settings != settings || s.model.method != m || s.model.encoder.n_in() != pixels {
                return Err(CliError::input(format!(
                    "{}: this checkpoint was trained with other settings ({}); give --restart to start over, or another --out",
                    path.display(),
                    serde_json::to_string(&s.settings).unwrap_or_default()
                )));
            }
            s
        } else {
            TrainState::new(m, pixels, settings.clone())
        };
        let total = (state.settings.epochs * state.batches_per_epoch()) as u64;
        let bar = if c.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(total) };
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{prefix:>11} {bar:30} {pos}/{len} steps, {msg}, {elapsed} (ETA {eta})",
            )
            .map_err(anyhow::Error::from)?,
        );
        bar.set_prefix(m.name());
        bar.set_position((state.epoch * state.batches_per_epoch() + state.batch_in_epoch) as u64);
        let result = state.run(train, Some(&path), t.checkpoint_every, &stop, |p| {
            bar.set_position((p.epoch * p.batches + p.batch) as u64);
            bar.set_message(format!("epoch {}/{}, loss {:.4}", p.epoch + 1, p.epochs, p.loss));
        });
        bar.finish_and_clear();
        match result {
            Ok(()) => {}
            Err(MnistError::Interrupted) => {
                return Err(CliError::Interrupted(format!(
                    "interrupted while training {}; the checkpoint {} is saved: run the same command again to resume",
                    m.name(),
                    path.display()
                )))
            }
            Err(e) => return Err(e.into()),
        }
        states.push(state);
    }
    Ok((states, started.elapsed().as_secs_f64()))
}

fn load_models(c: &Common) -> Result<Vec<Model>, CliError> {
    let mut out = Vec::new();
    for m in c.methods() {
        let path = checkpoint_path(&c.out, m);
        if !path.exists() {
            return Err(CliError::input(format!(
                "{}: no trained {} model; run `voronoi-fit mnist train --out {}` first",
                path.display(),
                m.name(),
                c.out.display()
            )));
        }
        let s = TrainState::load(&path)?;
        if !s.finished() {
            eprintln!(
                "voronoi-fit: {} is at epoch {} of {}; using it as it is",
                path.display(),
                s.epoch,
                s.settings.epochs
            );
        }
        out.push(s.model);
    }
    Ok(out)
}

/// The models take images of the test set's size.
fn check_sizes(models: &[Model], test: &DigitSet) -> Result<(), CliError> {
    let pixels = test.images.rows * test.images.cols;
    if let Some(m) = models.iter().find(|m| m.encoder.n_in() != pixels) {
        return Err(CliError::input(format!(
            "{}: {}×{} images, but the {} model was trained on {} pixels per image",
            test.source.display(),
            test.images.rows,
            test.images.cols,
            m.method.name(),
            m.encoder.n_in()
        )));
    }
    if test.is_empty() {
        return Err(CliError::input(format!("{}: the test set is empty", test.source.display())));
    }
    Ok(())
}

fn eval_all(c: &Common, models: &[Model], test: &DigitSet, n: usize) -> Result<Vec<MethodResult>, CliError> {
    let bar = if c.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(models.len() as u64) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("eval {bar:30} {pos}/{len} methods, {msg}")
            .map_err(anyhow::Error::from)?,
    );
    let mut results = Vec::new();
    for m in models {
        bar.set_message(m.method.name());
        results.push(eval::evaluate(m, test, n, FINE_IMAGES));
        bar.inc(1);
    }
    bar.finish_and_clear();
    write_results(&c.out, &results, test)?;
    Ok(results)
}

fn write_results(out: &Path, results: &[MethodResult], test: &DigitSet) -> Result<(), CliError> {
    let mut md = String::new();
    md.push_str(&format!(
        "Test set: the first {} digits of {} (mismatched pixels on the 28 × 28 grid: per image; IoU: mean per image).\n\n",
        results.first().map_or(0, |r| r.images),
        test.source.display()
    ));
    md.push_str(&eval::table_markdown(results));
    write_text(&out.join("table.md"), &md)?;
    let json = serde_json::to_string_pretty(results).map_err(anyhow::Error::from)?;
    write_text(&out.join("results.json"), &json)?;
    let mut csv = String::from("method,decoder_params,encoder_params,images,mismatched_mean,mismatched_std,mismatched_median,iou28,iou112,images112\n");
    for r in results {
        csv.push_str(&format!(
            "{},{},{},{},{:.3},{:.3},{:.1},{:.5},{:.5},{}\n",
            r.method.name(),
            r.decoder_params,
            r.encoder_params,
            r.images,
            r.mismatched_pixels.mean,
            r.mismatched_pixels.std,
            r.mismatched_pixels.median,
            r.iou.mean,
            r.iou_fine.mean,
            r.images_fine
        ));
    }
    write_text(&out.join("results.csv"), &csv)
}

fn write_text(path: &Path, s: &str) -> Result<(), CliError> {
    mesh_io::atomic_write(path, |w| w.write_all(s.as_bytes())).map_err(|e| CliError::failure(e.to_string()))
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

fn tsne_one(
    c: &Common,
    m: &Model,
    test: &DigitSet,
    count: Option<usize>,
    iterations: Option<usize>,
) -> Result<f64, CliError> {
    let n = count.unwrap_or(if c.quick { 500 } else { 10_000 }).min(test.len());
    let images: Vec<&[u8]> = (0..n).map(|i| test.images.image(i)).collect();
    let codes = m.encode(&images);
    let settings =
        TsneSettings { epochs: iterations.unwrap_or(if c.quick { 300 } else { 1000 }), ..TsneSettings::default() };
    let t = Instant::now();
    if !c.quiet {
        eprintln!("voronoi-fit: tSNE of {n} {} codes…", m.method.name());
    }
    let emb = tsne::embed(&codes, mnist::model::LATENT, &settings)?;
    let secs = t.elapsed().as_secs_f64();
    let labels = &test.labels[..n];
    let title = format!(
        "tSNE of the {} encoder's codes of {n} test digits (perplexity {})",
        m.method.label(),
        settings.perplexity
    );
    let d = figures::tsne_drawing(&emb.points, labels, &title);
    let stem = c.out.join(format!("tsne_{}", m.method.name()));
    figures::write_both(&d, &stem)?;
    let mut npz = vf_common::npz::NpzOut::new();
    npz.add_vec("codes", codes)?;
    npz.add_vec("embedding", emb.points.iter().flat_map(|p| *p).collect::<Vec<f64>>())?;
    npz.add_vec("labels", labels.to_vec())?;
    npz.add_vec("bhtsne_cost", vec![emb.bhtsne_cost])?;
    npz.add_vec("perplexity", vec![settings.perplexity])?;
    npz.write(&stem.with_extension("npz"))?;
    crate::output::out!(
        "mnist tsne: {n} codes of {} embedded in {:.1} s (bhtsne's cost estimate {:.3}); wrote {}.png/.svg/.npz.",
        m.method.name(),
        secs,
        emb.bhtsne_cost,
        stem.display()
    );
    Ok(secs)
}

fn interpolate(c: &Common, models: &[Model], test: &DigitSet, pairs: &[String], steps: usize) -> Result<(), CliError> {
    if !(2..=32).contains(&steps) {
        return Err(CliError::input(format!("--steps {steps}: must be in 2..=32")));
    }
    let voronoi = models
        .iter()
        .find(|m| m.method == Method::Voronoi)
        .ok_or_else(|| CliError::input("the interpolation needs the voronoi model: include voronoi in --methods"))?;
    let occnet = models
        .iter()
        .filter(|m| matches!(m.method, Method::OccNet { .. }))
        .max_by_key(|m| m.decoder.params.len())
        .ok_or_else(|| CliError::input("the interpolation needs an OccNet model: include one in --methods"))?;
    let first_of = |class: u8| test.labels.iter().position(|&l| l == class);
    let mut list = Vec::new();
    for p in pairs {
        let parse = |s: &str| s.trim().parse::<u8>().ok().filter(|&d| d <= 9);
        let (a, b) = p
            .split_once(':')
            .and_then(|(a, b)| Some((parse(a)?, parse(b)?)))
            .ok_or_else(|| CliError::input(format!("--pairs {p}: a pair is two digits A:B, e.g. 3:5")))?;
        let (ia, ib) = (first_of(a), first_of(b));
        let (Some(ia), Some(ib)) = (ia, ib) else {
            return Err(CliError::input(format!(
                "--pairs {p}: the test set has no digit {}",
                if ia.is_none() { a } else { b }
            )));
        };
        list.push(Interpolation {
            title: format!("{a} to {b} (test digits #{ia} and #{ib})"),
            a: (test.images.image(ia), a),
            b: (test.images.image(ib), b),
            rows: test.images.rows,
            cols: test.images.cols,
        });
    }
    let d = figures::interpolation_drawing(voronoi, occnet, &list, steps);
    let stem = c.out.join("interpolation");
    figures::write_both(&d, &stem)?;
    // Reconstructions of the first 10 test digits, one per class where possible.
    let mut picks: Vec<usize> = (0..10u8).filter_map(first_of).collect();
    picks.sort_unstable();
    let digits: Vec<(&[u8], u8)> = picks.iter().map(|&i| (test.images.image(i), test.labels[i])).collect();
    let refs: Vec<&Model> = models.iter().collect();
    let r = figures::reconstructions_drawing(&refs, &digits, test.images.rows, test.images.cols);
    figures::write_both(&r, &c.out.join("reconstructions"))?;
    crate::output::out!(
        "mnist interpolate: {} pair(s) in {steps} steps, {} beside {}; wrote {}/interpolation.png/.svg and reconstructions.png/.svg.",
        list.len(),
        voronoi.method.label(),
        occnet.method.label(),
        c.out.display()
    );
    Ok(())
}

fn run_all(a: RunArgs) -> Result<(), CliError> {
    let t0 = Instant::now();
    let c = &a.common;
    if !c.methods().contains(&Method::Voronoi) || !c.methods().iter().any(|m| matches!(m, Method::OccNet { .. })) {
        return Err(CliError::input("`mnist run` needs voronoi and at least one OccNet method in --methods"));
    }
    let train = c.data.load(false)?;
    let test = c.data.load(true)?;
    if (test.images.rows, test.images.cols) != (train.images.rows, train.images.cols) {
        return Err(CliError::input(format!(
            "{} has {}×{} images but {} has {}×{}; the two sets must have one image size",
            test.source.display(),
            test.images.rows,
            test.images.cols,
            train.source.display(),
            train.images.rows,
            train.images.cols
        )));
    }
    let (states, train_secs) = train_all(c, &a.train, &train)?;
    let curves: Vec<(String, Vec<mnist::train::CurvePoint>)> =
        states.iter().map(|s| (s.model.method.label(), s.curve.clone())).collect();
    let chart = figures::curves_chart(&curves);
    chart.write_svg(&c.out.join("curves.svg")).map_err(|e| CliError::failure(e.to_string()))?;
    chart.write_png(&c.out.join("curves.png")).map_err(|e| CliError::failure(e.to_string()))?;
    let models: Vec<Model> = states.iter().map(|s| s.model.clone()).collect();
    check_sizes(&models, &test)?;
    let t_eval = Instant::now();
    let n = if c.quick { 1000 } else { usize::MAX };
    let results = eval_all(c, &models, &test, n)?;
    let eval_secs = t_eval.elapsed().as_secs_f64();
    let voronoi = models.iter().find(|m| m.method == Method::Voronoi).expect("checked above");
    let tsne_secs = tsne_one(c, voronoi, &test, None, None)?;
    interpolate(c, &models, &test, &["3:5".into(), "9:6".into()], 8)?;
    let total = t0.elapsed().as_secs_f64();
    let run = serde_json::json!({
        "quick": c.quick,
        "train_data": train.source.display().to_string(),
        "test_data": test.source.display().to_string(),
        "settings": states.first().map(|s| s.settings.clone()),
        "training_seconds_per_method": states.iter().map(|s| (s.model.method.name(), s.seconds)).collect::<std::collections::BTreeMap<_, _>>(),
        "seconds": { "train_this_process": train_secs, "eval": eval_secs, "tsne": tsne_secs, "total": total },
        "threads": rayon::current_num_threads(),
    });
    write_text(&c.out.join("run.json"), &serde_json::to_string_pretty(&run).map_err(anyhow::Error::from)?)?;
    print_table_summary(&results, &c.out);
    crate::output::out!(
        "mnist run ({}): {} methods trained on {} images for {} epochs, evaluated on {} test digits, tSNE and interpolation drawn, in {:.0} s; everything is in {} (run.json has the settings and times).",
        if c.quick { "quick" } else { "full" },
        states.len(),
        states.first().map_or(0, |s| s.settings.train_images),
        states.first().map_or(0, |s| s.settings.epochs),
        results.first().map_or(0, |r| r.images),
        total,
        c.out.display()
    );
    Ok(())
}

fn bench(a: BenchArgs) -> Result<(), CliError> {
    let train = a.data.load(false)?;
    let methods = a.methods.clone().filter(|m| !m.is_empty()).unwrap_or_else(Method::all);
    let mut rows = Vec::new();
    for m in methods {
        let settings =
            TrainSettings { batch: a.batch, points: a.points, train_images: train.len(), ..TrainSettings::full() };
        settings.validate()?;
        let mut state = TrainState::new(m, train.images.rows * train.images.cols, settings);
        let n = train.len() as u32;
        let batch =
            |k: usize| -> Vec<u32> { (0..a.batch as u32).map(|i| (k as u32 * a.batch as u32 + i) % n).collect() };
        for k in 0..2 {
            state.step(&train, &batch(k))?;
        }
        let t = Instant::now();
        for k in 0..a.steps {
            state.step(&train, &batch(k + 2))?;
        }
        let secs = t.elapsed().as_secs_f64();
        let ips = (a.steps * a.batch) as f64 / secs;
        rows.push(serde_json::json!({
            "method": m.name(),
            "batch": a.batch,
            "points": a.points,
            "steps": a.steps,
            "seconds": secs,
            "images_per_second": ips,
            "decoder_params": state.model.decoder.params.len(),
            "encoder_params": state.model.encoder.params.len(),
            "threads": rayon::current_num_threads(),
        }));
        eprintln!(
            "voronoi-fit: {}: {:.0} images/s (forward + backward + Adam, batch {}, {} points)",
            m.name(),
            ips,
            a.batch,
            a.points
        );
    }
    println!("{}", serde_json::to_string_pretty(&rows).map_err(anyhow::Error::from)?);
    Ok(())
}
