//! The main job, `voronoi-fit MESH [-o OUT.glb] [--sites K] [--steps S] [--seed N]`:
//! load → normalise into the unit cube → sample → train the sites (soft-Voronoi) → crust →
//! export in the input frame → evaluate → report.
//!
//! Writes OUT.glb (the crust), OUT.sites.npz (the sites file), OUT.report.json, and, while
//! training, OUT.ckpt.npz (every `--checkpoint-every` steps and on Ctrl-C; removed when the
//! run finishes unless `--keep-checkpoint`).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Instant;

use anyhow::anyhow;
use crust::{check::check_crust, Crust, CrustConfig, SitesFile};
use mesh_io::{TriMesh, UnitCubeTransform};
use occupancy::sample::{near_surface, uniform_in_box, SurfaceSampler};
use occupancy::MeshOracle;
use serde_json::json;
use soft_voronoi::{checkpoint, classify, Init, MeshSolid, TrainConfig, TrainState, Trainer, TrainingData};

use crate::cli_error::CliError;

/// Empty space around the mesh in the unit cube (each side), as a fraction of the cube.
const MARGIN: f64 = 0.05;

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// Input mesh (.obj, .stl, .ply, .off, .glb, .gltf).
    pub mesh: PathBuf,
    /// Output crust (.glb, .gltf, .obj or .ply). Default: MESH's stem + `.voronoi.glb` in
    /// the current directory. The sites file, report and checkpoint go beside it.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Number of trainable sites K (plus ⌈√K⌉ fixed outside sites on the cube's faces).
    #[arg(long)]
    pub sites: Option<usize>,
    /// Optimisation steps.
    #[arg(long)]
    pub steps: Option<usize>,
    /// Seed of the samples, the initialisation and the batches (the run is reproducible).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Settings preset: `default` (measured best here) or `paper` (the seed paper's).
    #[arg(long, default_value = "default", value_parser = ["default", "paper"])]
    pub preset: String,
    /// Initialisation: `surface` (pairs of sites straddling the surface; default), `samples`
    /// (sites drawn from the labelled training samples) or `paper` (uniform, half inside,
    /// half outside).
    #[arg(long)]
    pub init: Option<Init>,
    /// Training samples per step.
    #[arg(long)]
    pub batch: Option<usize>,
    /// Initial learning rate (cosine decay to 1% of it, or constant with --preset paper).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Anneal β geometrically from this value to 10,000 over the first half of training.
    #[arg(long)]
    pub beta_start: Option<f64>,
    /// Surface initialisation: each site's distance from the surface, as a fraction of the
    /// spacing of the pairs.
    #[arg(long)]
    pub surface_offset: Option<f64>,
    /// Weight of the signed-distance regulariser.
    #[arg(long)]
    pub w_sdf: Option<f64>,
    /// Weight of the centroidal regulariser.
    #[arg(long)]
    pub w_centroidal: Option<f64>,
    /// Size of the training sample pool (half uniform in the cube, half near the surface).
    #[arg(long, default_value_t = 1_000_000)]
    pub samples: usize,
    /// Fresh samples for the misclassification figure (half uniform, half near-surface).
    #[arg(long, default_value_t = 1_000_000)]
    pub eval_samples: usize,
    /// Write a checkpoint every this many steps (0: only on Ctrl-C).
    #[arg(long, default_value_t = 100)]
    pub checkpoint_every: usize,
    /// Continue from a checkpoint (the settings come from the checkpoint; the mesh must be
    /// the same).
    #[arg(long)]
    pub resume: Option<PathBuf>,
    /// Stop (with a checkpoint, as on Ctrl-C) after this many steps of this invocation.
    #[arg(long, hide = true)]
    pub stop_after: Option<usize>,
    /// Keep OUT.ckpt.npz after a finished run.
    #[arg(long)]
    pub keep_checkpoint: bool,
    /// Print the report as JSON on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

/// Training pool: near-surface spreads σ as fractions of the mesh's bounding-box diagonal
/// (half of the near-surface samples each).
const TRAIN_SIGMAS: [f64; 2] = [0.01, 0.003];
/// Evaluation: near-surface spread as a fraction of the diagonal, the default of
/// `voronoi-fit sample` (and of OccNet-style evaluations).
const EVAL_SIGMAS: [f64; 1] = [0.01];

/// What a resumed run must reproduce besides the training settings.
#[derive(serde::Serialize, serde::Deserialize, PartialEq, Debug)]
struct Context {
    mesh: String,
    samples: usize,
    seed: u64,
    sigmas: Vec<f64>,
    margin: f64,
}

fn bad(e: impl std::fmt::Display) -> CliError {
    CliError::BadInput(anyhow!("{e}"))
}

/// Paths of the outputs.
struct Outputs {
    mesh: PathBuf,
    sites: PathBuf,
    report: PathBuf,
    checkpoint: PathBuf,
}

fn outputs(args: &Args) -> Result<Outputs, CliError> {
    let mesh = match &args.output {
        Some(p) => p.clone(),
        None => {
            let stem = args.mesh.file_stem().map(|s| s.to_string_lossy().to_string()).unwrap_or_else(|| "mesh".into());
            PathBuf::from(format!("{stem}.voronoi.glb"))
        }
    };
    let ext = mesh.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    if !["glb", "gltf", "obj", "ply"].contains(&ext.as_str()) {
        return Err(bad(format!("{}: the output must end in .glb, .gltf, .obj or .ply", mesh.display())));
    }
    let base = mesh.with_extension("");
    let with = |suffix: &str| PathBuf::from(format!("{}{suffix}", base.display()));
    Ok(Outputs { sites: with(".sites.npz"), report: with(".report.json"), checkpoint: with(".ckpt.npz"), mesh })
}

fn config_from_args(args: &Args) -> Result<TrainConfig, CliError> {
    let k = args.sites.unwrap_or(DEFAULT_SITES);
    let mut c = if args.preset == "paper" { TrainConfig::paper(k) } else { TrainConfig::default_for(k) };
    c.steps = args.steps.unwrap_or(c.steps);
    c.seed = args.seed;
    if let Some(i) = args.init {
        c.init = i;
    }
    if let Some(b) = args.batch {
        c.batch = b;
    }
    if let Some(lr) = args.lr {
        c.lr_final = if args.preset == "paper" { lr } else { lr * (c.lr_final / c.lr) };
        c.lr = lr;
    }
    c.beta_start = args.beta_start.or(c.beta_start);
    if let Some(h) = args.surface_offset {
        c.surface_offset = h;
    }
    if let Some(w) = args.w_sdf {
        c.weights.signed_distance = w;
    }
    if let Some(w) = args.w_centroidal {
        c.weights.centroidal = w;
    }
    c.validate().map_err(|e| bad(format!("{e}; see voronoi-fit --help")))?;
    Ok(c)
}

/// Default number of trainable sites.
pub const DEFAULT_SITES: usize = 8192;

/// The mesh without unreferenced vertices (they must not move the normalisation).
fn compact(mesh: &TriMesh) -> TriMesh {
    let mut map = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                map[v as usize]
            })
        })
        .collect();
    TriMesh { positions, triangles }
}

/// Samples in the unit cube: `n/2` uniform, `n − n/2` near the surface (`sigmas`, unit-cube lengths),
/// labelled by |winding number| ≥ 0.5.
fn labelled_samples(
    sampler: &SurfaceSampler,
    solid: &MeshSolid,
    n: usize,
    sigmas: &[f64],
    seed: u64,
) -> Result<(TrainingData, usize), CliError> {
    let mut points = uniform_in_box([0.0; 3], [1.0; 3], n / 2, seed).map_err(|e| CliError::Failure(e.into()))?;
    let num_uniform = points.len();
    points.extend(near_surface(sampler, n - n / 2, sigmas, seed).map_err(|e| CliError::Failure(e.into()))?);
    let occupancy = solid.inside(&points);
    let surface = sampler.sample(n.min(1 << 20), seed ^ 0x5151);
    Ok((TrainingData { points, occupancy, surface: surface.points, normals: surface.normals }, num_uniform))
}

fn summary_json_losses(state: &TrainState) -> serde_json::Value {
    let h = &state.history;
    let every = (h.len() / 200).max(1);
    let rows: Vec<_> =
        h.iter().enumerate().filter(|(i, _)| i % every == 0 || *i + 1 == h.len()).map(|(_, s)| s).collect();
    json!({
        "columns": soft_voronoi::StepStats::NAMES,
        "every": every,
        "rows": rows.iter().map(|s| s.to_row().to_vec()).collect::<Vec<_>>(),
        "final": h.last(),
    })
}

/// The checked crust of `sites`, with its check and the number of jittered retries.
///
/// The crust is exact for the sites, but its Voronoi vertices are rounded to f64 in the
/// output; where trained sites are nearly cospherical, distinct vertices can round onto
/// each other and the exact checker rejects the mesh. Then the sites are moved by a seeded
/// jitter far below their spacing (1e-9, then 1e-7 of the unit cube) and the crust is
/// extracted again; `sites` is updated, so a sites file written from it reproduces the
/// crust.
///
/// # Errors
/// The crust's error, or the check's after two retries.
pub(crate) fn checked_crust(
    sites: &mut [[f64; 3]],
    labels: &[bool],
    seed: u64,
) -> Result<(Crust, crust::check::CrustCheck, usize), CliError> {
    let mut retries = 0;
    loop {
        let attempt = Crust::extract(sites, labels, &CrustConfig::default())
            .map_err(|e| CliError::Failure(anyhow!("crust of the trained sites: {e}")))
            .and_then(|c| match check_crust(&c.mesh) {
                Ok(check) => Ok((c, check)),
                Err(e) => Err(CliError::Failure(anyhow!("the crust failed its check ({e}); please report this"))),
            });
        match attempt {
            Ok((c, check)) => return Ok((c, check, retries)),
            Err(e) if retries >= 2 => return Err(e),
            Err(_) => {
                retries += 1;
                let amplitude = if retries == 1 { 1e-9 } else { 1e-7 };
                let mut rng = occupancy::sample::rng::ChunkRng::for_chunk(seed, 201, retries as u64);
                for p in sites.iter_mut() {
                    for x in p.iter_mut() {
                        *x = (*x + amplitude * (2.0 * rng.uniform() - 1.0)).clamp(1e-9, 1.0 - 1e-9);
                    }
                }
            }
        }
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    let t_all = Instant::now();
    // Ctrl-C sets a flag; training checks it after every step and stops with a checkpoint.
    // Installed first, so an early Ctrl-C also ends cleanly (before training nothing has
    // been written and the run exits at the first step).
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let out = outputs(&args)?;
    let mut timings = serde_json::Map::new();
    let mut lap = {
        let mut t = Instant::now();
        move |name: &str, timings: &mut serde_json::Map<String, serde_json::Value>| {
            timings.insert(name.to_string(), json!(t.elapsed().as_secs_f64()));
            t = Instant::now();
        }
    };

    // Settings: from the arguments, or from the checkpoint when resuming.
    let resumed = match &args.resume {
        Some(p) => Some(checkpoint::read(p).map_err(bad)?),
        None => None,
    };
    let (config, context) = match &resumed {
        Some((state, ctx)) => {
            let ctx: Context = serde_json::from_str(ctx).map_err(|e| {
                bad(format!(
                    "{}: not a checkpoint of `voronoi-fit MESH` ({e})",
                    args.resume.as_ref().map_or(String::new(), |p| p.display().to_string())
                ))
            })?;
            (state.config.clone(), ctx)
        }
        None => {
            let c = config_from_args(&args)?;
            if !(1000..=100_000_000).contains(&args.samples) || c.num_sites > args.samples / 2 {
                return Err(bad(format!(
                    "--samples {} must be in 1000..=100000000 and at least twice --sites {}",
                    args.samples, c.num_sites
                )));
            }
            let ctx = Context {
                mesh: args.mesh.display().to_string(),
                samples: args.samples,
                seed: args.seed,
                sigmas: TRAIN_SIGMAS.to_vec(),
                margin: MARGIN,
            };
            (c, ctx)
        }
    };
    if args.eval_samples > 100_000_000 {
        return Err(bad(format!("--eval-samples {} must be at most 100000000", args.eval_samples)));
    }

    // Load and normalise.
    let input = mesh_io::read_mesh(&args.mesh)?;
    let mesh = compact(&input);
    if mesh.triangles.is_empty() {
        return Err(bad(format!("{}: the mesh has no triangles; nothing to fit", args.mesh.display())));
    }
    let transform = UnitCubeTransform::of_mesh(&mesh, context.margin).ok_or_else(|| {
        bad(format!(
            "{}: the mesh has no extent (all vertices coincide) or non-finite coordinates",
            args.mesh.display()
        ))
    })?;
    let unit = transform.mesh_to_unit(&mesh);
    let topology = mesh_io::TopologyReport::of(&mesh);
    lap("load", &mut timings);
    let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default())
        .map_err(|e| bad(format!("{}: {e}", args.mesh.display())))?;
    let sampler = SurfaceSampler::from_mesh(&unit)
        .map_err(|e| bad(format!("{}: {e} (the mesh has no area to sample)", args.mesh.display())))?;
    let solid = MeshSolid { oracle: &oracle };
    lap("oracle", &mut timings);
    let diagonal = unit.diagonal();
    let train_sigmas: Vec<f64> = context.sigmas.iter().map(|s| s * diagonal).collect();
    let (data, _) = labelled_samples(&sampler, &solid, context.samples, &train_sigmas, context.seed)?;
    let num_inside = data.occupancy.iter().filter(|&&o| o).count();
    if num_inside == 0 {
        return Err(bad(format!(
            "{}: no training sample is inside the mesh (|winding number| < 0.5 everywhere): it encloses no volume. \
             Close the surface (fill its holes) and try again",
            args.mesh.display()
        )));
    }
    lap("sample", &mut timings);

    // Train.
    let mut trainer = match resumed {
        Some((state, _)) => {
            let p = args.resume.as_ref().map(|p| p.display().to_string()).unwrap_or_default();
            Trainer::resume(state, &data, &solid, &p).map_err(bad)?
        }
        None => Trainer::new(config.clone(), &data, &solid).map_err(bad)?,
    };
    let context_json = serde_json::to_string(&context).map_err(anyhow::Error::from)?;
    let bar = if args.quiet || args.json {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::new(config.steps as u64)
    };
    bar.set_style(
        indicatif::ProgressStyle::with_template("train {bar:30} {pos}/{len} steps, loss {msg}, {elapsed} (ETA {eta})")
            .map_err(anyhow::Error::from)?,
    );
    bar.set_position(trainer.state().step as u64);
    let mut done_here = 0usize;
    while !trainer.is_done() {
        let s = trainer.step().map_err(|e| CliError::Failure(e.into()))?;
        done_here += 1;
        bar.set_position(s.step as u64 + 1);
        if s.step % 10 == 0 {
            bar.set_message(format!("{:.5} (recon {:.5})", s.total, s.reconstruction));
        }
        let stop = interrupted.load(Ordering::SeqCst) || args.stop_after.is_some_and(|n| done_here >= n);
        let due = args.checkpoint_every > 0 && (s.step + 1) % args.checkpoint_every == 0;
        if (due || stop) && !trainer.is_done() {
            checkpoint::write(&out.checkpoint, trainer.state(), &context_json)
                .map_err(|e| CliError::Failure(e.into()))?;
        }
        if stop && !trainer.is_done() {
            bar.abandon();
            eprintln!(
                "stopped at step {} of {}; checkpoint {}. Continue with: voronoi-fit {} -o {} --resume {}",
                s.step + 1,
                config.steps,
                out.checkpoint.display(),
                args.mesh.display(),
                out.mesh.display(),
                out.checkpoint.display()
            );
            std::process::exit(130);
        }
    }
    bar.finish_and_clear();
    lap("train", &mut timings);

    // Crust.
    let (mut sites, labels, num_projected) = trainer.final_sites();
    let (crust, check, crust_retries) = checked_crust(&mut sites, &labels, context.seed)?;
    let flip = transform.scale < 0.0;
    let crust_mesh = TriMesh {
        positions: crust.mesh.positions.iter().map(|&p| transform.from_unit(p)).collect(),
        triangles: crust.mesh.triangles.iter().map(|t| if flip { [t[0], t[2], t[1]] } else { *t }).collect(),
    };
    lap("crust", &mut timings);

    // Quality on fresh samples (another seed stream than training).
    let eval_seed = context.seed ^ 0x5eed_e7a1_0000_0001;
    let eval_sigmas: Vec<f64> = EVAL_SIGMAS.iter().map(|s| s * diagonal).collect();
    let (eval, num_uniform) = labelled_samples(&sampler, &solid, args.eval_samples.max(2), &eval_sigmas, eval_seed)?;
    let predicted = classify(&sites, &labels, &eval.points);
    let wrong = |r: std::ops::Range<usize>| r.clone().filter(|&i| predicted[i] != eval.occupancy[i]).count();
    let n_eval = eval.points.len();
    let (wrong_u, wrong_n) = (wrong(0..num_uniform), wrong(num_uniform..n_eval));
    let misclassification = (wrong_u + wrong_n) as f64 / n_eval as f64;
    lap("evaluate", &mut timings);

    // Metrics against the input (the same code as `voronoi-fit eval`); the crust was
    // checked above, so its validity is not recomputed.
    let metrics_opts = metrics::EvalOptions { skip_validity: true, ..Default::default() };
    let (metrics_json, metrics_line) = match metrics::evaluate(&mesh, &crust_mesh, &metrics_opts) {
        Ok(m) => {
            let line = format!(
                "Against the input: Hausdorff in [{:.4e}, {:.4e}] (certified; libigl's vertex-only value {:.4e}), \
                 Chamfer L1 {:.4e}, F-score {:.4}, IoU {}.",
                m.hausdorff.lo,
                m.hausdorff.hi,
                m.hausdorff_libigl,
                m.surface.chamfer_l1,
                m.surface.fscore,
                m.iou.as_ref().and_then(|i| i.iou).map_or("n/a".to_string(), |v| format!("{v:.5}"))
            );
            (serde_json::to_value(&m).map_err(anyhow::Error::from)?, line)
        }
        Err(e) => (json!({ "error": e.to_string() }), format!("Metrics against the input failed: {e}.")),
    };
    lap("metrics", &mut timings);

    // Write: sites file, crust, report (each atomically).
    let sites_file =
        SitesFile { sites: sites.clone(), inside: labels.clone(), transform: transform.from_unit_matrix() };
    sites_file.write(&out.sites).map_err(|e| CliError::Failure(e.into()))?;
    mesh_io::write_mesh(&out.mesh, &crust_mesh)?;
    let state = trainer.state();
    let volume = mesh_io::TopologyReport::of(&crust_mesh).signed_volume;
    let report = json!({
        "format_version": 1,
        "input": {
            "path": args.mesh.display().to_string(),
            "num_vertices": input.positions.len(),
            "num_triangles": input.triangles.len(),
            "is_closed": topology.is_closed,
            "is_manifold": topology.is_manifold,
            "signed_volume": topology.signed_volume,
        },
        "settings": {
            "train": &state.config,
            "preset": args.preset,
            "samples": context.samples,
            "near_surface_sigmas_of_diagonal": context.sigmas,
            "near_surface_sigmas": train_sigmas,
            "margin": context.margin,
            "eval_samples": n_eval,
            "resumed_from": args.resume.as_ref().map(|p| p.display().to_string()),
            "threads": rayon::current_num_threads(),
        },
        "transform": { "center": transform.center, "scale": transform.scale },
        "timings_seconds": timings,
        "losses": summary_json_losses(state),
        "quality": {
            "misclassification": misclassification,
            "misclassification_uniform": wrong_u as f64 / num_uniform.max(1) as f64,
            "misclassification_near_surface": wrong_n as f64 / (n_eval - num_uniform).max(1) as f64,
            "eval_seed": eval_seed,
            "eval_near_surface_sigmas_of_diagonal": EVAL_SIGMAS,
            "eval_near_surface_sigmas": eval_sigmas,
        },
        "metrics": metrics_json,
        "crust": {
            "num_sites": crust.stats.num_sites,
            "num_inside": crust.stats.num_inside,
            "num_sites_projected_into_cube": num_projected,
            "jitter_retries": crust_retries,
            "num_vertices": crust_mesh.positions.len(),
            "num_triangles": crust_mesh.triangles.len(),
            "num_components": check.report.num_components,
            "genus": check.report.genus,
            "is_closed": check.report.is_closed,
            "is_manifold": check.report.is_manifold,
            "self_intersections": 0,
            "volume": volume,
        },
        "outputs": {
            "crust": out.mesh.display().to_string(),
            "sites": out.sites.display().to_string(),
            "report": out.report.display().to_string(),
        },
        "total_seconds": t_all.elapsed().as_secs_f64(),
    });
    let text = serde_json::to_string_pretty(&report).map_err(anyhow::Error::from)?;
    mesh_io::atomic_write(&out.report, |w| w.write_all(text.as_bytes()))?;
    if !args.keep_checkpoint && out.checkpoint.exists() {
        let _ = std::fs::remove_file(&out.checkpoint);
    }
    if args.json {
        crate::output::out!("{text}");
    } else {
        crate::output::out!(
            "{}: fitted {} sites ({} inside, {} fixed on the boundary) in {} steps; on {} fresh samples {:.3}% are \
             misclassified ({:.3}% of uniform, {:.3}% of near-surface ones). Crust: {} triangles, {} component(s), \
             genus {}, closed, manifold and free of self-intersections (checked), volume {:.6e}. {} Wrote {}, {} and \
             {} in {:.1} s.",
            args.mesh.display(),
            config.num_sites,
            labels[..config.num_sites].iter().filter(|&&l| l).count(),
            sites.len() - config.num_sites,
            config.steps,
            n_eval,
            100.0 * misclassification,
            100.0 * wrong_u as f64 / num_uniform.max(1) as f64,
            100.0 * wrong_n as f64 / (n_eval - num_uniform).max(1) as f64,
            crust_mesh.triangles.len(),
            check.report.num_components,
            check.report.genus.map_or("n/a".to_string(), |g| g.to_string()),
            volume,
            metrics_line,
            out.mesh.display(),
            out.sites.display(),
            out.report.display(),
            t_all.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
