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
//! No scheduler crate: a shared counter over the input list and `std::thread::scope` are
//! all one machine needs; fanning out over machines is the Python runner's job, on Ray.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use clap::Parser;
use serde::{Deserialize, Serialize};

use crate::cli_error::CliError;
use crate::cmd_fit;

/// File extensions taken from a folder.
const MESH_EXTENSIONS: [&str; 6] = ["obj", "stl", "ply", "off", "glb", "gltf"];

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

/// One mesh's `voronoi-fit fit` command line, parsed by the fit command's own arguments.
#[derive(Parser)]
#[command(name = "voronoi-fit")]
struct FitLine {
    #[command(flatten)]
    fit: cmd_fit::Args,
}

/// What a finished folder was made from (`DIR/NAME/batch.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct Provenance {
    input: String,
    input_bytes: u64,
    input_fnv1a64: String,
    fit_args: Vec<String>,
    format: String,
    version: String,
}

/// One input and where its results go.
#[derive(Clone, Debug)]
struct Job {
    input: PathBuf,
    name: String,
}

/// How one mesh ended in this run.
#[derive(Clone, Debug)]
enum Outcome {
    /// Fitted now (seconds), or found finished (`reused`).
    Done { seconds: f64, reused: bool, resumed: bool },
    /// Failed: bad input (exit-2 kind) or another failure, with the message.
    Failed { input_fault: bool, error: String, seconds: f64 },
}

pub fn run(args: Args) -> Result<(), CliError> {
    let t_all = Instant::now();
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
    // The fit options are checked once, before any work (a usage error exits 2 here).
    let probe = fit_args_for(Path::new("probe.obj"), Path::new("probe.voronoi.glb"), &args, None);
    if let Err(e) = FitLine::try_parse_from(&probe) {
        return Err(CliError::input(format!("the fit options after `--`: {}", e.render().to_string().trim())));
    }
    let inputs = expand_inputs(&args.inputs)?;
    if inputs.is_empty() {
        return Err(CliError::input(
            "no meshes among the inputs (files, folders of .obj/.stl/.ply/.off/.glb/.gltf, or @LIST files)",
        ));
    }
    let jobs = name_jobs(inputs);
    std::fs::create_dir_all(args.out.join(".work"))
        .map_err(|e| CliError::failure(format!("{}: cannot create the output folder ({e})", args.out.display())))?;
    mesh_io::check_output_location(&args.out.join("summary.csv"))?;

    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let bar =
        if args.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(jobs.len() as u64) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("batch {bar:30} {pos}/{len} meshes, {elapsed} (ETA {eta}) {msg}")
            .map_err(anyhow::Error::from)?,
    );
    let outcomes: Mutex<Vec<Option<Outcome>>> = Mutex::new(vec![None; jobs.len()]);
    let running: Mutex<BTreeMap<usize, String>> = Mutex::new(BTreeMap::new());
    let next = AtomicUsize::new(0);
    let workers = args.jobs.min(jobs.len());
    let threads = rayon::current_num_threads().div_ceil(workers).max(1);
    let stopped = AtomicBool::new(false);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().ok();
                loop {
                    if interrupted.load(Ordering::SeqCst) {
                        return;
                    }
                    let i = next.fetch_add(1, Ordering::SeqCst);
                    let Some(job) = jobs.get(i) else { return };
                    set_running(&running, &bar, i, Some(&job.name));
                    let work = || run_one(job, &args, interrupted.clone());
                    let result = match &pool {
                        Some(p) => p.install(work),
                        None => work(),
                    };
                    set_running(&running, &bar, i, None);
                    match result {
                        Ok(outcome) => {
                            let mut o = outcomes.lock().unwrap_or_else(|e| e.into_inner());
                            o[i] = Some(outcome);
                            // Every finished mesh updates summary.csv; a failure to write it
                            // is reported at the end, when it is written again.
                            let _ = write_summary(&args.out, &jobs, &o);
                        }
                        Err(Stop) => stopped.store(true, Ordering::SeqCst),
                    }
                    bar.inc(1);
                }
            });
        }
    });
    bar.finish_and_clear();
    let outcomes = outcomes.into_inner().unwrap_or_else(|e| e.into_inner());
    write_summary(&args.out, &jobs, &outcomes)?;
    let count = |f: &dyn Fn(&Outcome) -> bool| outcomes.iter().flatten().filter(|o| f(o)).count();
    let fitted = count(&|o| matches!(o, Outcome::Done { reused: false, .. }));
    let reused = count(&|o| matches!(o, Outcome::Done { reused: true, .. }));
    let resumed = count(&|o| matches!(o, Outcome::Done { resumed: true, .. }));
    let failed: Vec<String> = jobs
        .iter()
        .zip(&outcomes)
        .filter_map(|(j, o)| match o {
            Some(Outcome::Failed { error, .. }) => Some(format!("{}: {error}", j.input.display())),
            _ => None,
        })
        .collect();
    let seconds = t_all.elapsed().as_secs_f64();
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
         in fits on {workers} job(s) of {threads} thread(s)). Summary: {}",
        jobs.len(),
        if resumed > 0 { format!(" ({resumed} resumed from a checkpoint)") } else { String::new() },
        failed.len(),
        seconds,
        fit_seconds,
        args.out.join("summary.csv").display()
    );
    if stopped.load(Ordering::SeqCst) || interrupted.load(Ordering::SeqCst) {
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

/// A fit stopped by Ctrl-C (its checkpoint is saved).
struct Stop;

fn set_running(running: &Mutex<BTreeMap<usize, String>>, bar: &indicatif::ProgressBar, i: usize, name: Option<&str>) {
    let mut r = running.lock().unwrap_or_else(|e| e.into_inner());
    match name {
        Some(n) => r.insert(i, n.to_string()),
        None => r.remove(&i),
    };
    bar.set_message(r.values().cloned().collect::<Vec<_>>().join(", "));
}

/// The fit command line for one mesh.
fn fit_args_for(input: &Path, crust: &Path, args: &Args, resume: Option<&Path>) -> Vec<std::ffi::OsString> {
    let mut v: Vec<std::ffi::OsString> =
        vec!["voronoi-fit".into(), input.into(), "-o".into(), crust.into(), "--quiet".into()];
    v.extend(args.fit_args.iter().map(Into::into));
    if let Some(r) = resume {
        v.push("--resume".into());
        v.push(r.into());
    }
    v
}

/// Files, folders and @lists → mesh paths, in the order given (folders sorted), without
/// repeats.
fn expand_inputs(inputs: &[String]) -> Result<Vec<PathBuf>, CliError> {
    let mut out = Vec::new();
    let mut seen = std::collections::HashSet::new();
    let mut push = |p: PathBuf, out: &mut Vec<PathBuf>| {
        let key = std::fs::canonicalize(&p).unwrap_or_else(|_| p.clone());
        if seen.insert(key) {
            out.push(p);
        }
    };
    for s in inputs {
        if let Some(list) = s.strip_prefix('@') {
            let list = Path::new(list);
            let text = std::fs::read_to_string(list)
                .map_err(|e| CliError::input_in(list, format!("cannot read the list ({e})")))?;
            let base = list.parent().unwrap_or(Path::new("."));
            for (n, line) in text.lines().enumerate() {
                let line = line.trim();
                if line.is_empty() || line.starts_with('#') {
                    continue;
                }
                let p = Path::new(line);
                let p = if p.is_absolute() { p.to_path_buf() } else { base.join(p) };
                if !p.is_file() {
                    return Err(CliError::input_in(
                        list,
                        format!("line {}: `{line}` is not a file (paths are relative to the list's folder)", n + 1),
                    ));
                }
                push(p, &mut out);
            }
        } else {
            let p = PathBuf::from(s);
            if p.is_dir() {
                let mut files: Vec<PathBuf> = std::fs::read_dir(&p)
                    .map_err(|e| CliError::input_in(&p, format!("cannot list the folder ({e})")))?
                    .filter_map(|e| e.ok().map(|e| e.path()))
                    .filter(|f| {
                        f.is_file()
                            && f.extension()
                                .and_then(|e| e.to_str())
                                .is_some_and(|e| MESH_EXTENSIONS.iter().any(|m| m.eq_ignore_ascii_case(e)))
                    })
                    .collect();
                files.sort();
                for f in files {
                    push(f, &mut out);
                }
            } else if p.is_file() {
                push(p, &mut out);
            } else {
                return Err(CliError::input_in(&p, "no such file or folder"));
            }
        }
    }
    Ok(out)
}

/// Output folder names: the file's stem, made safe; stems shared by several inputs get a
/// hash of the path, so names are stable across reruns with the same inputs.
fn name_jobs(inputs: Vec<PathBuf>) -> Vec<Job> {
    let stem = |p: &Path| {
        let s = p.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "mesh".into());
        let s: String = s.chars().map(|c| if c.is_alphanumeric() || "-_.".contains(c) { c } else { '_' }).collect();
        if s.is_empty() || s.starts_with('.') {
            format!("mesh{s}")
        } else {
            s
        }
    };
    let mut counts: HashMap<String, usize> = HashMap::new();
    for p in &inputs {
        *counts.entry(stem(p)).or_default() += 1;
    }
    inputs
        .into_iter()
        .map(|p| {
            let s = stem(&p);
            let name = if counts[&s] > 1 {
                let full = std::fs::canonicalize(&p).unwrap_or_else(|_| p.clone());
                format!("{s}-{:08x}", fnv1a64(full.to_string_lossy().as_bytes()) as u32)
            } else {
                s
            };
            Job { input: p, name }
        })
        .collect()
}

fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

fn provenance(job: &Job, args: &Args) -> Result<Provenance, CliError> {
    let bytes = std::fs::read(&job.input).map_err(|e| CliError::input_in(&job.input, format!("cannot read ({e})")))?;
    Ok(Provenance {
        input: std::fs::canonicalize(&job.input).unwrap_or_else(|_| job.input.clone()).display().to_string(),
        input_bytes: bytes.len() as u64,
        input_fnv1a64: format!("{:016x}", fnv1a64(&bytes)),
        fit_args: args.fit_args.clone(),
        format: args.format.clone(),
        version: env!("CARGO_PKG_VERSION").to_string(),
    })
}

fn read_provenance(dir: &Path) -> Option<Provenance> {
    serde_json::from_str(&std::fs::read_to_string(dir.join("batch.json")).ok()?).ok()
}

/// One mesh: skip, resume or fit, then publish the folder. `Err(Stop)` only on Ctrl-C.
fn run_one(job: &Job, args: &Args, interrupted: Arc<AtomicBool>) -> Result<Outcome, Stop> {
    let t = Instant::now();
    let failed = |e: CliError, t: &Instant| Outcome::Failed {
        input_fault: e.exit_code() == 2,
        error: e.to_string().replace('\n', " "),
        seconds: t.elapsed().as_secs_f64(),
    };
    let prov = match provenance(job, args) {
        Ok(p) => p,
        Err(e) => return Ok(failed(e, &t)),
    };
    let done_dir = args.out.join(&job.name);
    let crust_name = format!("{}.voronoi.{}", job.name, args.format);
    if read_provenance(&done_dir).as_ref() == Some(&prov)
        && done_dir.join(format!("{}.voronoi.report.json", job.name)).is_file()
    {
        return Ok(Outcome::Done { seconds: 0.0, reused: true, resumed: false });
    }
    let work = args.out.join(".work").join(&job.name);
    let checkpoint = work.join(format!("{}.voronoi.ckpt.npz", job.name));
    let resume = read_provenance(&work).as_ref() == Some(&prov) && checkpoint.is_file();
    if !resume {
        let _ = std::fs::remove_dir_all(&work);
    }
    let result = (|| -> Result<(), CliError> {
        std::fs::create_dir_all(&work)
            .map_err(|e| CliError::failure(format!("{}: cannot create ({e})", work.display())))?;
        let text = serde_json::to_string_pretty(&prov).map_err(anyhow::Error::from)?;
        mesh_io::atomic_write(&work.join("batch.json"), |w| w.write_all(text.as_bytes()))?;
        let argv = fit_args_for(&job.input, &work.join(&crust_name), args, resume.then_some(checkpoint.as_path()));
        let fit_args = FitLine::try_parse_from(&argv)
            .map_err(|e| CliError::input(format!("the fit options: {}", e.render().to_string().trim())))?
            .fit;
        // A panic is a bug, but one mesh's bug must not end the batch.
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            cmd_fit::fit_to_files(&fit_args, interrupted.clone(), indicatif::ProgressBar::hidden())
        }))
        .map_err(|p| {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            CliError::failure(format!("internal error (panic: {what}); please report it with this mesh"))
        })??;
        publish(&work, &done_dir, &args.out.join(".work"), &job.name)
    })();
    match result {
        Ok(()) => Ok(Outcome::Done { seconds: t.elapsed().as_secs_f64(), reused: false, resumed: resume }),
        Err(CliError::Interrupted(_)) => Err(Stop),
        Err(e) => {
            // Keep a stopped run's checkpoint for the retry; drop anything else half made.
            if !checkpoint.is_file() {
                let _ = std::fs::remove_dir_all(&work);
            }
            Ok(failed(e, &t))
        }
    }
}

/// Moves the finished work folder into place; an older result is moved aside first and
/// removed after.
fn publish(work: &Path, done: &Path, scratch: &Path, name: &str) -> Result<(), CliError> {
    let fail =
        |e: std::io::Error| CliError::failure(format!("{}: cannot move the result into place ({e})", done.display()));
    let old = scratch.join(format!("{name}.replaced"));
    if done.exists() {
        let _ = std::fs::remove_dir_all(&old);
        std::fs::rename(done, &old).map_err(fail)?;
    }
    std::fs::rename(work, done).map_err(fail)?;
    let _ = std::fs::remove_dir_all(&old);
    Ok(())
}

/// summary.csv: one row per input in input order; figures from each finished folder's
/// report.
fn write_summary(out: &Path, jobs: &[Job], outcomes: &[Option<Outcome>]) -> Result<(), CliError> {
    let mut text = String::from(
        "name,input,status,error,seconds,hausdorff_hi,hausdorff_of_diagonal,chamfer_l1,fscore,normal_consistency,iou,\
         misclassification,sites,triangles,components,genus,folder\n",
    );
    let csv =
        |s: &str| if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() };
    for (job, outcome) in jobs.iter().zip(outcomes) {
        let dir = out.join(&job.name);
        let (status, error, seconds) = match outcome {
            None => ("not run", String::new(), String::new()),
            Some(Outcome::Done { reused: true, .. }) => ("done earlier", String::new(), String::new()),
            Some(Outcome::Done { seconds, resumed, .. }) => {
                (if *resumed { "fitted (resumed)" } else { "fitted" }, String::new(), format!("{seconds:.1}"))
            }
            Some(Outcome::Failed { input_fault, error, seconds }) => {
                (if *input_fault { "bad input" } else { "failed" }, error.clone(), format!("{seconds:.1}"))
            }
        };
        let ok = matches!(outcome, Some(Outcome::Done { .. }));
        let report: Option<serde_json::Value> = ok
            .then(|| std::fs::read_to_string(dir.join(format!("{}.voronoi.report.json", job.name))).ok())
            .flatten()
            .and_then(|t| serde_json::from_str(&t).ok());
        let get = |path: &[&str]| -> String {
            let mut v = report.as_ref();
            for k in path {
                v = v.and_then(|x| x.get(*k));
            }
            match v {
                Some(serde_json::Value::Number(n)) => n.to_string(),
                Some(serde_json::Value::Bool(b)) => b.to_string(),
                Some(serde_json::Value::String(s)) => s.clone(),
                _ => String::new(),
            }
        };
        let seconds = if seconds.is_empty() && ok { get(&["total_seconds"]) } else { seconds };
        let h_of_d = {
            let (h, d) = (
                get(&["metrics", "hausdorff", "hi"]).parse::<f64>(),
                get(&["metrics", "hausdorff", "diagonal"]).parse::<f64>(),
            );
            match (h, d) {
                (Ok(h), Ok(d)) if d > 0.0 => format!("{:.6e}", h / d),
                _ => String::new(),
            }
        };
        let row = [
            csv(&job.name),
            csv(&job.input.display().to_string()),
            status.to_string(),
            csv(&error),
            seconds,
            get(&["metrics", "hausdorff", "hi"]),
            h_of_d,
            get(&["metrics", "surface", "chamfer_l1"]),
            get(&["metrics", "surface", "fscore"]),
            get(&["metrics", "surface", "normal_consistency"]),
            get(&["metrics", "iou", "iou"]),
            get(&["quality", "misclassification"]),
            get(&["crust", "num_sites"]),
            get(&["crust", "num_triangles"]),
            get(&["crust", "num_components"]),
            get(&["crust", "genus"]),
            if ok { csv(&dir.display().to_string()) } else { String::new() },
        ];
        text.push_str(&row.join(","));
        text.push('\n');
    }
    mesh_io::atomic_write(&out.join("summary.csv"), |w| w.write_all(text.as_bytes()))?;
    Ok(())
}
