//! The main job, `voronoi-fit MESH [-o OUT.glb] [--sites K] [--steps S] [--seed N]`: the
//! arguments, Ctrl-C, the progress bar and the printing around [`jobs::fit_to_files`],
//! which writes OUT.glb (the crust), OUT.sites.npz, OUT.png, OUT.report.json and, while
//! training, OUT.ckpt.npz (every `--checkpoint-every` steps and on Ctrl-C; removed when the
//! run finishes unless `--keep-checkpoint`).

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use fit::{FitOptions, Progress, SolidRule};
use soft_voronoi::{Density, Init, StepStats};

use crate::cli_error::CliError;

#[derive(clap::Args, Clone, Debug)]
pub struct Args {
    /// Input mesh (.obj, .stl, .ply, .off, .glb, .gltf).
    pub mesh: PathBuf,
    /// Output crust (.glb, .gltf, .obj or .ply). Default: MESH's stem + `.voronoi.glb` in
    /// the current directory. The sites file, report and checkpoint go beside it.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    #[arg(long, default_value = "flat", value_parser = mesh_io::Normals::parse, value_name = "flat|smooth|crease[:DEG]",
          help = crate::output::NORMALS_HELP)]
    pub normals: mesh_io::Normals,
    /// Number of trainable sites K (plus ⌈√K⌉ fixed outside sites on the cube's faces).
    #[arg(long)]
    pub sites: Option<usize>,
    /// Optimisation steps.
    #[arg(long)]
    pub steps: Option<usize>,
    /// Seed of the samples, the initialisation and the batches (the run is reproducible).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Settings preset: `default` (measured best here), `fast` (about half the time for a
    /// rougher crust: 100 training steps, one plain polish of 300 steps, a pool of 250,000
    /// samples; explicit flags still win) or `paper` (the seed paper's).
    #[arg(long, default_value = "default", value_parser = ["default", "fast", "paper"])]
    pub preset: String,
    /// Initialisation: `pairs` (mirrored pairs at well-spread surface points, denser where
    /// the part is thin; default), `surface` (pairs at random surface points, the previous
    /// default), `samples` (sites drawn from the labelled training samples) or `paper`
    /// (uniform, half inside, half outside).
    #[arg(long)]
    pub init: Option<Init>,
    /// Pair initialisation's density: `adaptive` (default: closer pairs where the part is
    /// thinner or more folded than the uniform spacing, docs/main-job.md) or `uniform`
    /// (one spacing everywhere; the ablation's baseline).
    #[arg(long)]
    pub density: Option<Density>,
    /// Training samples per step.
    #[arg(long)]
    pub batch: Option<usize>,
    /// Initial learning rate (cosine decay to 1% of it, or constant with --preset paper).
    #[arg(long)]
    pub lr: Option<f64>,
    /// Anneal β geometrically from this value to 10,000 over the first half of training.
    #[arg(long)]
    pub beta_start: Option<f64>,
    /// Pair initialisations: each site's distance from the surface, as a fraction of the
    /// (local) spacing of the pairs.
    #[arg(long)]
    pub surface_offset: Option<f64>,
    /// Weight of the signed-distance regulariser.
    #[arg(long)]
    pub w_sdf: Option<f64>,
    /// Weight of the centroidal regulariser.
    #[arg(long)]
    pub w_centroidal: Option<f64>,
    /// Weight of the normal alignment inside the surface term.
    #[arg(long)]
    pub w_normal: Option<f64>,
    /// Weight of the reconstruction (occupancy) loss E|O − V|.
    #[arg(long)]
    pub w_reconstruction: Option<f64>,
    /// Weight of the surface term (surface samples pulled onto the bisector of their
    /// nearest inside and outside sites).
    #[arg(long)]
    pub w_surface: Option<f64>,
    /// Size of the training sample pool (half uniform in the cube, half near the surface);
    /// default 1,000,000 (250,000 with --preset fast).
    #[arg(long)]
    pub samples: Option<usize>,
    /// Fresh samples for the misclassification figure (half uniform, half near-surface);
    /// the report gives its 95% interval.
    #[arg(long, default_value_t = fit::DEFAULT_EVAL_SAMPLES)]
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
    /// Also write OUT.html, the offline viewer page of the result (as `voronoi-fit view`).
    #[arg(long)]
    pub html: bool,
    /// Print the report as JSON on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// After the summary, print the whole story of the fit (the solid, the polish and its
    /// choice, carving, pruning, every metric) and how viewers will shade the crust.
    #[arg(short, long)]
    pub verbose: bool,
    /// Merge vertices closer than this fraction of the bounding-box diagonal before fitting
    /// (closes float-rounding cracks of CAD exports; e.g. 1e-6). Default: exact welding only.
    #[arg(long, value_parser = mesh_io::weld::parse_tolerance)]
    pub weld_tolerance: Option<f64>,
    /// The solid to fit: `winding` (|winding number| ≥ 0.5: closed meshes, soups of closed
    /// parts, open meshes with a volume), `flood` (what a flood fill from outside cannot
    /// reach, on the input's surface, sheets as thin bands: soups of single-sided panels,
    /// open or flipped boxes, doubled faces), `shell` (the surface thickened by a thin band:
    /// sheets, lone open patches) or `auto` (winding for a closed mesh; for an open one,
    /// flood where it encloses a volume the winding number does not agree with, else shell
    /// where the winding number stays near ±0.5 beside most of the surface, else winding).
    #[arg(long, default_value = "auto", value_parser = parse_solid)]
    pub solid: SolidRule,
    /// Thickness of the shell solid as a share of the bounding-box diagonal (`1%` or
    /// `0.01`). Default: the thinnest of 0.15, 0.2, 0.3, 0.4, 0.5 and 0.7 times about one
    /// site spacing whose crust keeps the topology and Hausdorff distance of the full
    /// spacing's (none thinner when 0.7 breaks), else the full spacing (the report's
    /// `solid.thickness_search`).
    #[arg(long, value_parser = parse_share)]
    pub shell_thickness: Option<f64>,
    /// Cells of the flood fill's grid along the longest side of the mesh (16 to 500,
    /// default 256); gaps narrower than about 2.7 cells are closed.
    #[arg(long)]
    pub flood_cells: Option<usize>,
    /// Keep an open mesh's planar holes open. By default, before the winding-number solid
    /// is built, each hole whose rim lies in a plane (within 1% of its size) is closed flat
    /// where that closes a piece with real volume (a cube without its bottom gets its
    /// bottom); other holes are closed by the |winding number| = 0.5 surface.
    #[arg(long)]
    pub no_fill_holes: bool,
    /// Train a thin shell's sites (and polish and carve them) instead of keeping them as
    /// constructed, whose bisectors are the band's sides already; measured worse on sheets.
    #[arg(long)]
    pub train_shell: bool,
    /// Ask for an accuracy instead of a K: the certified Hausdorff distance to the input as
    /// a share of its bounding-box diagonal (`0.5%` or `0.005`). The fit starts at --sites
    /// and doubles K, refining where the error was, until met or --max-sites.
    #[arg(long, value_parser = parse_share)]
    pub target_hausdorff: Option<f64>,
    /// Grow K as --target-hausdorff does (alone or with it) until the crust has the input's
    /// genus and components: for a closed, manifold input fitted as its winding solid
    /// without faces inside it (report: topology, accuracy_target).
    #[arg(long)]
    pub keep_topology: bool,
    /// Keep the training labels (default: after training every site takes the solid's label
    /// where it stands). Needs --no-polish: the polish moves sites without their labels.
    #[arg(long)]
    pub no_relabel: bool,
    /// Insert mirrored pairs of sites where the crust strays farther than this share of the
    /// diagonal from the input (`0.3%` or `0.003`), up to K/8 sites in eight rounds, keeping
    /// the best round. Default 0.3% (off with --preset paper).
    #[arg(long, value_parser = parse_share)]
    pub carve: Option<f64>,
    /// No site insertion after training.
    #[arg(long, conflicts_with = "carve")]
    pub no_carve: bool,
    /// Keep every site (default: last, the sites whose Delaunay neighbours all carry their
    /// label are removed; they change neither the crust nor the occupancy; off with
    /// --preset paper).
    #[arg(long)]
    pub no_prune: bool,
    /// Steps of the surface polish after training (VoroMesh's bisector loss pulls the
    /// diagram's faces onto surface samples; default 400, 600 above K = 4,096; 0 or --no-polish: none; off with
    /// --preset paper unless given).
    #[arg(long)]
    pub polish_steps: Option<usize>,
    /// Initial learning rate of the polish (default 1e-3 at 8,192 sites, scaled by
    /// √(8192/K); halved four times over the steps).
    #[arg(long)]
    pub polish_lr: Option<f64>,
    /// Surface samples per polish step (default 20,000).
    #[arg(long)]
    pub polish_batch: Option<usize>,
    /// Weight of the polish's alignment term over its first half (nearest inside and
    /// outside sites of each surface sample turned along its normal, which lines the pairs
    /// up, for smoother normals on smooth shapes). Default: on a closed input the polish
    /// runs twice, without the term and with weight 0.1, and the aligned crust is kept only
    /// if it is at least as good on all four metrics against the input (Hausdorff
    /// distances both within the F-score's τ, 0.3% of the diagonal, or with overlapping
    /// certified intervals count as equal; report: polish_choice); 0: VoroLoss alone, as VoroMesh (faster); W > 0: always weight W
    /// (docs/main-job.md, *Polish*).
    #[arg(long)]
    pub polish_align: Option<f64>,
    /// No surface polish after training.
    #[arg(long, conflicts_with_all = ["polish_steps", "polish_lr", "polish_batch", "polish_align"])]
    pub no_polish: bool,
    /// Budget of sites for --target-hausdorff and --keep-topology.
    #[arg(long, default_value_t = fit::DEFAULT_MAX_SITES)]
    pub max_sites: usize,
    /// Also write OUT.points.npz: N occupancy samples of the fitted solid (labelled by the
    /// sites, i.e. inside the crust), in Occupancy Networks' layout (`points` float16 in the
    /// mesh's normalised frame, `occupancies` packed bits, `loc`, `scale`).
    #[arg(long, value_name = "N")]
    pub occupancy: Option<usize>,
    /// Share of the --occupancy points drawn uniformly in the padded cube; the rest lie near
    /// the crust's surface (OccNet's points_uniform_ratio).
    #[arg(long, default_value_t = 0.5)]
    pub occupancy_uniform_fraction: f64,
    /// Standard deviation of the near-surface --occupancy points' Gaussian offsets, in the
    /// normalised frame (longest side of the bounding box = 1; OccNet's points_sigma).
    #[arg(long, default_value_t = 0.01)]
    pub occupancy_sigma: f64,
    /// The --occupancy uniform points fill the cube of side 1 + this around the normalised
    /// mesh (OccNet's points_padding).
    #[arg(long, default_value_t = 0.1)]
    pub occupancy_padding: f64,
}

/// `0.5%` → 0.005; `0.005` → 0.005.
fn parse_share(s: &str) -> Result<f64, String> {
    let (number, scale) = match s.strip_suffix('%') {
        Some(n) => (n, 0.01),
        None => (s, 1.0),
    };
    let x: f64 = number.trim().parse().map_err(|_| format!("`{s}` is not a share; write e.g. 0.5% or 0.005"))?;
    let x = x * scale;
    if x.is_finite() && x > 0.0 && x < 1.0 {
        Ok(x)
    } else {
        Err(format!("`{s}` must be between 0 and 100% of the diagonal"))
    }
}

fn parse_solid(s: &str) -> Result<SolidRule, String> {
    match s {
        "auto" => Ok(SolidRule::Auto),
        "winding" => Ok(SolidRule::Winding),
        "shell" => Ok(SolidRule::Shell),
        "flood" => Ok(SolidRule::Flood),
        _ => Err(format!("`{s}` is not a solid; use auto, winding, shell or flood")),
    }
}

impl Args {
    /// The typed options of the main job for these arguments (the fit options through
    /// [`fit::FitOptions`], as the Python package passes them).
    pub fn to_job(&self) -> jobs::FitJob {
        jobs::FitJob {
            mesh: self.mesh.clone(),
            output: self.output.clone(),
            normals: self.normals,
            options: FitOptions {
                sites: self.sites,
                steps: self.steps,
                seed: self.seed,
                preset: Some(self.preset.clone()),
                init: self.init,
                density: self.density,
                batch: self.batch,
                lr: self.lr,
                beta_start: self.beta_start,
                surface_offset: self.surface_offset,
                w_sdf: self.w_sdf,
                w_centroidal: self.w_centroidal,
                w_normal: self.w_normal,
                w_reconstruction: self.w_reconstruction,
                w_surface: self.w_surface,
                samples: self.samples,
                eval_samples: Some(self.eval_samples),
                solid: self.solid,
                shell_thickness: self.shell_thickness,
                flood_cells: self.flood_cells,
                no_fill_holes: self.no_fill_holes,
                train_shell: self.train_shell,
                no_relabel: self.no_relabel,
                carve: self.carve,
                no_carve: self.no_carve,
                no_prune: self.no_prune,
                skip_metrics: false,
                no_polish: self.no_polish,
                polish_steps: self.polish_steps,
                polish_lr: self.polish_lr,
                polish_batch: self.polish_batch,
                polish_align: self.polish_align,
            },
            weld_tolerance: self.weld_tolerance,
            target_hausdorff: self.target_hausdorff,
            max_sites: self.max_sites,
            keep_topology: self.keep_topology,
            checkpoint_every: self.checkpoint_every,
            resume: self.resume.clone(),
            stop_after: self.stop_after,
            keep_checkpoint: self.keep_checkpoint,
            html: self.html,
            occupancy: self.occupancy.map(|points| jobs::OccupancySpec {
                points,
                uniform_fraction: self.occupancy_uniform_fraction,
                sigma: self.occupancy_sigma,
                padding: self.occupancy_padding,
            }),
        }
    }
}

/// A job error as the binary's: a stopped run exits 130 with how to continue, the input's
/// fault 2, anything else 1.
pub fn cli_error(e: jobs::Error) -> CliError {
    match e {
        jobs::Error::Interrupted { step, steps, checkpoint, mesh, output } => CliError::Interrupted(format!(
            "stopped at step {step} of {steps}; checkpoint {}. Continue with: voronoi-fit {} -o {} --resume {}",
            checkpoint.display(),
            mesh.display(),
            output.display(),
            checkpoint.display()
        )),
        e if e.is_input_fault() => CliError::BadInput(e.into()),
        e => CliError::Failure(e.into()),
    }
}

/// The progress bar and Ctrl-C.
struct CliProgress {
    bar: indicatif::ProgressBar,
    interrupted: Arc<AtomicBool>,
}

impl Progress for CliProgress {
    fn train_start(&mut self, done: usize, total: usize) {
        self.bar.reset();
        self.bar.set_prefix("train");
        self.bar.set_length(total as u64);
        self.bar.set_position(done as u64);
    }

    fn train_step(&mut self, s: &StepStats) {
        self.bar.set_position(s.step as u64 + 1);
        if s.step.is_multiple_of(10) {
            self.bar.set_message(format!("loss {:.5} (recon {:.5})", s.total, s.reconstruction));
        }
    }

    fn should_stop(&mut self) -> bool {
        self.interrupted.load(Ordering::SeqCst)
    }

    fn train_end(&mut self) {
        self.bar.finish_and_clear();
    }

    fn polish_step(&mut self, done: usize, total: usize, loss: f64) {
        if done == 1 {
            self.bar.reset();
            self.bar.set_length(total as u64);
            self.bar.set_prefix("polish");
        }
        self.bar.set_position(done as u64);
        if done.is_multiple_of(10) {
            self.bar.set_message(format!("VoroLoss {loss:.3e}"));
        }
        if done == total {
            self.bar.finish_and_clear();
        }
    }
}

pub fn run(args: Args) -> Result<(), CliError> {
    // Ctrl-C sets a flag; training checks it after every step and stops with a checkpoint.
    // Installed first, so an early Ctrl-C also ends cleanly at the first step.
    let interrupted = Arc::new(AtomicBool::new(false));
    {
        let flag = interrupted.clone();
        let _ = ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst));
    }
    let bar = if args.quiet || args.json { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(0) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("{prefix} {bar:30} {pos}/{len} steps, {msg}, {elapsed} (ETA {eta})")
            .map_err(anyhow::Error::from)?,
    );
    let mut progress = CliProgress { bar, interrupted };
    let done = jobs::fit_to_files(&args.to_job(), &mut progress).map_err(cli_error)?;
    if args.json {
        crate::output::out!("{}", done.json);
    } else {
        // At most five lines: what was fitted, the solid, quality, validity (the report's
        // summary) and the files with the time; `--verbose` adds the rest.
        let lines: Vec<String> = done.report.summary_lines().collect();
        for line in &lines {
            crate::output::out!("{line}");
        }
        // The crust in full, the files beside it by what follows the crust's stem.
        let stem = done.outputs.mesh.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        let mut beside = vec![&done.outputs.sites, &done.picture, &done.outputs.report];
        beside.extend(done.page.as_ref());
        if done.report.outputs.occupancy.is_some() {
            beside.push(&done.outputs.points);
        }
        let beside: Vec<String> = beside.iter().map(|p| after_stem(p, &stem)).collect();
        crate::output::out!(
            "Wrote {} (+ {}) in {:.1} s",
            done.outputs.mesh.display(),
            beside.join(", "),
            done.report.total_seconds
        );
        if args.verbose {
            // How viewers will shade a glTF crust (docs/viewer.md).
            let gltf = matches!(
                mesh_io::OutputFormat::from_path(&done.outputs.mesh),
                Ok(mesh_io::OutputFormat::Glb | mesh_io::OutputFormat::Gltf)
            );
            let shading = match args.normals {
                _ if !gltf => String::new(),
                mesh_io::Normals::Flat => {
                    " The crust is flat-shaded; --normals crease shades smooth surfaces smooth.".into()
                }
                mesh_io::Normals::Smooth => " The crust carries smooth normals.".into(),
                mesh_io::Normals::Crease(d) => format!(" The crust's normals are creased at {d}°."),
            };
            crate::output::out!("\n{}{shading}", done.report.details());
            if let Some(page) = &done.page {
                crate::output::out!("The viewer page {} works offline in a browser.", page.display());
            }
        }
    }
    Ok(())
}

/// A file written beside the crust, named by what follows the crust's stem (`.sites.npz`),
/// or by its whole name when it does not start with the stem.
fn after_stem(path: &std::path::Path, stem: &str) -> String {
    let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
    match name.strip_prefix(stem) {
        Some(rest) if !stem.is_empty() && rest.starts_with('.') => rest.to_string(),
        _ => name,
    }
}
