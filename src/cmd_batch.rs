//! `voronoi-fit batch INPUTS… --out DIR [--jobs N] [-- FIT OPTIONS]`: the main job on many
//! meshes, one output folder per mesh and a `summary.csv`, resumable.
//!
//! - INPUTS are mesh files, folders (their mesh files, not recursive) or `@LIST` files
//!   (one path per line, `#` comments; relative paths are taken from the list's folder).
//! - Each mesh is fitted in `DIR/.work/NAME/` with checkpoints; only when its report is
//!   written is that folder renamed to `DIR/NAME/` (one `rename`), so `DIR/NAME/` is
//!   always a complete result and never half a one.
//! - `DIR/NAME/batch.json` records what the result was made from (the input's path, size
//!   and content hash, the fit options). A rerun skips a mesh whose finished folder matches,
//!   resumes one that was stopped or crashed from its checkpoint, and redoes one whose
//!   input or options changed (replacing the old folder only when the new one is done).
//! - A mesh that fails (unreadable, no volume, …) is recorded with its error in
//!   `summary.csv` and the batch goes on; a rerun tries it again. A panic in one fit is
//!   caught and recorded the same way.
//! - `summary.csv` (rewritten atomically after every mesh) has one row per input: status,
//!   error, seconds and the report's figures. The exit code is 0 when every mesh has a
//!   result, 1 when any failed, 130 on Ctrl-C (after the running fits' checkpoints).
//! - `--jobs N` fits N meshes at once, each on its own rayon pool of ⌈threads / N⌉
//!   threads; results do not depend on N (fits are bit-identical for any thread count).
//!
//! The protocol is [`jobs::batch`]; this module turns the arguments into its typed options,
//! draws the bar and prints the tally.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use clap::Parser;
use jobs::batch::{BatchOptions, BatchProgress, Job, Outcome};

use crate::cli_error::CliError;
use crate::cmd_fit;

/// Fit options the batch sets itself (per mesh), refused after `--`.
const RESERVED: [&str; 8] =
    ["-o", "--output", "--resume", "--json", "--html", "--stop-after", "--quiet", "--keep-checkpoint"];

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// Meshes: files, folders (their .obj/.stl/.ply/.off/.glb/.gltf files) or @LIST files
    /// with one path per line.
    #[arg(required = true)]
    pub inputs: Vec<String>,
    /// Output folder: one folder per mesh and summary.csv.
    #[arg(long)]
    pub out: PathBuf,
    /// Meshes fitted at once (each on its share of the threads).
    #[arg(long, default_value_t = 1)]
    pub jobs: usize,
    /// Crust format of every mesh: glb, gltf, obj or ply.
    #[arg(long, default_value = "glb", value_parser = ["glb", "gltf", "obj", "ply"])]
    pub format: String,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Options for every fit, after `--` (e.g. `-- --sites 4096 --steps 300`): any option of
    /// `voronoi-fit fit` except the output ones the batch sets itself.
    #[arg(last = true)]
    pub fit_args: Vec<String>,
}

/// The fit options after `--` as a `voronoi-fit fit` command line, parsed once by the fit
/// command's own arguments.
#[derive(Parser)]
#[command(name = "voronoi-fit")]
struct FitLine {
    #[command(flatten)]
    fit: cmd_fit::Args,
}

/// The bar: meshes done, and the names of those running.
struct Bar {
    bar: indicatif::ProgressBar,
    running: Mutex<BTreeMap<usize, String>>,
}

impl Bar {
    fn set_running(&self, i: usize, name: Option<&str>) {
        let mut r = self.running.lock().unwrap_or_else(|e| e.into_inner());
        match name {
            Some(n) => r.insert(i, n.to_string()),
            None => r.remove(&i),
        };
        self.bar.set_message(r.values().cloned().collect::<Vec<_>>().join(", "));
    }
}

impl BatchProgress for Bar {
    fn started(&self, index: usize, job: &Job) {
        self.set_running(index, Some(&job.name));
    }

    fn finished(&self, index: usize, _job: &Job, _outcome: Option<&Outcome>) {
        self.set_running(index, None);
        self.bar.inc(1);
    }
}

/// The typed options of every fit, from the arguments after `--` (parsed once, by the fit
/// command's own arguments; a usage error exits 2).
fn fit_template(args: &Args) -> Result<jobs::FitJob, CliError> {
    let mut argv: Vec<std::ffi::OsString> =
        vec!["voronoi-fit".into(), "probe.obj".into(), "-o".into(), "probe.voronoi.glb".into(), "--quiet".into()];
    argv.extend(args.fit_args.iter().map(Into::into));
    let line = FitLine::try_parse_from(&argv)
        .map_err(|e| CliError::input(format!("the fit options after `--`: {}", e.render().to_string().trim())))?;
    Ok(line.fit.to_job())
}

pub fn run(args: Args) -> Result<(), CliError> {
    if args.jobs == 0 {
        return Err(CliError::input("--jobs must be at least 1"));
    }
    if let Some(bad) =
        args.fit_args.iter().find(|a| RESERVED.iter().any(|r| a.as_str() == *r || a.starts_with(&format!("{r}="))))
    {
        return Err(CliError::input(format!(
            "`{bad}` cannot be given to a batch: it sets each mesh's outputs, checkpoints and resumption itself"
        )));
    }
    // The fit options are checked once, before any work.
    let fit = fit_template(&args)?;
    let plan = jobs::batch::plan(&args.inputs).map_err(cmd_fit::cli_error)?;
    let options = BatchOptions {
        out: args.out.clone(),
        jobs: args.jobs,
        format: args.format.clone(),
        fit,
        fit_args: args.fit_args.clone(),
        version: env!("CARGO_PKG_VERSION").to_string(),
    };
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let bar =
        if args.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(plan.len() as u64) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("batch {bar:30} {pos}/{len} meshes, {elapsed} (ETA {eta}) {msg}")
            .map_err(anyhow::Error::from)?,
    );
    let progress = Bar { bar, running: Mutex::new(BTreeMap::new()) };
    let run = jobs::batch::run_batch(plan, &options, &interrupted, &progress);
    progress.bar.finish_and_clear();
    let run = run.map_err(cmd_fit::cli_error)?;
    let (jobs, outcomes) = (&run.jobs, &run.outcomes);
    let count = |f: &dyn Fn(&Outcome) -> bool| outcomes.iter().flatten().filter(|o| f(o)).count();
    let fitted = count(&|o| matches!(o, Outcome::Done { reused: false, .. }));
    let reused = count(&|o| matches!(o, Outcome::Done { reused: true, .. }));
    let resumed = count(&|o| matches!(o, Outcome::Done { resumed: true, .. }));
    let failed: Vec<String> = jobs
        .iter()
        .zip(outcomes)
        .filter_map(|(j, o)| match o {
            Some(Outcome::Failed { error, .. }) => Some(format!("{}: {error}", j.input.display())),
            _ => None,
        })
        .collect();
    let seconds = run.seconds;
    let fit_seconds: f64 = outcomes
        .iter()
        .flatten()
        .map(|o| match o {
            Outcome::Done { seconds, reused: false, .. } | Outcome::Failed { seconds, .. } => *seconds,
            _ => 0.0,
        })
        .sum();
    let rate = if fitted > 0 && seconds > 0.0 {
        format!("{:.2} meshes fitted per minute", 60.0 * fitted as f64 / seconds)
    } else {
        "nothing fitted".to_string()
    };
    crate::output::out!(
        "{} meshes: {fitted} fitted now{}, {reused} already done (skipped), {} failed. {:.1} s in all ({rate}; {:.1} s \
         in fits on {} job(s) of {} thread(s)). Summary: {}",
        jobs.len(),
        if resumed > 0 { format!(" ({resumed} resumed from a checkpoint)") } else { String::new() },
        failed.len(),
        seconds,
        fit_seconds,
        run.workers,
        run.threads,
        args.out.join("summary.csv").display()
    );
    if run.stopped {
        return Err(CliError::Interrupted(format!(
            "stopped; the running fits saved checkpoints in {}. Run the same command again to continue.",
            args.out.join(".work").display()
        )));
    }
    if !failed.is_empty() {
        return Err(CliError::failure(format!(
            "{} mesh(es) failed (recorded in summary.csv):\n  {}",
            failed.len(),
            failed.join("\n  ")
        )));
    }
    Ok(())
}
