//! The batch protocol: the main job on many meshes, one output folder per mesh and a
//! `summary.csv`, resumable.
//!
//! - Inputs are mesh files, folders (their mesh files, not recursive) or `@LIST` files
//!   (one path per line, `#` comments; relative paths are taken from the list's folder):
//!   [`plan`] expands them and names each mesh's folder.
//! - Each mesh is fitted in `DIR/.work/NAME/` with checkpoints; only when its report is
//!   written is that folder renamed to `DIR/NAME/` (one `rename`, [`publish`]), so
//!   `DIR/NAME/` is always a complete result and never half a one.
//! - `DIR/NAME/batch.json` ([`Provenance`]) records what the result was made from (the
//!   input's path, size and content hash, the fit options). A rerun skips a mesh whose
//!   finished folder matches, resumes one that was stopped or crashed from its checkpoint,
//!   and redoes one whose input or options changed (replacing the old folder only when
//!   the new one is done): [`run_one`].
//! - A mesh that fails is recorded with its error and the batch goes on; a panic in one
//!   fit is caught and recorded the same way.
//! - `summary.csv` ([`write_summary`], rewritten atomically after every mesh) has one row
//!   per input: status, error, seconds, the report's figures, the folder and the
//!   occupancy samples (`NAME.voronoi.points.npz`, when the fits write them).
//! - [`run_batch`] fits `jobs` meshes at once, each on its own rayon pool of
//!   ⌈threads / jobs⌉ threads; results do not depend on it.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::{fit_to_files, message_with_causes, Error, FitJob};

/// File extensions taken from a folder.
pub const MESH_EXTENSIONS: [&str; 6] = ["obj", "stl", "ply", "off", "glb", "gltf"];

/// A batch: where the results go, how many fits at once, and each fit's options.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BatchOptions {
    /// Output folder: one folder per mesh, `summary.csv` and the work area `.work/`.
    pub out: PathBuf,
    /// Meshes fitted at once (at least 1).
    pub jobs: usize,
    /// Crust format of every mesh: `glb`, `gltf`, `obj` or `ply`.
    pub format: String,
    /// The options of every fit; its `mesh`, `output` and `resume` are set per mesh.
    pub fit: FitJob,
    /// The fit options as the user wrote them (the CLI's arguments after `--`), recorded
    /// in `batch.json`: a result made with other options is redone.
    pub fit_args: Vec<String>,
    /// The program's version, recorded in `batch.json`: a result made by another version
    /// is redone.
    pub version: String,
}

/// What a finished folder was made from (`DIR/NAME/batch.json`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// The input's canonical path.
    pub input: String,
    /// Its size.
    pub input_bytes: u64,
    /// FNV-1a (64 bits, hex) of its bytes.
    pub input_fnv1a64: String,
    /// [`BatchOptions::fit_args`].
    pub fit_args: Vec<String>,
    /// [`BatchOptions::format`].
    pub format: String,
    /// [`BatchOptions::version`].
    pub version: String,
}

/// One input and the name of its folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Job {
    /// The mesh, as given (or as the list or folder named it).
    pub input: PathBuf,
    /// Its folder's name under the output folder (also the stem of its files).
    pub name: String,
}

/// How one mesh ended in this run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Outcome {
    /// Fitted now (`seconds`), or found finished (`reused`); `resumed` from a checkpoint.
    Done {
        /// Seconds of this run on it (0 when reused).
        seconds: f64,
        /// Found finished with the same provenance: skipped.
        reused: bool,
        /// Continued from a stopped run's checkpoint.
        resumed: bool,
    },
    /// Failed: bad input or another failure, with the message.
    Failed {
        /// The input (mesh or options) is at fault.
        input_fault: bool,
        /// The error, on one line.
        error: String,
        /// Seconds spent before it failed.
        seconds: f64,
    },
}

/// A fit stopped on request (its checkpoint is saved in the work folder).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stopped;

/// Reports a batch's progress (the CLI's bar). Called from the worker threads.
pub trait BatchProgress: Sync {
    /// Mesh `index` of the plan starts.
    fn started(&self, _index: usize, _job: &Job) {}
    /// Mesh `index` ended: its outcome, or `None` when it was stopped.
    fn finished(&self, _index: usize, _job: &Job, _outcome: Option<&Outcome>) {}
}

/// No progress reports.
pub struct NoBatchProgress;

impl BatchProgress for NoBatchProgress {}

/// What [`run_batch`] did.
#[derive(Clone, Debug)]
pub struct BatchRun {
    /// The plan, in input order.
    pub jobs: Vec<Job>,
    /// Each job's outcome (`None`: not run, or stopped).
    pub outcomes: Vec<Option<Outcome>>,
    /// Stopped on request: the running fits saved checkpoints in `.work/`.
    pub stopped: bool,
    /// Fits run at once.
    pub workers: usize,
    /// Threads of each fit.
    pub threads: usize,
    /// Wall-clock seconds.
    pub seconds: f64,
}

/// Files, folders and @lists → the jobs, in the order given (folders sorted), without
/// repeats, each with its folder name ([`name_jobs`]). No meshes at all is an input error.
pub fn plan(inputs: &[String]) -> Result<Vec<Job>, Error> {
    let inputs = expand_inputs(inputs)?;
    if inputs.is_empty() {
        return Err(Error::Input(
            "no meshes among the inputs (files, folders of .obj/.stl/.ply/.off/.glb/.gltf, or @LIST files)".into(),
        ));
    }
    Ok(name_jobs(inputs))
}

/// Files, folders and @lists → mesh paths, in the order given (folders sorted), without
/// repeats.
pub fn expand_inputs(inputs: &[String]) -> Result<Vec<PathBuf>, Error> {
    let mut out = Vec::new();
    let mut seen = HashSet::new();
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
                .map_err(|e| Error::input_in(list, format!("cannot read the list ({e})")))?;
            let base = list.parent().unwrap_or(Path::new("."));
            for (n, line) in text.lines().enumerate() {
                let line = line.trim();
                if line.is_empty() || line.starts_with('#') {
                    continue;
                }
                let p = Path::new(line);
                let p = if p.is_absolute() { p.to_path_buf() } else { base.join(p) };
                if !p.is_file() {
                    return Err(Error::input_in(
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
                    .map_err(|e| Error::input_in(&p, format!("cannot list the folder ({e})")))?
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
                return Err(Error::input_in(&p, "no such file or folder"));
            }
        }
    }
    Ok(out)
}

/// Output folder names: the file's stem, made safe; stems shared by several inputs get the
/// low 32 bits of FNV-1a of the canonical path, so names are stable across reruns with the
/// same inputs.
pub fn name_jobs(inputs: Vec<PathBuf>) -> Vec<Job> {
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

/// FNV-1a, 64 bits.
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

/// What `job`'s result is made from with these options (reads the input to hash it).
pub fn provenance(job: &Job, options: &BatchOptions) -> Result<Provenance, Error> {
    let bytes = std::fs::read(&job.input).map_err(|e| Error::input_in(&job.input, format!("cannot read ({e})")))?;
    Ok(Provenance {
        input: std::fs::canonicalize(&job.input).unwrap_or_else(|_| job.input.clone()).display().to_string(),
        input_bytes: bytes.len() as u64,
        input_fnv1a64: format!("{:016x}", fnv1a64(&bytes)),
        fit_args: options.fit_args.clone(),
        format: options.format.clone(),
        version: options.version.clone(),
    })
}

/// The provenance recorded in `dir/batch.json`, if it is there and readable.
pub fn read_provenance(dir: &Path) -> Option<Provenance> {
    serde_json::from_str(&std::fs::read_to_string(dir.join("batch.json")).ok()?).ok()
}

/// Whether `dir` holds the finished result of `name` made from `prov` (its `batch.json`
/// matches and its report is there): a rerun skips it.
pub fn is_finished(dir: &Path, name: &str, prov: &Provenance) -> bool {
    read_provenance(dir).as_ref() == Some(prov) && dir.join(format!("{name}.voronoi.report.json")).is_file()
}

/// Stops training when the flag is set.
struct Flag<'a>(&'a AtomicBool);

impl fit::Progress for Flag<'_> {
    fn should_stop(&mut self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// Fits `job` into the work folder `work` (created if needed): `batch.json` first, then
/// the main job's files named `NAME.voronoi.FORMAT` and so on, continuing from the
/// folder's checkpoint when `resume`. A panic in the fit is caught and returned as an
/// error; [`Error::Interrupted`] when `interrupted` stopped it (the checkpoint stays).
pub fn fit_into(
    job: &Job,
    options: &BatchOptions,
    prov: &Provenance,
    work: &Path,
    resume: bool,
    interrupted: &AtomicBool,
) -> Result<(), Error> {
    std::fs::create_dir_all(work).map_err(|e| Error::Failure(format!("{}: cannot create ({e})", work.display())))?;
    let text = serde_json::to_string_pretty(prov).map_err(|e| Error::Failure(format!("batch.json: {e}")))?;
    mesh_io::atomic_write(&work.join("batch.json"), |w| w.write_all(text.as_bytes()))?;
    let fit_job = FitJob {
        mesh: job.input.clone(),
        output: Some(work.join(format!("{}.voronoi.{}", job.name, options.format))),
        resume: resume.then(|| checkpoint_in(work, &job.name)),
        ..options.fit.clone()
    };
    // A panic is a bug, but one mesh's bug must not end the batch.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| fit_to_files(&fit_job, &mut Flag(interrupted))))
        .map_err(|p| {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown".into());
            Error::Failure(format!("internal error (panic: {what}); please report it with this mesh"))
        })??;
    Ok(())
}

/// The checkpoint of `name`'s fit in the work folder `work`.
pub fn checkpoint_in(work: &Path, name: &str) -> PathBuf {
    work.join(format!("{name}.voronoi.ckpt.npz"))
}

/// One mesh: skip, resume or fit in `OUT/.work/NAME/`, then publish the folder as
/// `OUT/NAME/`. A failure is an [`Outcome::Failed`]; `Err(Stopped)` only when
/// `interrupted` stopped the fit (its checkpoint stays for the next run).
pub fn run_one(job: &Job, options: &BatchOptions, interrupted: &AtomicBool) -> Result<Outcome, Stopped> {
    let t = Instant::now();
    let failed = |e: Error, t: &Instant| Outcome::Failed {
        input_fault: e.is_input_fault(),
        error: message_with_causes(&e).replace('\n', " "),
        seconds: t.elapsed().as_secs_f64(),
    };
    let prov = match provenance(job, options) {
        Ok(p) => p,
        Err(e) => return Ok(failed(e, &t)),
    };
    let done_dir = options.out.join(&job.name);
    if is_finished(&done_dir, &job.name, &prov) {
        return Ok(Outcome::Done { seconds: 0.0, reused: true, resumed: false });
    }
    let scratch = options.out.join(".work");
    let work = scratch.join(&job.name);
    let checkpoint = checkpoint_in(&work, &job.name);
    let resume = read_provenance(&work).as_ref() == Some(&prov) && checkpoint.is_file();
    if !resume {
        let _ = std::fs::remove_dir_all(&work);
    }
    let result = fit_into(job, options, &prov, &work, resume, interrupted)
        .and_then(|()| publish(&work, &done_dir, &scratch.join(format!("{}.replaced", job.name)), &prov).map(|_| ()));
    match result {
        Ok(()) => Ok(Outcome::Done { seconds: t.elapsed().as_secs_f64(), reused: false, resumed: resume }),
        Err(Error::Interrupted { .. }) => Err(Stopped),
        Err(e) => {
            // Keep a stopped run's checkpoint for the retry; drop anything else half made.
            if !checkpoint.is_file() {
                let _ = std::fs::remove_dir_all(&work);
            }
            Ok(failed(e, &t))
        }
    }
}

/// How [`publish`] ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Published {
    /// The work folder is now the result.
    Moved,
    /// Another attempt had already published the same result (same provenance): the work
    /// folder was removed and the result left as it was.
    AlreadyThere,
}

/// Publishes the finished work folder `work` as `done` by one rename. When `done` is in
/// the way: a finished result of the same provenance `prov` (another attempt of the same
/// mesh published first) stays and `work` is removed; anything else is moved to `aside`
/// first and removed after.
pub fn publish(work: &Path, done: &Path, aside: &Path, prov: &Provenance) -> Result<Published, Error> {
    let fail =
        |e: std::io::Error| Error::Failure(format!("{}: cannot move the result into place ({e})", done.display()));
    if std::fs::rename(work, done).is_ok() {
        return Ok(Published::Moved);
    }
    let name = done.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_default();
    if is_finished(done, &name, prov) {
        let _ = std::fs::remove_dir_all(work);
        return Ok(Published::AlreadyThere);
    }
    if done.exists() {
        let _ = std::fs::remove_dir_all(aside);
        std::fs::rename(done, aside).map_err(fail)?;
    }
    std::fs::rename(work, done).map_err(fail)?;
    let _ = std::fs::remove_dir_all(aside);
    Ok(Published::Moved)
}

/// Runs the plan: creates the output folder, fits `options.jobs` meshes at once (each on
/// its share of the rayon threads), rewrites `summary.csv` after every mesh and once at
/// the end. Stops starting meshes when `interrupted` is set (the running fits stop with
/// their checkpoints). `Err` only when the output folder or the final summary cannot be
/// written; failed meshes are in the outcomes.
pub fn run_batch(
    jobs: Vec<Job>,
    options: &BatchOptions,
    interrupted: &AtomicBool,
    progress: &dyn BatchProgress,
) -> Result<BatchRun, Error> {
    let t_all = Instant::now();
    if options.jobs == 0 {
        return Err(Error::Input("a batch needs at least one job at a time".into()));
    }
    if let Some(spec) = &options.fit.occupancy {
        spec.validate()?;
    }
    std::fs::create_dir_all(options.out.join(".work"))
        .map_err(|e| Error::Failure(format!("{}: cannot create the output folder ({e})", options.out.display())))?;
    mesh_io::check_output_location(&options.out.join("summary.csv"))?;
    let outcomes: Mutex<Vec<Option<Outcome>>> = Mutex::new(vec![None; jobs.len()]);
    let next = AtomicUsize::new(0);
    let workers = options.jobs.min(jobs.len()).max(1);
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
                    progress.started(i, job);
                    let work = || run_one(job, options, interrupted);
                    let result = match &pool {
                        Some(p) => p.install(work),
                        None => work(),
                    };
                    match result {
                        Ok(outcome) => {
                            let mut o = outcomes.lock().unwrap_or_else(|e| e.into_inner());
                            o[i] = Some(outcome);
                            // Every finished mesh updates summary.csv; a failure to write it
                            // is reported at the end, when it is written again.
                            let _ = write_summary(&options.out, &jobs, &o);
                            progress.finished(i, job, o[i].as_ref());
                        }
                        Err(Stopped) => {
                            stopped.store(true, Ordering::SeqCst);
                            progress.finished(i, job, None);
                        }
                    }
                }
            });
        }
    });
    let outcomes = outcomes.into_inner().unwrap_or_else(|e| e.into_inner());
    write_summary(&options.out, &jobs, &outcomes)?;
    Ok(BatchRun {
        jobs,
        outcomes,
        stopped: stopped.load(Ordering::SeqCst) || interrupted.load(Ordering::SeqCst),
        workers,
        threads,
        seconds: t_all.elapsed().as_secs_f64(),
    })
}

/// The header of `summary.csv`.
pub const SUMMARY_HEADER: &str =
    "name,input,status,error,seconds,hausdorff_hi,hausdorff_of_diagonal,chamfer_l1,fscore,\
normal_consistency,iou,misclassification,sites,triangles,components,genus,folder,occupancy,\
solid,solid_chosen_by,band_half_thickness_of_diagonal,holes_closed_flat,cap_area_share,input_genus,\
handles_closed,handles_added";

/// One row of `summary.csv` before the report's figures are added.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// The mesh and its folder name.
    pub job: Job,
    /// `fitted`, `done earlier`, `bad input`, `failed`, `not run`, …
    pub status: String,
    /// The error, if any.
    pub error: String,
    /// Seconds spent on it in this run (empty: the report's `total_seconds` for a
    /// finished result).
    pub seconds: String,
    /// Whether `OUT/NAME/` holds its result (its report's figures are filled in).
    pub finished: bool,
    /// Values of the runner's extra columns, in order.
    pub extra: Vec<String>,
}

impl SummaryRow {
    /// The row of `job` with this outcome.
    pub fn of(job: &Job, outcome: Option<&Outcome>) -> Self {
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
        SummaryRow {
            job: job.clone(),
            status: status.into(),
            error,
            seconds,
            finished: matches!(outcome, Some(Outcome::Done { .. })),
            extra: Vec::new(),
        }
    }
}

/// `summary.csv` in `out`, atomically: one row per job in plan order; figures from each
/// finished folder's report.
pub fn write_summary(out: &Path, jobs: &[Job], outcomes: &[Option<Outcome>]) -> Result<(), Error> {
    let rows: Vec<SummaryRow> = jobs.iter().zip(outcomes).map(|(j, o)| SummaryRow::of(j, o.as_ref())).collect();
    write_summary_rows(out, &rows, &[])
}

/// `summary.csv` in `out`, atomically, from rows: [`SUMMARY_HEADER`]'s columns (figures
/// from each finished folder's report), then `extra_columns` (a runner's own, e.g. the
/// Ray runner's worker and node).
pub fn write_summary_rows(out: &Path, rows: &[SummaryRow], extra_columns: &[String]) -> Result<(), Error> {
    let csv =
        |s: &str| if s.contains([',', '"', '\n']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s.to_string() };
    let mut text = String::from(SUMMARY_HEADER);
    for c in extra_columns {
        text.push(',');
        text.push_str(&csv(c));
    }
    text.push('\n');
    for r in rows {
        let (job, ok) = (&r.job, r.finished);
        let dir = out.join(&job.name);
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
        let seconds = if r.seconds.is_empty() && ok { get(&["total_seconds"]) } else { r.seconds.clone() };
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
        let mut row = vec![
            csv(&job.name),
            csv(&job.input.display().to_string()),
            csv(&r.status),
            csv(&r.error),
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
            // The occupancy samples in the finished folder (the report names the file).
            match Path::new(&get(&["outputs", "occupancy"])).file_name() {
                Some(f) if ok => csv(&dir.join(f).display().to_string()),
                _ => String::new(),
            },
            // Which solid was fitted and what it approximated: the rule and why, the band
            // a sheet was thickened into (the thin shell's, or the flood solid's sheets'),
            // the planar holes closed flat, and the caps' share of the area on an open mesh.
            get(&["solid", "rule"]),
            csv(&get(&["solid", "chosen_by"])),
            match get(&["solid", "half_thickness_of_diagonal"]) {
                h if !h.is_empty() => h,
                _ if get(&["solid", "flood", "sheet_share"]).parse::<f64>().is_ok_and(|s| s > 0.0) => {
                    get(&["solid", "flood", "sheet_half_thickness_of_diagonal"])
                }
                _ => String::new(),
            },
            get(&["solid", "holes_filled", "loops_filled"]),
            get(&["solid", "cap_area_share"]),
            // The crust's handles against the input's, where the report could compare them
            // (a clean closed input fitted as its winding solid).
            get(&["input", "genus"]),
            get(&["topology", "handles_closed"]),
            get(&["topology", "handles_added"]),
        ];
        row.extend((0..extra_columns.len()).map(|k| csv(r.extra.get(k).map_or("", String::as_str))));
        text.push_str(&row.join(","));
        text.push('\n');
    }
    mesh_io::atomic_write(&out.join("summary.csv"), |w| w.write_all(text.as_bytes()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_safe_and_shared_stems_get_a_path_hash() {
        let jobs = name_jobs(vec!["a/x y.obj".into(), "b/x y.obj".into(), "c/.z.stl".into()]);
        assert!(jobs[0].name.starts_with("x_y-") && jobs[0].name.len() == "x_y-".len() + 8, "{jobs:?}");
        assert_ne!(jobs[0].name, jobs[1].name);
        assert_eq!(jobs[2].name, "mesh.z");
        assert_eq!(fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
    }

    #[test]
    fn inputs_expand_in_order_without_repeats() {
        let dir = tempfile::tempdir().unwrap();
        for f in ["b.obj", "a.OBJ", "c.txt"] {
            std::fs::write(dir.path().join(f), "").unwrap();
        }
        let list = dir.path().join("list.txt");
        std::fs::write(&list, "# meshes\nb.obj\n\na.OBJ\n").unwrap();
        let d = dir.path().display().to_string();
        let got = expand_inputs(&[format!("@{}", list.display()), d.clone()]).unwrap();
        assert_eq!(got, vec![dir.path().join("b.obj"), dir.path().join("a.OBJ")]);
        assert!(plan(&[format!("{d}/none.obj")]).unwrap_err().is_input_fault());
        std::fs::write(&list, "missing.obj\n").unwrap();
        let e = plan(&[format!("@{}", list.display())]).unwrap_err();
        assert!(e.to_string().contains("line 1: `missing.obj` is not a file"), "{e}");
    }

    #[test]
    fn summary_rows_follow_the_plan() {
        let dir = tempfile::tempdir().unwrap();
        let jobs = name_jobs(vec!["m/a.obj".into(), "m/b,c.obj".into()]);
        let outcomes =
            vec![Some(Outcome::Failed { input_fault: true, error: "m/a.obj: no volume".into(), seconds: 0.5 }), None];
        write_summary(dir.path(), &jobs, &outcomes).unwrap();
        let text = std::fs::read_to_string(dir.path().join("summary.csv")).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], SUMMARY_HEADER);
        assert_eq!(lines[1], format!("a,m/a.obj,bad input,m/a.obj: no volume,0.5{}", ",".repeat(21)));
        assert_eq!(lines[2], format!("b_c,\"m/b,c.obj\",not run{}", ",".repeat(23)));
        // A runner's own columns go last.
        let mut row = SummaryRow::of(&jobs[1], None);
        row.extra = vec!["12".into()];
        write_summary_rows(dir.path(), &[row], &["attempt_pid".into(), "node".into()]).unwrap();
        let text = std::fs::read_to_string(dir.path().join("summary.csv")).unwrap();
        assert_eq!(text.lines().next(), Some(format!("{SUMMARY_HEADER},attempt_pid,node").as_str()));
        assert!(text.lines().nth(1).unwrap().ends_with(",12,"), "{text}");
    }

    /// Publishing: a free place takes the work folder; the same finished result stays (the
    /// work folder goes); another result is replaced, and nothing is left aside.
    #[test]
    fn publish_moves_keeps_or_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let input = dir.path().join("m.obj");
        std::fs::write(&input, "v 0 0 0\n").unwrap();
        let job = Job { input, name: "m".into() };
        let options = BatchOptions {
            out: dir.path().join("out"),
            jobs: 1,
            format: "glb".into(),
            fit: FitJob::default(),
            fit_args: vec!["--sites".into(), "8".into()],
            version: "test".into(),
        };
        let prov = provenance(&job, &options).unwrap();
        assert_eq!(prov.input_bytes, 8);
        let (done, aside) = (options.out.join("m"), options.out.join(".work/m.replaced"));
        let attempt = |tag: &str, p: &Provenance| {
            let work = options.out.join(".work").join(format!("m.{tag}"));
            std::fs::create_dir_all(&work).unwrap();
            std::fs::write(work.join("batch.json"), serde_json::to_string(p).unwrap()).unwrap();
            std::fs::write(work.join("m.voronoi.report.json"), tag).unwrap();
            work
        };
        let first = attempt("a", &prov);
        assert_eq!(publish(&first, &done, &aside, &prov).unwrap(), Published::Moved);
        assert!(is_finished(&done, "m", &prov) && !first.exists());
        let second = attempt("b", &prov);
        assert_eq!(publish(&second, &done, &aside, &prov).unwrap(), Published::AlreadyThere);
        assert_eq!(std::fs::read_to_string(done.join("m.voronoi.report.json")).unwrap(), "a");
        assert!(!second.exists());
        let other = Provenance { fit_args: vec![], ..prov.clone() };
        let third = attempt("c", &other);
        assert_eq!(publish(&third, &done, &aside, &other).unwrap(), Published::Moved);
        assert_eq!(std::fs::read_to_string(done.join("m.voronoi.report.json")).unwrap(), "c");
        assert!(!third.exists() && !aside.exists() && !is_finished(&done, "m", &prov));
    }
}
