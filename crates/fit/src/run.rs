//! The driver: [`fit`], one stage after another.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crust::output::FrameMap;
use crust::SitesFile;
use mesh_io::{TopologyReport, TriMesh, UnitCubeTransform};
use occupancy::sample::SurfaceSampler;
use occupancy::MeshOracle;
use soft_voronoi::{checkpoint, classify, MeshSolid, Solid, TrainState, Trainer, TrainingData};

use crate::carve::SurfaceBar;
use crate::config::{FitConfig, SolidRule, AMBIGUITY_SAMPLES, SHELL_ABOVE};
use crate::crust_step::{crust_of, CheckedCrust};
use crate::data::{compact, labelled_samples};
use crate::error::{FitError, MeshFault};
use crate::progress::{NoProgress, Progress, Stage};
use crate::report::*;
use crate::target;

/// What a fit produces.
pub struct FitOutput {
    /// The trained sites (trainable then boundary; unit-cube coordinates), their labels and
    /// the map back to the input's frame.
    pub sites: SitesFile,
    /// The crust in the input's frame (counter-clockwise seen from outside), rounded to
    /// `FitConfig::output_precision` and checked exactly as rounded: write it as it is.
    pub crust: TriMesh,
    /// The training state at the end (sites, optimiser, losses).
    pub state: TrainState,
    /// The report.
    pub report: FitReport,
}

/// The mesh in the unit cube and what is built on it.
struct Prepared {
    /// The input without unreferenced vertices (the metrics' reference).
    mesh: TriMesh,
    transform: UnitCubeTransform,
    /// The solid's surface in the unit cube: the input consistently oriented, with its
    /// planar holes closed when they were filled.
    unit: TriMesh,
    /// The input's topology.
    topology: TopologyReport,
    reoriented: mesh_io::Reorientation,
    /// The holes closed flat (open input, filling asked for and not a thin shell).
    holes: Option<mesh_io::HoleFilling>,
    /// Whether `unit` is closed: the input is, or its fills closed it. A mesh closed by its
    /// fills is fitted as a closed one: the winding-number solid without caps, and both
    /// polishes tried.
    closed: bool,
}

fn prepare(input: &TriMesh, config: &FitConfig) -> Result<Prepared, FitError> {
    let name = &config.sampling.mesh;
    let mesh = compact(input);
    if mesh.triangles.is_empty() {
        return Err(FitError::Mesh { mesh: name.clone(), fault: MeshFault::NoTriangles });
    }
    let transform = UnitCubeTransform::of_mesh(&mesh, config.sampling.margin)
        .ok_or_else(|| FitError::Mesh { mesh: name.clone(), fault: MeshFault::NoExtent })?;
    // The solid, the samples' normals and the carving use a copy whose pieces agree on
    // their orientation (triangles flipped against their neighbours turn part of a body
    // inside out for the winding number); the input itself, and the metrics against it,
    // stay as given.
    let (unit, reoriented) = mesh_io::orient_consistently(&transform.mesh_to_unit(&mesh));
    let topology = TopologyReport::of(&mesh);
    // Holes closed the way a person would: a planar rim by its flat lid, before the
    // winding numbers are computed, so that the lid is the solid's surface (the |w| = 0.5
    // cap is sampled, and bends where several holes are open). Not for a thin shell, whose
    // surface is the input as it is: not under `--solid shell`, nor under `--solid auto` for
    // an open mesh that is a sheet as it is ([`open_mesh_is_a_sheet`]); `fill_planar_holes`
    // leaves a sheet's own outline open by itself.
    let fill = config.sampling.fill_holes && config.sampling.solid != SolidRule::Shell && !topology.is_closed;
    let (unit, holes) = if fill {
        let (filled, mut r) = mesh_io::fill_planar_holes(&unit, &mesh_io::FillOptions::default());
        // Unit-cube areas back to the input's units (`scale`: unit-cube lengths per input unit).
        r.filled_area /= transform.scale * transform.scale;
        if r.loops_filled > 0 && config.sampling.solid == SolidRule::Auto && open_mesh_is_a_sheet(&unit, config)? {
            (unit, None)
        } else {
            (filled, Some(r))
        }
    } else {
        (unit, None)
    };
    let closed =
        topology.is_closed || holes.as_ref().is_some_and(|h| h.loops_filled > 0 && TopologyReport::of(&unit).is_closed);
    Ok(Prepared { mesh, transform, unit, topology, reoriented, holes, closed })
}

/// Whether `--solid auto` takes a thin shell for the open `unit` as it is: its winding number
/// ambiguous beside most of its surface, judged on [`AMBIGUITY_SAMPLES`] near-surface points
/// as `target::choose` judges the pool's. Such a mesh is a sheet and keeps its holes: closing
/// some of them could tip the rule to the winding solid of a sheet (the real-world
/// benchmark's car body with its windows closed: a volume with caps under it, 16.7% of the
/// diagonal from the input, against 1.3% as a shell). Costs an oracle of the open mesh
/// (0.1 s on that car body) and winding numbers at the probe points.
fn open_mesh_is_a_sheet(unit: &TriMesh, config: &FitConfig) -> Result<bool, FitError> {
    let (oracle, sampler) = oracle_and_sampler(unit, &config.sampling.mesh)?;
    let sigmas: Vec<f64> = config.sampling.sigmas.iter().map(|x| x * unit.diagonal()).collect();
    let probe = occupancy::sample::near_surface(&sampler, AMBIGUITY_SAMPLES, &sigmas, config.sampling.seed)
        .map_err(|source| FitError::Occupancy { during: "sampling", source })?;
    let w = oracle
        .winding_numbers(&probe, occupancy::WindingMode::Fast)
        .map_err(|source| FitError::Occupancy { during: "winding numbers", source })?;
    Ok(target::ambiguous_share(&w) >= SHELL_ABOVE)
}

/// Everything from the polish on: the sites and the checked crust built from them, with the
/// reports of each stage.
struct Attempt {
    sites: Vec<[f64; 3]>,
    labels: Vec<bool>,
    num_projected: usize,
    polish: Option<soft_voronoi::PolishReport>,
    num_relabelled: usize,
    guard: Option<crate::guard::GuardReport>,
    carving: Option<crate::carve::CarveReport>,
    pruning: Option<PruneReport>,
    checked: CheckedCrust,
}

/// An attempt's sites after its polish, before the crust stage.
struct Polished {
    sites: Vec<[f64; 3]>,
    labels: Vec<bool>,
    num_projected: usize,
    polish: Option<soft_voronoi::PolishReport>,
}

/// What the aligned attempt running beside the plain one shares with it: its polish's
/// progress (for the bar), a stop asked for on the plain side, and the plain crust's first
/// measurement (its carving's gate).
#[derive(Default)]
struct Beside {
    stop: AtomicBool,
    polished: AtomicBool,
    done: AtomicUsize,
    loss_bits: AtomicU64,
    gate: GateSlot,
}

/// Stops the aligned attempt and releases it from its wait for the gate when dropped.
struct Release<'a>(&'a Beside);

impl Drop for Release<'_> {
    fn drop(&mut self) {
        self.0.stop.store(true, Ordering::Relaxed);
        self.0.gate.publish(None);
    }
}

/// The aligned attempt's outcome ([`AfterTraining::aligned_beside`]): its attempt (or why
/// there is none), its metrics, its own seconds per stage and its wall seconds.
struct Side {
    result: Result<Result<Attempt, SurfaceBar>, FitError>,
    metrics: Option<MetricsReport>,
    timings: Timings,
    seconds: f64,
}

/// The gate of carving ([`crate::carve::carve_with`]'s `first_surface`): called with the
/// uncarved crust's figures, returns the bar to stop under.
type Gate<'a> = &'a (dyn Fn(SurfaceBar) -> Option<SurfaceBar> + Sync);

/// No gate: carving runs its rounds.
const NO_GATE: Gate<'static> = &|_| None;

/// The plain crust's uncarved figures, handed to the aligned attempt beside it: set once
/// (the first carving's round 0, or `None` when the plain attempt ended without one),
/// waited for by the aligned attempt's carving.
#[derive(Default)]
struct GateSlot {
    value: Mutex<Option<Option<SurfaceBar>>>,
    ready: std::sync::Condvar,
}

impl GateSlot {
    /// Sets the value unless it is set.
    fn publish(&self, bar: Option<SurfaceBar>) {
        let mut v = self.value.lock().unwrap_or_else(|e| e.into_inner());
        if v.is_none() {
            *v = Some(bar);
            self.ready.notify_all();
        }
    }

    /// The value, once set.
    fn wait(&self) -> Option<SurfaceBar> {
        let mut v = self.value.lock().unwrap_or_else(|e| e.into_inner());
        loop {
            if let Some(bar) = *v {
                return bar;
            }
            v = self.ready.wait(v).unwrap_or_else(|e| e.into_inner());
        }
    }
}

impl Beside {
    /// Records a finished step; `false` once a stop was asked for.
    fn step(&self, done: usize, loss: f64) -> bool {
        self.done.store(done, Ordering::Relaxed);
        self.loss_bits.store(loss.to_bits(), Ordering::Relaxed);
        !self.stop.load(Ordering::Relaxed)
    }

    fn loss(&self) -> f64 {
        f64::from_bits(self.loss_bits.load(Ordering::Relaxed))
    }
}

/// Hausdorff (certified upper end), Chamfer L1, F-score and normal consistency of a
/// measured crust; `None` when the metrics failed.
fn scores(m: &MetricsReport) -> Option<PolishScores> {
    match m {
        MetricsReport::Done(m) => Some(PolishScores {
            hausdorff: m.hausdorff.hi,
            hausdorff_lo: m.hausdorff.lo,
            chamfer_l1: m.surface.chamfer_l1,
            fscore: m.surface.fscore,
            normal_consistency: m.surface.normal_consistency,
            fscore_tau: m.surface.fscore_tau,
        }),
        _ => None,
    }
}

/// The rule by which the default keeps the aligned polish's crust over the plain one's: at
/// least as good on all four metrics against the input (certified Hausdorff distance,
/// Chamfer L1, F-score, normal consistency) and better on one, with Hausdorff distances
/// both within the F-score's τ or with overlapping certified intervals counted as equal
/// ([`PolishScores::no_worse_and_better_than`]). Why a rule and not one or
/// the other: the term lines the pairs up, which helps the normals of smooth shapes
/// (libigl's 18 closed meshes: normal consistency better on all 18) but moves the Hausdorff
/// distance either way (featuretype 0.33 → 0.65%, the Menger sponge 1.92 → 2.71%), and
/// neither the input's curvature nor a crease mask told in advance which (README, *Lined-up
/// pairs*). Measured on the crust as written, so the kept crust is never worse than the
/// plain one on any of the four, but for a Hausdorff distance that stays within τ or
/// within the certificate's resolution.
fn choose_alignment(
    plain_report: &MetricsReport,
    aligned: Option<&MetricsReport>,
    aligned_error: Option<String>,
) -> PolishChoice {
    let plain = scores(plain_report);
    let aligned_scores = aligned.and_then(scores);
    let aligned_kept = match (&plain, &aligned_scores) {
        (Some(a), Some(b)) => b.no_worse_and_better_than(a),
        _ => false,
    };
    let diagonal = match plain_report {
        MetricsReport::Done(m) => m.reference_diagonal,
        _ => f64::NAN,
    };
    PolishChoice {
        plain,
        aligned: aligned_scores,
        aligned_error,
        before_carving: None,
        aligned_kept,
        diagonal,
        seconds: 0.0,
    }
}

/// Seconds since the last lap.
struct Lap(Instant);

impl Lap {
    fn start() -> Self {
        Lap(Instant::now())
    }

    fn lap(&mut self) -> f64 {
        let s = self.0.elapsed().as_secs_f64();
        self.0 = Instant::now();
        s
    }
}

/// Stage timer: the time since the last lap, and the report's per-stage timings.
struct Clock {
    t: Lap,
    timings: Timings,
}

impl Clock {
    fn new() -> Self {
        Clock { t: Lap::start(), timings: Timings::default() }
    }

    /// Seconds since the last lap.
    fn lap(&mut self) -> f64 {
        self.t.lap()
    }
}

/// Fits `config.train.num_sites` labelled sites to `input` and returns them with their
/// checked crust and the report. Reproducible from the seed, bit for bit on any thread
/// count; with `config.checkpointing` the optimiser's state is saved as it goes, and
/// `config.resume` continues a saved run exactly.
///
/// - `input`: #V×3 f64 positions and #F×3 u32 triangles in any frame and unit; unreferenced
///   vertices are ignored.
///
/// # Errors
/// [`FitError::Mesh`] for unusable meshes (no triangles, no extent, no area, nothing
/// inside), [`FitError::Settings`] and the like for settings (all with
/// [`FitError::is_input_fault`]); [`FitError::Interrupted`] when `progress` asked to stop
/// (after the checkpoint is written); another variant for what failed otherwise.
///
/// Under `--solid auto`, a winding-number solid whose parts are all thinner than the sites'
/// spacing leaves no site inside after training (an empty crust); the fit then runs again
/// as a thin shell around the surface, and the report's `solid.chosen_by` says so.
///
/// With `config.sampling.fill_holes` (the default), an open input's planar holes are closed
/// flat before the winding-number solid is built ([`mesh_io::fill_planar_holes`]; the
/// report's `solid.holes_filled`), never for a thin shell.
pub fn fit(input: &TriMesh, config: &FitConfig, progress: &mut dyn Progress) -> Result<FitOutput, FitError> {
    match fit_holes(input, config, progress) {
        Err(FitError::Mesh { fault: MeshFault::NoSiteInside, .. }) if config.sampling.solid == SolidRule::Auto => {
            let mut shell = config.clone();
            shell.sampling.solid = SolidRule::Shell;
            let mut out = fit_holes(input, &shell, progress)?;
            out.report.solid.chosen_by = CHOSEN_AFTER_EMPTY_WINDING;
            Ok(out)
        }
        r => r,
    }
}

/// One fit with the solid rule as configured, the input's planar holes filled as
/// configured; should `--solid auto` take a thin shell for the filled mesh (still open and
/// a sheet beside most of its surface), the fit starts again without the fills: a thin
/// shell's surface is the input as it is.
fn fit_holes(input: &TriMesh, config: &FitConfig, progress: &mut dyn Progress) -> Result<FitOutput, FitError> {
    if let Some(out) = fit_once(input, config, progress)? {
        return Ok(out);
    }
    let mut open = config.clone();
    open.sampling.fill_holes = false;
    fit_once(input, &open, progress)?.ok_or(FitError::Internal("a fit without fills asked to run again without them"))
}

/// One fit with the solid rule as configured ([`fit`] adds the fallback to a thin shell);
/// `None` when a thin shell was chosen for a mesh whose holes were filled ([`fit_holes`]).
fn fit_once(input: &TriMesh, config: &FitConfig, progress: &mut dyn Progress) -> Result<Option<FitOutput>, FitError> {
    let t_all = Instant::now();
    config.validate()?;
    let mut clock = Clock::new();

    progress.stage(Stage::Load);
    let p = prepare(input, config)?;
    clock.timings.load = clock.lap();
    progress.stage(Stage::Oracle);
    let (oracle, sampler) = oracle_and_sampler(&p.unit, &config.sampling.mesh)?;
    clock.timings.oracle = clock.lap();

    progress.stage(Stage::Sample);
    let diagonal = p.unit.diagonal();
    // Where the flood solid may be chosen, the pool is labelled once the solid is known.
    let flood_candidate = match config.sampling.solid {
        SolidRule::Flood => true,
        SolidRule::Auto => !p.closed,
        _ => false,
    };
    let (mut data, num_uniform, train_sigmas) = training_pool(&sampler, &oracle, config, diagonal, !flood_candidate)?;
    let (target, solid_report) = target::choose(
        &oracle,
        &p.unit,
        &sampler,
        &mut data,
        num_uniform,
        config,
        diagonal,
        p.transform.scale,
        p.closed,
    )?;
    let filled = p.holes.as_ref().is_some_and(|h| h.loops_filled > 0);
    if filled && target.places_sites() {
        return Ok(None);
    }
    let mut solid_report = solid_report;
    solid_report.holes_filled = p.holes.clone();
    clock.timings.sample = clock.lap();
    // A thin shell's sites are kept as constructed unless asked for (`train_shell`).
    let untrained;
    let config = if target.places_sites() && !config.train_shell {
        untrained =
            FitConfig { train: soft_voronoi::TrainConfig { steps: 0, ..config.train.clone() }, ..config.clone() };
        &untrained
    } else {
        config
    };

    progress.stage(Stage::Train);
    let (initial, refined_share) = initial_sites(&target, config, &p, &oracle, &sampler, &data)?;
    let trainer = train(&data, target.solid(), initial, config, progress)?;
    clock.timings.train = clock.lap();

    let after = AfterTraining {
        config,
        p: &p,
        oracle: &oracle,
        data: &data,
        target: &target,
        trainer: &trainer,
        cap_samples: solid_report.cap_samples,
        diagonal,
        parts: Default::default(),
    };
    let (chosen, measured, polish_choice) = after.polish_and_crust(progress, &mut clock)?;
    let crust_mesh = chosen.checked.written.mesh.clone();
    clock.timings.crust += clock.lap();
    clock.timings.crust_parts = *after.parts.lock().unwrap_or_else(|e| e.into_inner());

    progress.stage(Stage::Evaluate);
    let quality = misclassification(&sampler, target.solid(), &chosen.sites, &chosen.labels, config, diagonal)?;
    clock.timings.evaluate = clock.lap();

    progress.stage(Stage::Metrics);
    let metrics = match measured {
        _ if config.skip_metrics => MetricsReport::Skipped { skipped: "not asked for".into() },
        Some(m) => m,
        None => after.measure(&crust_mesh),
    };
    clock.timings.metrics += clock.lap();

    let state = trainer.state().clone();
    let Attempt { sites, labels, num_projected, polish, num_relabelled, guard, carving, pruning, checked } = chosen;
    let input_block = input_report(input, &config.sampling.mesh, &p);
    let crust_block = crust_report(&checked, &crust_mesh, num_projected);
    let topology = topology_check(&input_block, &solid_report, &p, &crust_block);
    let report = FitReport {
        format_version: 1,
        input: input_block,
        settings: settings_report(&state, config, train_sigmas),
        solid: solid_report,
        transform: TransformReport { center: p.transform.center, scale: p.transform.scale },
        timings_seconds: clock.timings,
        losses: LossesReport::of(&state),
        quality,
        metrics,
        crust: crust_block,
        refined_share,
        polish,
        polish_choice,
        relabelled_sites: config.relabel.then_some(num_relabelled),
        carving,
        guard,
        pruning,
        accuracy_target: None,
        iou_reference: Some(target.iou_reference()),
        topology,
        outputs: OutputsReport::default(),
        total_seconds: t_all.elapsed().as_secs_f64(),
    };
    let sites = SitesFile { sites, inside: labels, transform: p.transform.from_unit_matrix() };
    Ok(Some(FitOutput { sites, crust: crust_mesh, state, report }))
}

/// The occupancy oracle and the surface sampler of the mesh in the unit cube (`name` for
/// messages).
fn oracle_and_sampler(unit: &TriMesh, name: &str) -> Result<(MeshOracle, SurfaceSampler), FitError> {
    let oracle = MeshOracle::from_mesh(unit, &occupancy::Config::default())
        .map_err(|e| FitError::Mesh { mesh: name.to_string(), fault: MeshFault::Oracle(e) })?;
    let sampler = SurfaceSampler::from_mesh(unit)
        .map_err(|e| FitError::Mesh { mesh: name.to_string(), fault: MeshFault::NoArea(e) })?;
    Ok((oracle, sampler))
}

/// The training pool, labelled by the winding-number solid when `label` (else left for
/// `target::choose`), where its near-surface part starts, and its spreads in unit-cube
/// lengths.
fn training_pool(
    sampler: &SurfaceSampler,
    oracle: &MeshOracle,
    config: &FitConfig,
    diagonal: f64,
    label: bool,
) -> Result<(TrainingData, usize, Vec<f64>), FitError> {
    let s = &config.sampling;
    let winding = MeshSolid { oracle };
    let train_sigmas: Vec<f64> = s.sigmas.iter().map(|x| x * diagonal).collect();
    let solid: Option<&dyn Solid> = if label { Some(&winding) } else { None };
    let (data, num_uniform) = labelled_samples(sampler, solid, s.samples, &train_sigmas, s.seed)?;
    Ok((data, num_uniform, train_sigmas))
}

/// The sites training starts from when not `config.train.init`'s: the thin shell's own, or
/// pairs refined where a previous crust missed (the accuracy target's rounds), with the
/// share of candidates refined.
type InitialSites = (Option<(Vec<[f64; 3]>, Vec<bool>)>, Option<f64>);

/// See [`InitialSites`].
fn initial_sites(
    target: &target::Target,
    config: &FitConfig,
    p: &Prepared,
    oracle: &MeshOracle,
    sampler: &SurfaceSampler,
    data: &TrainingData,
) -> Result<InitialSites, FitError> {
    Ok(match (target.initial_sites(), &config.refine) {
        (Some(initial), _) => (Some(initial), None),
        (None, Some(r)) if config.train.init == soft_voronoi::Init::Pairs && config.resume.is_none() => {
            let area = sampler.total_area();
            let (sites, labels, share) =
                crate::refine::refined_pairs(r, &p.transform, oracle, area, data, target.solid(), config)?;
            (Some((sites, labels)), Some(share))
        }
        _ => (None, None),
    })
}

/// What the stages after training share: the trained sites and everything they were
/// trained on.
struct AfterTraining<'a> {
    config: &'a FitConfig,
    p: &'a Prepared,
    oracle: &'a MeshOracle,
    data: &'a TrainingData,
    target: &'a target::Target<'a>,
    trainer: &'a Trainer<'a>,
    /// Surface samples on the winding solid's caps (at the end of `data.surface`).
    cap_samples: usize,
    diagonal: f64,
    /// Seconds of the crust stage's parts, summed over attempts (which may run side by side).
    parts: Mutex<CrustParts>,
}

impl AfterTraining<'_> {
    /// The metrics of a crust against the input (the crust was checked when it was built,
    /// so its validity is not recomputed).
    fn measure(&self, crust: &TriMesh) -> MetricsReport {
        let opts = metrics::EvalOptions { skip_validity: true, iou_samples: Some(0), ..Default::default() };
        let seed = opts.surface.seed.wrapping_add(2);
        // Interior faces are told apart by the solid fitted, in the unit cube (on a soup the
        // raw input's winding number is ambiguous beside every single-sided panel and its
        // exact fallback costs minutes).
        let t = &self.p.transform;
        let eps = metrics::BURIED_OFFSET * self.diagonal;
        let interior = |points: &[[f64; 3]], normals: &[[f64; 3]]| {
            let unit: Vec<[f64; 3]> = points.iter().map(|&x| t.to_unit(x)).collect();
            let sign = t.scale.signum();
            let normals: Vec<[f64; 3]> = normals.iter().map(|n| n.map(|c| sign * c)).collect();
            Ok(self.target.buried(&unit, &normals, eps))
        };
        let measured = metrics::evaluate_with(&self.p.mesh, crust, &opts, (self.target.interior_by(), interior))
            .and_then(|mut m| {
                m.iou = Some(self.iou_against_the_solid(crust, IOU_SAMPLES, seed)?);
                Ok(m)
            });
        match measured {
            Ok(m) => MetricsReport::Done(Box::new(m)),
            Err(e) => MetricsReport::Failed { error: e.to_string() },
        }
    }

    /// IoU of the crust against the solid the sites were fitted to (the reoriented input's
    /// winding-number solid, the flood solid or the thin shell: [`target::Target::solid`],
    /// named in the report's `iou_reference`), on `n` points uniform in the union of the
    /// two boxes in the unit cube; the crust's side by its own oracle.
    fn iou_against_the_solid(
        &self,
        crust: &TriMesh,
        n: usize,
        seed: u64,
    ) -> Result<metrics::IouResult, metrics::MetricsError> {
        let unit = self.p.transform.mesh_to_unit(crust);
        let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default())?;
        let ((l1, h1), (l2, h2)) = (self.oracle.bounding_box(), oracle.bounding_box());
        let lo = [0, 1, 2].map(|k| l1[k].min(l2[k]));
        let hi = [0, 1, 2].map(|k| h1[k].max(h2[k]));
        let points = occupancy::sample::uniform_in_box(lo, hi, n, seed)?;
        let prediction = oracle.inside(&points)?;
        let reference = self.target.solid().inside(&points);
        Ok(metrics::iou_of_labels(&reference, &prediction))
    }

    /// Everything from the polish on, once or twice: returns the attempt kept, its metrics
    /// when the choice measured them, and the choice.
    ///
    /// The polish's alignment term lines pairs up, and lined-up pairs are nearly
    /// cospherical: their crust has Voronoi vertices that nearly coincide. Should the crust
    /// then not survive rounding to the output's precision, everything from the polish on
    /// runs again without the term (the report's `polish.alignment_dropped`). Asked for with
    /// `--polish-align W`; by default on a closed input both crusts are built and the
    /// aligned one is kept only where it is at least as good on all four metrics against
    /// the input ([`choose_alignment`]).
    fn polish_and_crust(
        &self,
        progress: &mut dyn Progress,
        clock: &mut Clock,
    ) -> Result<(Attempt, Option<MetricsReport>, Option<PolishChoice>), FitError> {
        let config = self.config;
        let forced = config.polish.as_ref().is_some_and(|pc| pc.alignment.is_some());
        let tries = config.try_alignment.is_some()
            && !forced
            && config.polish.is_some()
            && !self.target.places_sites()
            && self.p.closed;
        // No gate is passed here, so every attempt below ends with a crust.
        let done = |a: Result<Attempt, SurfaceBar>| a.map_err(|_| FitError::Internal("carving stopped without a gate"));
        if tries {
            return self.plain_beside_aligned(progress, clock);
        }
        let plain = if forced {
            match self.attempt(true, NO_GATE, progress, clock, None) {
                Err(e) if e.is_input_fault() => {
                    let mut a = done(self.attempt(false, NO_GATE, progress, clock, None)?)?;
                    if let Some(pr) = a.polish.as_mut() {
                        pr.alignment_dropped = Some(e.to_string());
                    }
                    a
                }
                other => done(other?)?,
            }
        } else {
            done(self.attempt(false, NO_GATE, progress, clock, None)?)?
        };
        Ok((plain, None, None))
    }

    /// The default on a closed input: the plain attempt (polish, crust, metrics) on this
    /// thread and the aligned one (polish, crust, metrics) on another beside it, then the
    /// choice between the two ([`choose_alignment`]).
    ///
    /// The attempts share nothing but the trained sites and one figure: the aligned crust's
    /// carving stops before its first round where its uncarved crust falls short of the
    /// plain one's Chamfer distance or normal consistency, and waits for the plain one's
    /// first measurement to know ([`GateSlot`]). A polish's result does not depend on the
    /// threads that run it, so this is the serial order's result to the bit, while the
    /// serial parts of one attempt (the crust's extraction and checks) run beside the other's.
    /// The aligned attempt's parallel parts run in rayon's global pool.
    fn plain_beside_aligned(
        &self,
        progress: &mut dyn Progress,
        clock: &mut Clock,
    ) -> Result<(Attempt, Option<MetricsReport>, Option<PolishChoice>), FitError> {
        let pc = self.polish_config(true).ok_or(FitError::Internal("no polish to align"))?;
        let beside = Beside::default();
        let (plain, plain_metrics, side) = std::thread::scope(|scope| {
            let side = scope.spawn(|| self.aligned_beside(&pc, &beside));
            let publish = |bar: SurfaceBar| {
                beside.gate.publish(Some(bar));
                None
            };
            // Should this thread unwind (a panic), the aligned attempt is stopped and released
            // from its wait for the gate, so that the scope's join can end.
            let release = Release(&beside);
            let plain = self.attempt(false, &publish, progress, clock, Some(&beside.stop));
            // Whatever happened, the aligned attempt no longer waits for a gate.
            beside.gate.publish(None);
            let plain = match plain {
                Ok(Ok(a)) => a,
                other => {
                    drop(release);
                    return Err(match other {
                        Err(e) => e,
                        Ok(_) => FitError::Internal("carving stopped without a gate"),
                    });
                }
            };
            progress.stage(Stage::Metrics);
            let plain_metrics = self.measure(&plain.checked.written.mesh);
            clock.timings.metrics += clock.lap();
            // What is left of the aligned attempt, its polish's progress shown and a stop
            // passed on.
            let mut shown = None;
            while !side.is_finished() {
                let polishing = !beside.polished.load(Ordering::Acquire);
                let stage = if polishing { Stage::Polish } else { Stage::Crust };
                if shown != Some(stage) {
                    progress.stage(stage);
                    shown = Some(stage);
                }
                if polishing {
                    progress.polish_step(beside.done.load(Ordering::Relaxed), pc.steps, beside.loss());
                }
                if progress.should_stop() {
                    beside.stop.store(true, Ordering::Relaxed);
                }
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            // The wait: the aligned attempt's own seconds are added below instead.
            clock.lap();
            drop(release); // the aligned attempt has finished: nothing left to stop
            let side = side.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            Ok((plain, plain_metrics, side))
        })?;
        let Side { result, metrics: aligned_metrics, timings, seconds } = side;
        clock.timings.polish += timings.polish;
        clock.timings.crust += timings.crust;
        clock.timings.metrics += timings.metrics;
        let (aligned, aligned_error, stopped) = match result {
            Ok(Ok(a)) => (Some(a), None, None),
            Ok(Err(bar)) => (None, None, Some(bar)),
            Err(FitError::StoppedPolish { step, steps }) => return Err(self.stopped(step, steps)),
            Err(e) if e.is_input_fault() => (None, Some(e.to_string()), None),
            Err(e) => return Err(e),
        };
        let gate = beside.gate.wait();
        let mut c = choose_alignment(&plain_metrics, aligned_metrics.as_ref(), aligned_error);
        c.before_carving = stopped.map(|aligned| BeforeCarving { plain: gate.unwrap_or_default(), aligned });
        let kept = c.aligned_kept;
        let choice = Some(PolishChoice { seconds, ..c });
        match (kept, aligned, aligned_metrics) {
            (true, Some(a), Some(m)) => Ok((a, Some(m), choice)),
            _ => Ok((plain, Some(plain_metrics), choice)),
        }
    }

    /// The aligned attempt beside the plain one ([`Self::plain_beside_aligned`]): its polish,
    /// its crust (carving gated by the plain crust's first measurement, which it waits for)
    /// and its metrics, with its own seconds per stage. A stop asked for on the plain side
    /// stops its polish ([`FitError::StoppedPolish`]) and skips its crust.
    fn aligned_beside(&self, pc: &soft_voronoi::PolishConfig, beside: &Beside) -> Side {
        let t = Instant::now();
        let mut clock = Clock::new();
        let (mut sites, labels, num_projected) = self.trainer.final_sites();
        let polish = self.run_polish(&mut sites, &labels, pc, |done, _, loss| beside.step(done, loss));
        clock.timings.polish += clock.lap();
        beside.polished.store(true, Ordering::Release);
        let stopped = |step| FitError::StoppedPolish { step, steps: pc.steps };
        let result = match polish {
            Err(e) => Err(FitError::Polish(e)),
            Ok(report) if report.steps < pc.steps => Err(stopped(report.steps)),
            Ok(_) if beside.stop.load(Ordering::Relaxed) => Err(stopped(pc.steps)),
            Ok(report) => {
                // Carving hardly moves a crust's Chamfer distance and normal consistency (it
                // works where the Hausdorff distance is set), and the choice asks for both to
                // be no worse: an aligned crust short of the plain one's on either before
                // carving stops there, which spares its carving (on the Menger sponge, 7 of 8
                // rounds' worth of seconds).
                let polished = Polished { sites, labels, num_projected, polish: Some(report) };
                self.crust_of_polished(polished, &|_| beside.gate.wait(), &mut NoProgress, &mut clock)
            }
        };
        let metrics = match &result {
            Ok(Ok(a)) => Some(self.measure(&a.checked.written.mesh)),
            _ => None,
        };
        clock.timings.metrics += clock.lap();
        Side { result, metrics, timings: clock.timings, seconds: t.elapsed().as_secs_f64() }
    }

    /// Everything from the polish on, with or without the polish's alignment term.
    /// `gate`: called with the uncarved crust's Chamfer distance and normal consistency, it
    /// returns the bar they must reach: where they do not, carving stops before its first
    /// round and the attempt ends with them (`Ok(Err(_))`); [`NO_GATE`] for none.
    /// `also_stop` is set when `progress` asks the polish to stop.
    fn attempt(
        &self,
        aligned: bool,
        gate: Gate,
        progress: &mut dyn Progress,
        clock: &mut Clock,
        also_stop: Option<&AtomicBool>,
    ) -> Result<Result<Attempt, SurfaceBar>, FitError> {
        progress.stage(Stage::Polish);
        let (mut sites, labels, num_projected) = self.trainer.final_sites();
        let polish = self.polish(&mut sites, &labels, aligned, progress, also_stop)?;
        clock.timings.polish += clock.lap();
        self.crust_of_polished(Polished { sites, labels, num_projected, polish }, gate, progress, clock)
    }

    /// The crust stage of an attempt: relabelling, guards, carving, pruning and the written
    /// crust, from the polished sites; `gate` as in [`Self::attempt`].
    fn crust_of_polished(
        &self,
        polished: Polished,
        gate: Gate,
        progress: &mut dyn Progress,
        clock: &mut Clock,
    ) -> Result<Result<Attempt, SurfaceBar>, FitError> {
        let config = self.config;
        let Polished { sites, mut labels, num_projected, polish } = polished;
        progress.stage(Stage::Crust);
        let num_relabelled = if config.relabel {
            relabel(&sites, &mut labels, self.trainer.config().num_sites, self.target.solid())
        } else {
            0
        };
        if !labels.iter().any(|&inside| inside) {
            // An empty crust: nothing to carve or measure (see `fit`'s fallback).
            return Err(FitError::Mesh { mesh: config.sampling.mesh.clone(), fault: MeshFault::NoSiteInside });
        }
        let carved = self.carve_and_crust(sites, labels, gate);
        clock.timings.crust += clock.lap();
        Ok(carved?.map(|(sites, labels, guard, carving, pruning, checked)| Attempt {
            sites,
            labels,
            num_projected,
            polish,
            num_relabelled,
            guard,
            carving,
            pruning,
            checked,
        }))
    }

    /// The polish of one attempt (none on a thin shell, whose sites are placed on the
    /// shell's sides, not on the sampled surface).
    fn polish(
        &self,
        sites: &mut [[f64; 3]],
        labels: &[bool],
        aligned: bool,
        progress: &mut dyn Progress,
        also_stop: Option<&AtomicBool>,
    ) -> Result<Option<soft_voronoi::PolishReport>, FitError> {
        let Some(pc) = self.polish_config(aligned) else { return Ok(None) };
        let mut stopped = false;
        let report = self
            .run_polish(sites, labels, &pc, |done, total, loss| {
                progress.polish_step(done, total, loss);
                stopped = progress.should_stop() && done < total;
                if let (true, Some(flag)) = (stopped, also_stop) {
                    flag.store(true, Ordering::Relaxed);
                }
                !stopped
            })
            .map_err(FitError::Polish)?;
        if stopped {
            return Err(self.stopped(report.steps, pc.steps));
        }
        Ok(Some(report))
    }

    /// [`soft_voronoi::polish::polish`] of the trainable sites among `sites` onto the surface
    /// samples, with `labels` and the samples' normals for the alignment term;
    /// `on_step(done, total, loss)` returns `false` to stop.
    fn run_polish(
        &self,
        sites: &mut [[f64; 3]],
        labels: &[bool],
        pc: &soft_voronoi::PolishConfig,
        on_step: impl FnMut(usize, usize, f64) -> bool,
    ) -> Result<soft_voronoi::PolishReport, soft_voronoi::TrainError> {
        let (data, k) = (self.data, self.trainer.config().num_sites);
        soft_voronoi::polish::polish(sites, k, &data.surface, Some((labels, &data.normals)), pc, on_step)
    }

    /// The settings of an attempt's polish, with or without the alignment term; `None` where
    /// there is none (no polish asked for, or a thin shell: its sites are placed on the
    /// shell's sides, not on the sampled surface).
    fn polish_config(&self, aligned: bool) -> Option<soft_voronoi::PolishConfig> {
        let config = self.config;
        let data = self.data;
        match &config.polish {
            Some(pc) if !self.target.places_sites() => {
                // Cap samples add to each batch instead of taking from the input's share, so the
                // input's faces are pulled as often as without caps; at most twice the batch,
                // which bounds the polish's time where the caps outweigh the input (an open
                // pipe's lids; libigl's halftunnel, caps a third of the crust, takes 1.4 times).
                let mut pc = pc.clone();
                let input = data.surface.len().saturating_sub(self.cap_samples).max(1);
                pc.batch = pc.batch * data.surface.len().min(2 * input) / input;
                pc.alignment =
                    if aligned { pc.alignment.clone().or_else(|| config.try_alignment.clone()) } else { None };
                Some(pc)
            }
            _ => None,
        }
    }

    /// The error of a polish stopped at `step` of `steps` on request: with checkpointing,
    /// the finished training's checkpoint is written (a resume redoes only the polish).
    fn stopped(&self, step: usize, steps: usize) -> FitError {
        let config = self.config;
        let Some(c) = &config.checkpointing else { return FitError::StoppedPolish { step, steps } };
        let trainer = self.trainer;
        let written = config.checkpoint_context().and_then(|context| {
            checkpoint::write(&c.path, trainer.state(), &context)
                .map_err(|source| FitError::CheckpointWrite { path: c.path.clone(), source })
        });
        match written {
            Ok(()) => {
                let steps = trainer.config().steps;
                FitError::Interrupted { step: steps, steps, checkpoint: c.path.clone() }
            }
            Err(e) => e,
        }
    }

    /// The guard, carving, pruning and the checked crust of relabelled sites; `Ok(Err(_))`
    /// when carving's gate stopped it (`gate`: [`crate::carve::carve_with`]'s `first_surface`).
    fn carve_and_crust(
        &self,
        mut sites: Vec<[f64; 3]>,
        mut labels: Vec<bool>,
        gate: Gate,
    ) -> Result<Result<Carved, SurfaceBar>, FitError> {
        let config = self.config;
        let places_sites = self.target.places_sites();
        // Not on a thin shell kept as constructed: its sides are the triplets' bisectors
        // already, and a carving pair (offset 0.3% of the diagonal) across a band thinner than
        // that has both sites outside and punches a hole in it (libigl's lilium at a
        // half-thickness of 0.24%: genus 0 → 260). At the default band no round was kept.
        let carve = if places_sites && !config.train_shell { None } else { config.carve };
        // With carving: no crust outside the input's bounding box (not on a thin shell, whose
        // solid reaches past the surface by its half-thickness). The guard runs before carving,
        // so that carving judges the crust as it will be written (a farthest crust vertex past
        // the box is the guard's to cut: on the thin plate at K = 8,192 a round that traded
        // one for a dent was kept, Hausdorff 0.25 → 0.36%), and again after carving's kept
        // rounds, whose cells may run past the box.
        let guard_box = match config.carve {
            Some(c) if !places_sites => {
                let (lo, hi) = self.p.unit.bounding_box();
                Some((lo, hi, c * self.diagonal))
            }
            _ => None,
        };
        // The report's `crust_parts`: seconds since the last lap added to one of them.
        let mut t = Lap::start();
        let mut add = |part: fn(&mut CrustParts) -> &mut f64| {
            *part(&mut self.parts.lock().unwrap_or_else(|e| e.into_inner())) += t.lap();
        };
        // The guard's last crust is of the sites as it leaves them: carving's first round
        // measures it instead of extracting it again, unless the solid guard below adds
        // sites (the first carving only: a retry extracts its own).
        let (mut guard, mut extracted) = match guard_box {
            Some((lo, hi, threshold)) => {
                let (g, crust) = crate::guard::guard_keeping(&mut sites, &mut labels, lo, hi, threshold)?;
                (Some(g), Some(crust))
            }
            None => (None, None),
        };
        // A thin shell kept as constructed gets the solid guard alone (its band reaches past
        // the box by its half-thickness): where the sheet bends sharper than the triplets'
        // spacing (a terrain's peaks) an inside cell runs out of the band.
        let shell_guard = match (config.carve, self.target) {
            (Some(c), crate::target::Target::Shell(..)) if !config.train_shell => Some(c * self.diagonal),
            _ => None,
        };
        if let (None, Some(threshold)) = (guard.as_ref(), shell_guard) {
            let (box_lo, box_hi) = self.p.unit.bounding_box();
            guard = Some(crate::guard::GuardReport { box_lo, box_hi, threshold, ..Default::default() });
        }
        let solid_threshold = guard_box.map(|g| g.2).or(shell_guard);
        // On the flood solid and the thin shell above, the same cut across the solid's own
        // surface where the crust stands outside it (`guard::guard_solid`: the ModelNet
        // airplane's wing fins, 6.5% of the diagonal off the input; a terrain's peaks). Not on
        // the winding solid: measured there, it changed nothing beyond noise but menger, which
        // it made worse (docs/main-job.md).
        let guarded: Option<&dyn soft_voronoi::Solid> = match self.target {
            crate::target::Target::Flood(solid) => Some(solid),
            crate::target::Target::Shell(solid, ..) => Some(solid),
            crate::target::Target::Winding(_) => None,
        };
        let mut before_solid_guard = match (guard.as_mut(), solid_threshold, guarded) {
            (Some(g), Some(threshold), Some(solid)) => {
                let before = (sites.clone(), labels.clone(), Some(g.clone()));
                let (per_round, from, to) = crate::guard::guard_solid(
                    &mut sites,
                    &mut labels,
                    solid,
                    threshold,
                    crate::guard::SOLID_GUARD_ROUNDS,
                )?;
                let added = per_round.iter().sum::<usize>() > 0;
                (g.solid_mirrors_per_round, g.solid_beyond_before, g.solid_beyond_after) = (per_round, from, to);
                if added {
                    extracted = None;
                }
                added.then_some(before)
            }
            _ => None,
        };
        add(|p| &mut p.guard);
        // Carving's mirrors can leave Voronoi features finer than the output's precision holds
        // (on snowden, a thin-walled shell, at K = 8,192: float32 rounding broke the crust
        // beyond repair); then carving runs again from the same sites without them, and
        // should that fail too, without the solid guard's mirrors.
        let mut before_carving = carve.map(|_| (sites.clone(), labels.clone(), guard.clone()));
        let mut mirrors = true;
        let mut dropped = None;
        loop {
            let carving = match carve {
                Some(c) => {
                    let k = self.trainer.config().num_sites;
                    let tolerance = c * self.diagonal;
                    let winding = matches!(self.target, crate::target::Target::Winding(_));
                    let peels = crate::carve::peels_for(winding, &self.p.unit);
                    let options = crate::carve::CarveOptions {
                        mirrors,
                        peels,
                        ..crate::carve::CarveOptions::for_sites(tolerance, k)
                    };
                    let solid = self.target.solid();
                    let (oracle, unit) = (self.oracle, &self.p.unit);
                    let start = crate::carve::Start { crust: extracted.take(), first_surface: gate };
                    let mut r =
                        crate::carve::carve_with(&mut sites, &mut labels, oracle, unit, solid, &options, start)?;
                    r.tolerance_of_diagonal = c;
                    r.mirrors_dropped = dropped.take();
                    Some(r)
                }
                None => None,
            };
            add(|p| &mut p.carve);
            if let Some(r) = carving.as_ref().filter(|r| r.gated) {
                return Ok(Err(r.first_surface));
            }
            if let (Some(g), Some((lo, hi, threshold)), Some(r)) = (guard.as_mut(), guard_box, carving.as_ref()) {
                if !r.inserted_per_round.is_empty() {
                    g.after_carving(crate::guard::guard(&mut sites, &mut labels, lo, hi, threshold)?);
                }
            }
            add(|p| &mut p.guard);
            let pruning = if config.prune { Some(prune(&mut sites, &mut labels)?) } else { None };
            add(|p| &mut p.prune);
            let mirrored = carving.as_ref().is_some_and(|r| r.inserted_as_mirrors_per_round.iter().sum::<usize>() > 0);
            // Mapped by the sites file's own matrix, evaluated as `crust::SitesFile` and
            // `voronoi-fit crust` evaluate it, so the crust of the written sites is this crust
            // to the bit (mapping by centre and scale rounds differently, and a merge of
            // vertices a few float steps apart could then go the other way).
            let map = FrameMap::Matrix(self.p.transform.from_unit_matrix());
            let written = crust_of(&sites, &labels, map, config.output_precision);
            add(|p| &mut p.write);
            match written {
                Ok(checked) => return Ok(Ok((sites, labels, guard, carving, pruning, checked))),
                Err(e) if mirrored && e.is_input_fault() => {
                    let Some((s, l, g)) = before_carving.clone() else { return Err(e) };
                    (sites, labels, guard) = (s, l, g);
                    mirrors = false;
                    dropped = Some(e.to_string());
                }
                Err(e) if e.is_input_fault() && before_solid_guard.is_some() => {
                    let Some((s, l, mut g)) = before_solid_guard.take() else { return Err(e) };
                    if let Some(g) = g.as_mut() {
                        g.solid_mirrors_dropped = Some(e.to_string());
                    }
                    (sites, labels, guard) = (s, l, g);
                    before_carving = carve.map(|_| (sites.clone(), labels.clone(), guard.clone()));
                }
                Err(e) => return Err(e),
            }
        }
    }
}

/// The sites and labels after carving and pruning, with the reports and the checked crust.
type Carved = (
    Vec<[f64; 3]>,
    Vec<bool>,
    Option<crate::guard::GuardReport>,
    Option<crate::carve::CarveReport>,
    Option<PruneReport>,
    CheckedCrust,
);

/// Report field `input`.
fn input_report(input: &TriMesh, name: &str, p: &Prepared) -> InputReport {
    InputReport {
        path: name.to_string(),
        num_vertices: input.positions.len(),
        num_triangles: input.triangles.len(),
        is_closed: p.topology.is_closed,
        is_manifold: p.topology.is_manifold,
        signed_volume: p.topology.signed_volume,
        genus: input_genus(&p.topology, &p.reoriented),
        reoriented: p.reoriented.clone(),
    }
}

/// The genus of a closed, manifold, orientable surface from its Euler characteristic and
/// components (χ = 2C − 2g), whatever its triangles' orientation (the reoriented mesh's is
/// consistent where no piece is non-orientable); `None` for other surfaces.
fn input_genus(t: &TopologyReport, reoriented: &mesh_io::Reorientation) -> Option<i64> {
    let twice = 2 * t.num_components as i64 - t.euler_characteristic;
    (t.is_closed && t.is_manifold && reoriented.non_orientable_pieces == 0 && twice % 2 == 0 && twice >= 0)
        .then_some(twice / 2)
}

/// Report field `topology`: made where the input's genus is the solid's ([`TopologyCheck`]).
fn topology_check(
    input: &InputReport,
    solid: &SolidReport,
    p: &Prepared,
    crust: &CrustReport,
) -> Option<TopologyCheck> {
    let input_genus = input.genus?;
    let crust_genus = crust.genus?;
    let winding = solid.rule == crate::config::SolidRule::Winding;
    let clean = solid.interior_surface_share.is_some_and(|s| s == 0.0);
    (winding && clean && p.holes.is_none())
        .then(|| TopologyCheck::new(input_genus, p.topology.num_components, crust_genus, crust.num_components))
}

/// Report field `settings`.
fn settings_report(state: &TrainState, config: &FitConfig, train_sigmas: Vec<f64>) -> SettingsReport {
    let s = &config.sampling;
    SettingsReport {
        train: state.config.clone(),
        preset: config.preset.clone(),
        samples: s.samples,
        near_surface_sigmas_of_diagonal: s.sigmas.clone(),
        near_surface_sigmas: train_sigmas,
        margin: s.margin,
        eval_samples: config.eval.samples.max(2),
        resumed_from: config.resume.as_ref().map(|r| r.1.clone()),
        threads: rayon::current_num_threads(),
        work_set_by: config.work_set_by.clone(),
    }
}

/// Trains to the end from `initial` sites when given (else `config.train.init`),
/// checkpointing as configured; stops with a checkpoint when
/// `progress` asks.
fn train<'a>(
    data: &'a TrainingData,
    solid: &'a dyn Solid,
    initial: Option<(Vec<[f64; 3]>, Vec<bool>)>,
    config: &FitConfig,
    progress: &mut dyn Progress,
) -> Result<Trainer<'a>, FitError> {
    let input = FitError::TrainStart;
    let mut trainer = match &config.resume {
        Some((state, path)) => Trainer::resume(state.clone(), data, solid, path).map_err(input)?,
        None => match initial {
            Some((sites, labels)) => Trainer::from_sites(config.train.clone(), data, solid, sites, labels),
            None => Trainer::new(config.train.clone(), data, solid),
        }
        .map_err(input)?,
    };
    let context = config.checkpoint_context()?;
    let steps = trainer.config().steps;
    progress.train_start(trainer.state().step, steps);
    while !trainer.is_done() {
        let s = trainer.step().map_err(FitError::Training)?;
        progress.train_step(&s);
        let stop = progress.should_stop();
        if let Some(c) = &config.checkpointing {
            let due = c.every > 0 && (s.step + 1) % c.every == 0;
            if (due || stop) && !trainer.is_done() {
                checkpoint::write(&c.path, trainer.state(), &context)
                    .map_err(|source| FitError::CheckpointWrite { path: c.path.clone(), source })?;
            }
            if stop && !trainer.is_done() {
                progress.train_end();
                return Err(FitError::Interrupted { step: s.step + 1, steps, checkpoint: c.path.clone() });
            }
        } else if stop && !trainer.is_done() {
            progress.train_end();
            return Err(FitError::StoppedTraining { step: s.step + 1, steps });
        }
    }
    progress.train_end();
    Ok(trainer)
}

/// Gives each of the first `k` (trainable) sites the solid's label at its final position and
/// returns how many changed. A site always lies in its own cell, so a site whose label
/// disagrees with the solid where it stands (it crossed the surface while training, or
/// started on the wrong side of a fold) is certainly wrong around itself: it shows as a
/// spike or a pit in the crust.
fn relabel(sites: &[[f64; 3]], labels: &mut [bool], k: usize, solid: &dyn Solid) -> usize {
    let truth = solid.inside(&sites[..k]);
    let mut changed = 0;
    for (l, t) in labels[..k].iter_mut().zip(truth) {
        changed += usize::from(*l != t);
        *l = t;
    }
    changed
}

/// Removes the sites that change neither the crust nor the nearest-site occupancy
/// ([`crust::prune::prune`], up to [`PRUNE_ROUNDS`] rounds).
fn prune(sites: &mut Vec<[f64; 3]>, labels: &mut Vec<bool>) -> Result<PruneReport, FitError> {
    let before = sites.len();
    let r = crust::prune::prune(sites, labels, 0, PRUNE_ROUNDS, &crust::CrustConfig::default())
        .map_err(|source| FitError::Crust { during: "removing the sites that change nothing", source })?;
    Ok(PruneReport { removed_per_round: r.removed_per_round, sites_before: before, sites_after: sites.len() })
}

/// Rounds of [`prune`]: each removes an independent set, about a third fewer than the
/// round before (bunny.ply: 460, 319, 214, 149, 96, 62, 40, 31 of the 1,433 that sixteen
/// rounds remove), at about 0.12 s a round for 8k sites.
pub const PRUNE_ROUNDS: usize = 8;

/// Uniform samples of the report's IoU (as `voronoi-fit eval`'s default).
const IOU_SAMPLES: usize = 100_000;

/// Misclassification of the hard Voronoi occupancy on a fresh pool (another seed stream
/// than training: seed XOR [`vf_common::rng::seed_tweak::EVALUATION`]).
fn misclassification(
    sampler: &SurfaceSampler,
    solid: &dyn Solid,
    sites: &[[f64; 3]],
    labels: &[bool],
    config: &FitConfig,
    diagonal: f64,
) -> Result<QualityReport, FitError> {
    let eval_seed = config.sampling.seed ^ vf_common::rng::seed_tweak::EVALUATION;
    let eval_sigmas: Vec<f64> = config.eval.sigmas.iter().map(|x| x * diagonal).collect();
    let (eval, num_uniform) =
        labelled_samples(sampler, Some(solid), config.eval.samples.max(2), &eval_sigmas, eval_seed)?;
    let predicted = classify(sites, labels, &eval.points);
    let wrong = |r: std::ops::Range<usize>| r.filter(|&i| predicted[i] != eval.occupancy[i]).count();
    let n = eval.points.len();
    let (wrong_u, wrong_n) = (wrong(0..num_uniform), wrong(num_uniform..n));
    // All, uniform, near-surface.
    let counts = [n, num_uniform, n - num_uniform];
    let wrongs = [wrong_u + wrong_n, wrong_u, wrong_n];
    let share = |i: usize| wrongs[i] as f64 / counts[i].max(1) as f64;
    Ok(QualityReport {
        misclassification: share(0),
        misclassification_uniform: share(1),
        misclassification_near_surface: share(2),
        misclassified_counts: wrongs,
        eval_counts: counts,
        misclassification_ci95: [0, 1, 2].map(|i| crate::report::wilson_interval(wrongs[i], counts[i])),
        eval_seed,
        eval_near_surface_sigmas_of_diagonal: config.eval.sigmas.clone(),
        eval_near_surface_sigmas: eval_sigmas,
    })
}

fn crust_report(checked: &CheckedCrust, mesh: &TriMesh, num_projected: usize) -> CrustReport {
    let r = &checked.check().report;
    CrustReport {
        num_sites: checked.crust.stats.num_sites,
        num_inside: checked.crust.stats.num_inside,
        num_sites_projected_into_cube: num_projected,
        num_merged_vertices: checked.crust.stats.num_merged_vertices,
        num_merged_in_output: checked.written.num_merged_vertices,
        num_separated_in_output: checked.written.num_separated_vertices,
        topology_before_rounding: checked.written.topology_before,
        num_vertices: mesh.positions.len(),
        num_triangles: mesh.triangles.len(),
        num_components: r.num_components,
        genus: r.genus,
        is_closed: r.is_closed,
        is_manifold: r.is_manifold,
        self_intersections: 0,
        volume: TopologyReport::of(mesh).signed_volume,
    }
}
