//! What a fit needs besides the mesh: training settings, the sampling of the training and
//! evaluation pools, checkpointing and resuming.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use soft_voronoi::{checkpoint, TrainConfig, TrainState};

use crate::error::FitError;

/// Default number of trainable sites.
pub const DEFAULT_SITES: usize = 8192;

/// Default number of fresh evaluation samples. At a typical 0.4% misclassification the
/// 95% interval the report states is then ±0.025 points (±6% of the figure); 1M samples
/// narrowed it to ±0.012 but cost 2–13 s of the main job (the Menger sponge's labelling).
pub const DEFAULT_EVAL_SAMPLES: usize = 250_000;

/// Empty space around the mesh in the unit cube (each side), as a fraction of the cube.
pub const MARGIN: f64 = 0.05;

/// Default carving tolerance, a share of the diagonal (measured in the README's ablation:
/// it takes the bunny's certified Hausdorff from 0.99% to 0.56% and spot's from 0.47% to
/// 0.34%; on featuretype and the thin plate every round was undone).
pub const DEFAULT_CARVE: f64 = 0.003;

/// Weight of the alignment term in the polish the default tries beside the plain one on a
/// closed input ([`FitConfig::try_alignment`]). Measured (K = 8,192, README *Lined-up
/// pairs*): on libigl's 18 closed meshes the aligned crust is at least as good as the plain
/// one on all four metrics on 13 at weight 0.1 and on 9 at 0.3 (mean normal consistency of
/// the kept crusts 0.9925 against 0.9917; the plain polish 0.9905); on the quality
/// benchmark's closed meshes both keep it on spot, quadknot and npm_bunny, 0.3 with a little
/// more to show there (spot's normal consistency 0.996 against 0.995).
pub const TRY_ALIGNMENT_WEIGHT: f64 = 0.1;

/// The training pool: what a resumed run must reproduce besides the training settings
/// (stored in checkpoints as JSON, compared on resume).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Sampling {
    /// Name of the input (the CLI: its path), for messages and the report.
    pub mesh: String,
    /// Size of the pool: half uniform in the unit cube, half near the surface.
    pub samples: usize,
    /// Seed of the pool (also the training seed).
    pub seed: u64,
    /// Near-surface spreads σ as fractions of the mesh's bounding-box diagonal (the
    /// near-surface half is split evenly between them).
    pub sigmas: Vec<f64>,
    /// Empty space around the mesh in the unit cube, each side.
    pub margin: f64,
    /// Which solid the sites fit (absent in checkpoints written before it existed: auto).
    #[serde(default)]
    pub solid: SolidRule,
    /// Thickness of the shell solid, a fraction of the diagonal (`None`: the thinnest band
    /// of `target::BAND_FACTORS` times about one site spacing ([`shell_half_thickness`])
    /// whose crust holds, see `target::thinnest_band`).
    #[serde(default)]
    pub shell_thickness: Option<f64>,
    /// Close the input's planar holes flat before the winding-number solid is built
    /// (`mesh_io::fill_planar_holes`; not for a thin shell). Absent in checkpoints written
    /// before it existed: off, as they were sampled.
    #[serde(default)]
    pub fill_holes: bool,
    /// Cells of the flood fill's grid along the longest side of the mesh's box
    /// ([`SolidRule::Flood`]; gaps narrower than about 2.7 cells are closed).
    #[serde(default = "default_flood_cells")]
    pub flood_cells: usize,
}

/// [`Sampling::flood_cells`]' default: 256 cells along the longest side, gaps up to about
/// 1% of it closed — the seams and slits of dataset models, not their openings.
pub const DEFAULT_FLOOD_CELLS: usize = 256;

fn default_flood_cells() -> usize {
    DEFAULT_FLOOD_CELLS
}

/// Which solid a mesh stands for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SolidRule {
    /// The winding-number solid, unless the mesh is an open sheet: then the shell (the
    /// test is [`SHELL_ABOVE`]).
    #[default]
    Auto,
    /// |generalized winding number| ≥ 0.5 (closed meshes, soups, open meshes with a volume).
    Winding,
    /// The surface thickened by a band (zero-thickness sheets, lone open patches).
    Shell,
    /// What a flood fill from outside cannot reach, bounded by the input's surface, with
    /// sheets (outside on both sides) thickened into bands: soups of single-sided panels,
    /// open or flipped boxes, doubled or buried faces ([`soft_voronoi::FloodSolid`]).
    Flood,
}

/// [`SolidRule::Auto`] takes the flood solid for an open mesh when at least this share of
/// its surface bounds parts the flood cannot reach, or at least [`FLOOD_ENCLOSED_SHARE`]
/// bounds them or lies inside them (so the input is mostly closed parts, up to gaps narrower
/// than the grid closes: not a scan or a bowl whose holes let the flood in, nor a sheet,
/// whose surface has the outside on both sides), and the flood and winding
/// solids disagree on at least [`FLOOD_DISAGREEMENT`] of the near-surface samples (so the
/// winding number is not decisive there: flipped, doubled, open or single-sided parts).
/// On benches/real_world's ModelNet chair (rails, a seat, a single-sided back) 55% of the
/// surface bounds enclosed parts and the solids disagree on 39% of the near-surface samples;
/// on its scan with a hole (camelhead) the flood fills the inside and nothing is enclosed.
pub const FLOOD_BOUNDARY_SHARE: f64 = 0.25;

/// See [`FLOOD_BOUNDARY_SHARE`]: a surface mostly on or inside enclosed parts is a volume-
/// filling soup. libigl's `cube_40k.obj` (a grid of cubes with an open side) has 6% of its
/// surface on the boundary and 61% inside; the boundary test alone left it to the winding
/// solid, whose labels did not finish in 600 s (fast winding numbers cost about 70 µs each
/// there, the exact fallback 2 ms), where the flood solid's fit takes about a minute. Half,
/// not a quarter: trimesh's `soup.stl` (100 random triangles: 16% boundary, 16% inside,
/// 68% sheets) keeps the winding solid, whose capped surface lies nearer its triangles than
/// the flood solid's bands (K = 8,192: F-score 0.589 against 0.139).
pub const FLOOD_ENCLOSED_SHARE: f64 = 0.5;

/// See [`FLOOD_BOUNDARY_SHARE`].
pub const FLOOD_DISAGREEMENT: f64 = 0.02;

/// [`SolidRule::Auto`] takes the shell for an open mesh (some edge without exactly two
/// triangles) when at least this share of the near-surface samples have an ambiguous
/// winding number, 0.25 < |w| < 0.75; a closed mesh always keeps the winding-number solid.
/// Off a closed surface (or a soup of one) w is exactly 0 or ±1, so nothing is ambiguous;
/// an open mesh around a volume (a teapot without its lid's seams closed, a bowl) has w
/// near 0 or 1 except close to its holes; but beside a sheet, flat, wavy or curved, w stays
/// within a few tenths of ±0.5 on both sides, so the "inside" it gives is a sliver of the
/// sheet's concave side, not a solid.
pub const SHELL_ABOVE: f64 = 0.5;

/// [`SolidRule::Auto`] takes the shell for an open mesh whose winding-number solid would be
/// closed by |w| = 0.5 caps of at least this share of the input's own area
/// (`target::cap_points`' estimate; the report's `solid.cap_area_share`). A scan's holes
/// are gaps in a surface that bounds a volume, and their caps a small part of it
/// (measured: the benchmark's camelhead, open at the neck, 6%; libigl's head bust
/// `face.obj`, open at the neck, and lion's head, open behind, 16–17%; a soup of 100
/// triangles 11%; the open teapot and the bunny scan 1–2%; a sphere open above a quarter
/// of its height 22% at K = 2,048). A thin-walled part with large openings is not:
/// libigl's halftunnel (two openings whose rims are not planar) 41%, a pipe without its
/// ends 45% at K = 2,048. Closed by its caps, halftunnel's basin filled up and its crust
/// stood 12.8% of the diagonal off the input, where its thin shell stands 0.94%.
pub const CAPS_SHELL_ABOVE: f64 = 1.0 / 3.0;

/// Near-surface samples whose winding number [`SolidRule::Auto`] looks at (the first ones
/// of the pool, which is random).
pub const AMBIGUITY_SAMPLES: usize = 20_000;

/// Half-thickness of the flood solid's sheet bands in unit-cube lengths: `thickness`·
/// `diagonal`/2 when given, else half the shell's default for the surface the crust
/// follows (`area`: the input's area on the solid's boundary or on a sheet, interior faces
/// left out), √(A/K)/2, clamped to [0.1 %, 1 %] of the diagonal. The sheets are usually a
/// part of the surface among closed parts, and the trained sites resolve a band that thin
/// there (the ShapeNet motorbike and ModelNet toilet of benches/real_world: Chamfer 0.78 →
/// 0.32% and 0.52 → 0.28% of the diagonal, normal consistency 0.80 → 0.90 and 0.88 →
/// 0.91, from √(A/K) to 0.5% of the diagonal).
pub fn flood_sheet_half_thickness(thickness: Option<f64>, area: f64, num_sites: usize, diagonal: f64) -> f64 {
    match thickness {
        Some(t) => 0.5 * t * diagonal,
        None => (0.5 * (area / num_sites.max(1) as f64).sqrt()).clamp(1e-3 * diagonal, 1e-2 * diagonal),
    }
}

/// Half-thickness of the shell solid in unit-cube lengths: `thickness`·`diagonal`/2 when
/// given, else the default band √(A/K) for surface area A and K sites (half the spacing of
/// K/2 mirrored pairs spread over both sides of the band), clamped to [0.1 %, 5 %] of the
/// diagonal, from which `target::thinnest_band` tries thinner ones.
pub fn shell_half_thickness(thickness: Option<f64>, area: f64, num_sites: usize, diagonal: f64) -> f64 {
    match thickness {
        Some(t) => 0.5 * t * diagonal,
        None => (area / num_sites.max(1) as f64).sqrt().clamp(1e-3 * diagonal, 5e-2 * diagonal),
    }
}

/// The fresh evaluation pool (misclassification).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvalSampling {
    /// Size (half uniform, half near-surface).
    pub samples: usize,
    /// Near-surface spreads as fractions of the diagonal.
    pub sigmas: Vec<f64>,
}

/// Where and how often training writes its checkpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpointing {
    /// The checkpoint file (written atomically; each write replaces the last).
    pub path: PathBuf,
    /// Every this many steps (0: only when [`crate::Progress::should_stop`] asks).
    pub every: usize,
}

/// What set the amount of a fit's work (report field `settings.work_set_by`): for the
/// training pool's size, the training steps and the polish's steps and batch, the rule or
/// the option that chose each. None of them follows the mesh yet: the pool is a fixed
/// number of samples and the steps follow K and the preset.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct WorkSetBy {
    /// `default` or `--samples`, `preset fast`.
    pub samples: String,
    /// `default`, `--steps`, `preset fast` or `preset paper`.
    pub train_steps: String,
    /// `default: K > 4096` (600 steps), `default: K <= 4096` (400), `--polish-steps` or
    /// `preset fast`.
    pub polish_steps: String,
    /// `default` or `--polish-batch` (either grown by the caps' share of the surface
    /// samples, at most twofold: the report's `polish.batch` is the one used).
    pub polish_batch: String,
}

impl WorkSetBy {
    /// The defaults' rules at `num_sites`.
    pub fn defaults(num_sites: usize) -> Self {
        let above = num_sites > soft_voronoi::polish::POLISH_STEPS_ABOVE;
        WorkSetBy {
            samples: "default".into(),
            train_steps: "default".into(),
            polish_steps: if above { "default: K > 4096" } else { "default: K <= 4096" }.into(),
            polish_batch: "default".into(),
        }
    }
}

/// Everything that determines a fit of a given mesh.
#[derive(Clone, Debug)]
pub struct FitConfig {
    /// Training settings (sites, steps, learning rate, losses, seed).
    pub train: TrainConfig,
    /// Name of the settings preset, for the report (`default` or `paper`).
    pub preset: String,
    /// The training pool.
    pub sampling: Sampling,
    /// The evaluation pool.
    pub eval: EvalSampling,
    /// Checkpoints during training (`None`: none).
    pub checkpointing: Option<Checkpointing>,
    /// A saved state to continue from (see [`FitConfig::resume`]), with its path for
    /// messages.
    pub resume: Option<(TrainState, String)>,
    /// How the crust will be stored (f32 for glTF, f64 for OBJ/PLY): the crust is rounded
    /// to it and checked as rounded.
    pub output_precision: crust::output::Precision,
    /// Train the sites of a thin shell too. By default they are kept as constructed (see
    /// `target::shell_sites`): their bisectors are the shell's sides already, and training
    /// measured worse on sheets (near-surface misclassification 0.3 % as constructed,
    /// 0.7–3 % after 600 steps at any learning rate tried). `--train-shell` sets it; a
    /// step count (`--steps`) alone does not, so a batch with its own steps keeps its
    /// sheets as constructed (it once did: the quality benchmark's open sheet at `--steps
    /// 150` went from F-score 1.000 to 0.000).
    pub train_shell: bool,
    /// Start from pairs refined where a previous fit's crust missed a tolerance (the
    /// accuracy target's rounds, `grow`); only with [`soft_voronoi::Init::Pairs`]
    /// on the winding-number solid.
    pub refine: Option<Refine>,
    /// After training, give every trainable site the solid's label where it stands (see
    /// the report's `relabelled_sites`). Default on; `--no-relabel` keeps the training
    /// labels.
    pub relabel: bool,
    /// Insert sites where the crust's vertices are farther than this share of the diagonal
    /// from the input (the `carve` stage; default 0.3%, up to K/8 sites in eight rounds);
    /// `None`: off.
    pub carve: Option<f64>,
    /// Last, remove the sites that change neither the crust nor the nearest-site occupancy
    /// (every Delaunay neighbour carries their label; [`crust::prune`]): boundary sites,
    /// sites deep inside or far outside. Default on; off with the paper preset
    /// (`--no-prune`).
    pub prune: bool,
    /// Skip the metrics against the input (Hausdorff, Chamfer, IoU): for callers that
    /// measure themselves.
    pub skip_metrics: bool,
    /// After training, move the sites so the diagram's faces pass through the surface
    /// samples (VoroMesh's loss, [`soft_voronoi::polish`]); before relabelling and carving.
    /// `None`: off (`--no-polish`, and the paper preset). Not used on a thin shell, whose
    /// sites are placed on the shell's two sides, not on the sampled surface.
    pub polish: Option<soft_voronoi::PolishConfig>,
    /// On a closed input, when `polish` has no alignment term of its own: polish a second
    /// time with this one and keep that crust only if it is at least as good on all four
    /// metrics against the input and better on one (the report's `polish_choice`). Default
    /// [`soft_voronoi::polish::Alignment::default`] at weight [`TRY_ALIGNMENT_WEIGHT`]; `None`: the plain polish only
    /// (`--polish-align 0`).
    pub try_alignment: Option<soft_voronoi::polish::Alignment>,
    /// What set the pool's size and the steps (the report's `settings.work_set_by`; the
    /// front ends' options say when a flag or a preset did).
    pub work_set_by: WorkSetBy,
}

impl FitConfig {
    /// The default fit of `num_sites` sites ([`TrainConfig::default_for`]), seed 0,
    /// 1,000,000 training samples, [`DEFAULT_EVAL_SAMPLES`] evaluation samples, no checkpoints.
    pub fn new(mesh: &str, num_sites: usize) -> Self {
        FitConfig {
            train: TrainConfig::default_for(num_sites),
            preset: "default".into(),
            sampling: Sampling {
                mesh: mesh.to_string(),
                samples: 1_000_000,
                seed: 0,
                sigmas: vec![0.01, 0.003],
                margin: MARGIN,
                solid: SolidRule::Auto,
                shell_thickness: None,
                flood_cells: DEFAULT_FLOOD_CELLS,
                fill_holes: true,
            },
            eval: EvalSampling { samples: DEFAULT_EVAL_SAMPLES, sigmas: vec![0.01] },
            checkpointing: None,
            resume: None,
            output_precision: crust::output::Precision::F32,
            train_shell: false,
            relabel: true,
            carve: Some(DEFAULT_CARVE),
            prune: true,
            refine: None,
            skip_metrics: false,
            polish: Some(soft_voronoi::PolishConfig::default_for(num_sites, 0)),
            try_alignment: Some(soft_voronoi::polish::Alignment {
                normal_weight: TRY_ALIGNMENT_WEIGHT,
                ..Default::default()
            }),
            work_set_by: WorkSetBy::defaults(num_sites),
        }
    }

    /// Sets the seed of the pool, the initialisation and the batches.
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.sampling.seed = seed;
        self.train.seed = seed;
        if let Some(p) = &mut self.polish {
            p.seed = seed;
        }
        self
    }

    /// Continues the checkpoint at `path`: its training settings and sampling, with the
    /// evaluation settings of `self` (the checkpoint does not hold them).
    ///
    /// # Errors
    /// [`FitError::CheckpointRead`] when the file cannot be read as a checkpoint,
    /// [`FitError::CheckpointSettings`] when it is not a checkpoint of the main job.
    pub fn resume(mut self, path: &Path) -> Result<Self, FitError> {
        let (state, context) =
            checkpoint::read(path).map_err(|source| FitError::CheckpointRead { path: path.to_path_buf(), source })?;
        let sampling: Sampling = serde_json::from_str(&context).map_err(|source| FitError::CheckpointSettings {
            path: path.to_path_buf(),
            what: "not a checkpoint of `voronoi-fit MESH`",
            source,
        })?;
        // The polish settings of the run that wrote the checkpoint (checkpoints written
        // before the polish existed have none: the current settings stay).
        if let Ok(serde_json::Value::Object(map)) = serde_json::from_str::<serde_json::Value>(&context) {
            if let Some(p) = map.get("polish") {
                self.polish = serde_json::from_value(p.clone()).map_err(|source| FitError::CheckpointSettings {
                    path: path.to_path_buf(),
                    what: "the checkpoint's polish settings",
                    source,
                })?;
                // The choice of the aligned polish came later: a checkpoint without it was
                // written by a run that polished once.
                self.try_alignment = match map.get("try_alignment") {
                    Some(a) => serde_json::from_value(a.clone()).map_err(|source| FitError::CheckpointSettings {
                        path: path.to_path_buf(),
                        what: "the checkpoint's alignment settings",
                        source,
                    })?,
                    None => None,
                };
            }
        }
        self.train = state.config.clone();
        self.sampling = sampling;
        self.resume = Some((state, path.display().to_string()));
        Ok(self)
    }

    /// What a checkpoint stores beside the training state: the sampling settings and the
    /// polish settings, as one JSON object (the sampling's fields plus `polish` and
    /// `try_alignment`), so a
    /// resume continues exactly the run that was stopped.
    ///
    /// # Errors
    /// [`FitError::CheckpointContext`] when serialisation fails.
    pub fn checkpoint_context(&self) -> Result<String, FitError> {
        let fail = FitError::CheckpointContext;
        let mut v = serde_json::to_value(&self.sampling).map_err(fail)?;
        if let serde_json::Value::Object(map) = &mut v {
            map.insert("polish".into(), serde_json::to_value(&self.polish).map_err(fail)?);
            map.insert("try_alignment".into(), serde_json::to_value(&self.try_alignment).map_err(fail)?);
        }
        serde_json::to_string(&v).map_err(fail)
    }

    /// Checks the settings.
    ///
    /// # Errors
    /// [`FitError::Settings`] or [`FitError::TrainSettings`] naming the setting and its accepted
    /// range.
    pub fn validate(&self) -> Result<(), FitError> {
        self.train.validate().map_err(FitError::TrainSettings)?;
        let s = &self.sampling;
        if self.resume.is_none() && (!(1000..=100_000_000).contains(&s.samples) || self.train.num_sites > s.samples / 2)
        {
            return Err(FitError::Settings(format!(
                "--samples {} must be in 1000..=100000000 and at least twice --sites {}",
                s.samples, self.train.num_sites
            )));
        }
        if let Some(p) = &self.polish {
            p.validate().map_err(FitError::TrainSettings)?;
        }
        if self.eval.samples > 100_000_000 {
            return Err(FitError::Settings(format!("--eval-samples {} must be at most 100000000", self.eval.samples)));
        }
        let good = |v: &[f64]| !v.is_empty() && v.iter().all(|x| x.is_finite() && *x > 0.0 && *x < 1.0);
        if !good(&s.sigmas) || !good(&self.eval.sigmas) {
            return Err(FitError::Settings("near-surface spreads must be in (0, 1) of the diagonal".into()));
        }
        if let Some(t) = s.shell_thickness {
            if !(t.is_finite() && t > 0.0 && t <= 0.2) {
                return Err(FitError::Settings(format!("--shell-thickness {t} must be in (0, 0.2] of the diagonal")));
            }
        }
        if !(s.margin.is_finite() && s.margin >= 0.0 && s.margin < 0.5) {
            return Err(FitError::Settings(format!("margin {} must be in [0, 0.5)", s.margin)));
        }
        Ok(())
    }
}

/// What to refine: the crust of a previous fit of the same mesh and the distance it should
/// have kept to the input.
#[derive(Clone, Debug)]
pub struct Refine {
    /// The previous crust, in the input's frame.
    pub previous: mesh_io::TriMesh,
    /// The target distance, input units.
    pub tolerance: f64,
}
