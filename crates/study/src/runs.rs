//! The runs: Voronoi sites at each K (the main job, [`fit::fit`]), OccNet and DeepSDF
//! decoders at each size, each trained to convergence ([`crate::plateau`]) under every
//! seed; and the two reference lines (the K-site construction, the marching-cubes floor).

use std::path::Path;
use std::time::Instant;

use baselines::{DecoderConfig, Mlp, Schedule};
use mesh_io::TriMesh;
use serde::Serialize;

use crate::budget::Budget;
use crate::data::{sphere_data, sphere_mesh};
use crate::measure::{measure, Measured, EVALUATIONS, TOLERANCE};
use crate::plateau::{flattened, Plateau, Verdict};
use crate::{StudyError, SPHERE};

/// One row of results.csv: one run of one method at one size under one seed, or a
/// reference (`construction`, `mc_floor`: no training, seed 0).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// `voronoi`, `occnet`, `deepsdf`, `construction` or `mc_floor`.
    pub method: String,
    /// Parameters (3K for K sites; the floor's row: 0).
    pub params: usize,
    /// Certified Hausdorff interval to the sphere, unit cube.
    pub hausdorff_lo: f64,
    /// Its upper end.
    pub hausdorff_hi: f64,
    /// Chamfer L1 to the sphere.
    pub chamfer: f64,
    /// Training wall time (the Voronoi fits: the main job's training stage).
    pub train_seconds: f64,
    /// Training steps run.
    pub steps: usize,
    /// `K=…`, `W×D` or `res=…`.
    pub size: String,
    /// Seed of the samples and the model.
    pub seed: u64,
    /// Triangles of the surface.
    pub triangles: usize,
    /// Closed and manifold.
    pub watertight: bool,
    /// Last training loss (the Voronoi fits: the total loss).
    pub final_loss: f64,
    /// How training ended: `plateau` (converged by the plateau rule), `capped` (reached
    /// the step cap first), `flattened` (fixed schedule, last windows within 1% or the
    /// noise) or `not flattened`, then which iterate the main job kept, or `-` for
    /// references.
    pub convergence: String,
    /// Wall time of the whole run (sampling, training, surface, measuring).
    pub total_seconds: f64,
}

/// Receives the study's progress.
pub trait StudyProgress {
    /// A run starts (its label, e.g. "Voronoi K = 64, seed 0").
    fn start(&mut self, _label: &str) {}
    /// A run finished; `rows` holds every row so far ([`crate::run_study`] saves them as
    /// it goes).
    fn done(&mut self, _rows: &[Row]) {}
    /// Something the user should know that does not stop the study (results.csv could not
    /// be saved along the way).
    fn warning(&mut self, _message: &str) {}
}

impl StudyProgress for () {}

/// Number of progress units [`run`] reports: the runs plus the references.
pub fn num_units(budget: &Budget) -> usize {
    budget.num_runs() + if budget.references { budget.voronoi_sites.len() + 1 } else { 0 }
}

/// Runs every size of every method under every seed of `budget`, then the references,
/// writing the first seed's surfaces as `meshes_dir/<method>_<size>.glb`; returns the rows
/// in run order. A run that fails does not stop the study: its row carries NaN distances
/// and `failed: <why>` as its convergence (see [`Row::failed`]).
///
/// # Errors
/// [`StudyError`] when a surface cannot be written.
pub fn run(budget: &Budget, meshes_dir: &Path, progress: &mut dyn StudyProgress) -> Result<Vec<Row>, StudyError> {
    let (sphere, _) = sphere_mesh(budget.icosphere_subdivisions);
    let mut rows = Vec::with_capacity(num_units(budget));
    let keep = |mesh: &TriMesh, name: String, seed: u64| -> Result<(), StudyError> {
        if seed == budget.seeds[0] && !mesh.triangles.is_empty() {
            mesh_io::write_mesh(&meshes_dir.join(format!("{name}.glb")), mesh)?;
        }
        Ok(())
    };
    for &seed in &budget.seeds {
        for &k in budget.voronoi_sites.iter().filter(|_| budget.voronoi) {
            progress.start(&format!("Voronoi K = {k}, seed {seed}"));
            match voronoi_run(&sphere, k, budget, seed) {
                Ok((row, mesh)) => {
                    keep(&mesh, format!("voronoi_{k}"), seed)?;
                    rows.push(row);
                }
                Err(e) => rows.push(Row::failed("voronoi", format!("K={k}"), 3 * k, seed, &e)),
            }
            progress.done(&rows);
        }
        if budget.decoders.is_empty() {
            continue;
        }
        let data = sphere_data(budget.samples, seed);
        for name in &budget.decoders {
            for &(width, depth) in &budget.mlp_sizes {
                progress.start(&format!("{name} {width}x{depth}, seed {seed}"));
                match mlp_run(&data, name, width, depth, budget, seed) {
                    Ok((row, mesh)) => {
                        keep(&mesh, format!("{name}_{width}x{depth}"), seed)?;
                        rows.push(row);
                    }
                    Err(e) => {
                        let params = DecoderConfig::occnet(width, depth).num_params().unwrap_or(0);
                        rows.push(Row::failed(name, format!("{width}x{depth}"), params, seed, &e));
                    }
                }
                progress.done(&rows);
            }
        }
    }
    if !budget.references {
        return Ok(rows);
    }
    for &k in &budget.voronoi_sites {
        progress.start(&format!("construction K = {k}"));
        rows.push(
            construction_run(k, budget).unwrap_or_else(|e| Row::failed("construction", format!("K={k}"), 3 * k, 0, &e)),
        );
        progress.done(&rows);
    }
    progress.start("marching-cubes floor");
    let res = budget.mc_res;
    rows.push(mc_floor_run(budget).unwrap_or_else(|e| Row::failed("mc_floor", format!("res={res}"), 0, 0, &e)));
    progress.done(&rows);
    Ok(rows)
}

/// K sites fitted by the main job ([`fit::fit`], default settings but the sample pool)
/// to the triangulated sphere. A fit whose loss has not flattened is run again with twice
/// the steps (up to the budget's doublings).
fn voronoi_run(sphere: &TriMesh, k: usize, budget: &Budget, seed: u64) -> Result<(Row, TriMesh), StudyError> {
    let t = Instant::now();
    let mut steps = budget.voronoi_steps.unwrap_or_else(|| soft_voronoi::TrainConfig::default_for(k).steps);
    let mut doublings = 0;
    loop {
        let name = format!("icosphere({}) of the study's sphere", budget.icosphere_subdivisions);
        let mut config = fit::FitConfig::new(&name, k).with_seed(seed);
        config.train.steps = steps;
        config.sampling.samples = budget.samples;
        config.eval.samples = budget.voronoi_eval_samples;
        config.skip_metrics = true;
        let out = fit::fit(sphere, &config, &mut fit::NoProgress)
            .map_err(|e| StudyError::Run(format!("Voronoi K = {k}, seed {seed}: {e}")))?;
        let losses: Vec<f64> = out.state.history.iter().map(|s| s.total).collect();
        let flat = flattened(&losses, (steps / 10).max(1), 0.01);
        if flat || doublings >= budget.voronoi_max_doublings {
            let m = measure(&out.crust, budget.chamfer_samples, seed, TOLERANCE, EVALUATIONS)?;
            let row = Row::new(
                "voronoi",
                format!("K={k}"),
                3 * k,
                seed,
                m,
                (out.report.timings_seconds.train, steps),
                losses.last().copied().unwrap_or(f64::NAN),
                &voronoi_convergence(flat, out.report.losses.selected.map(|s| s.step), steps),
                t.elapsed().as_secs_f64(),
            );
            return Ok((row, out.crust));
        }
        steps *= 2;
        doublings += 1;
    }
}

/// The Voronoi row's `convergence`: whether the loss flattened, and which iterate the
/// main job kept (its best by the fixed evaluation batch).
fn voronoi_convergence(flat: bool, kept: Option<usize>, steps: usize) -> String {
    let flat = if flat { "flattened" } else { "not flattened" };
    match kept {
        Some(s) if s == steps => format!("{flat}; kept the last iterate"),
        Some(0) => format!("{flat}; kept the initialisation"),
        Some(s) => format!("{flat}; kept step {}", s),
        None => flat.to_string(),
    }
}

/// One decoder (OccNet: PyTorch's default initialisation; DeepSDF: SAL's geometric
/// initialisation as a sphere of radius 1 in network coordinates, the one SAL uses for
/// shapes scaled into the unit ball, not the target's), trained with Adam at a constant
/// rate lowered ×0.1 at each plateau until converged ([`crate::plateau`]); marching cubes
/// of its field on the budget's grid over the unit cube.
fn mlp_run(
    data: &baselines::TrainingData,
    name: &str,
    width: usize,
    depth: usize,
    budget: &Budget,
    seed: u64,
) -> Result<(Row, TriMesh), StudyError> {
    let fail = |e: baselines::BaselineError| StudyError::Run(format!("{name} {width}x{depth}, seed {seed}: {e}"));
    let t = Instant::now();
    if name != "occnet" && name != "deepsdf" {
        return Err(StudyError::Run(format!("unknown decoder `{name}` (occnet or deepsdf)")));
    }
    let mut model: Mlp<f32> = if name == "occnet" {
        Mlp::new(DecoderConfig::occnet(width, depth), seed)
    } else {
        // Network coordinates are twice the unit cube's: the SDF targets are half the
        // network's distances.
        Mlp::new_geometric(DecoderConfig::deepsdf(width, depth, None, 0.1), seed, 1.0, 0.5)
    }
    .map_err(fail)?;
    let rule = budget.mlp_plateau;
    let train_config = baselines::TrainConfig {
        steps: rule.max_steps,
        batch: budget.mlp_batch,
        lr: budget.mlp_lr,
        schedule: Schedule::Constant,
        seed,
        // Chunks are the unit of parallel work: a batch of one chunk (the default 4,096
        // rows at batch 4,096) runs on one core.
        chunk_rows: 1024,
        ..Default::default()
    };
    let targets = data.targets(model.config().kind).map_err(fail)?;
    let mut trainer = baselines::Trainer::new(&model, data.points.len(), &train_config).map_err(fail)?;
    let mut plateau = Plateau::new(rule);
    let mut last;
    let convergence = loop {
        let rec = trainer.step_unchecked(&mut model, &data.points, targets).map_err(fail)?;
        last = rec.loss;
        match plateau.push(rec.loss) {
            Verdict::Continue => {}
            Verdict::Reduce(f) => trainer.set_lr_factor(f),
            Verdict::Converged => break "plateau",
            Verdict::Capped => break "capped",
        }
    };
    let steps = trainer.steps_done();
    let train_seconds = t.elapsed().as_secs_f64();
    let grid = model.eval_grid_box(budget.mc_res, [-1.0; 3], [1.0; 3]).map_err(fail)?;
    let inside = if name == "occnet" { baselines::Inside::Above } else { baselines::Inside::Below };
    let mc = baselines::McOptions { spacing: [1.0 / (budget.mc_res - 1) as f64; 3], inside, ..Default::default() };
    let mesh = baselines::marching_cubes(grid.view(), &mc).map_err(fail)?;
    let m = measure(&mesh, budget.chamfer_samples, seed, TOLERANCE, EVALUATIONS)?;
    let row = Row::new(
        name,
        format!("{width}x{depth}"),
        model.num_params(),
        seed,
        m,
        (train_seconds, steps),
        last,
        convergence,
        t.elapsed().as_secs_f64(),
    );
    Ok((row, mesh))
}

/// The reference for K sites: mirrored pairs c + (r ± δ)·d at K/2 directions d of a
/// Fibonacci lattice (even spread), δ the budget's fractions of the pairs' spacing
/// √(4πr²/(K/2)) (at most 90% of the room between the sphere and the cube), no
/// training; the best of the offsets.
fn construction_run(k: usize, budget: &Budget) -> Result<Row, StudyError> {
    let t = Instant::now();
    let n = (k / 2).max(1);
    let (c, r) = (SPHERE.center, SPHERE.radius);
    let spacing = (4.0 * std::f64::consts::PI * r * r / n as f64).sqrt();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let dirs: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let z = 1.0 - (2 * i + 1) as f64 / n as f64;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            [s * phi.cos(), s * phi.sin(), z]
        })
        .collect();
    let mut best: Option<(Measured, f64)> = None;
    for &f in &budget.construction_offsets {
        // Outside sites stay inside the unit cube (the crust's domain).
        let room = (0..3).map(|i| c[i].min(1.0 - c[i])).fold(f64::INFINITY, f64::min) - r;
        let delta = (f * spacing).min(0.9 * room).min(0.9 * r);
        let mut sites = Vec::with_capacity(2 * n);
        let mut labels = Vec::with_capacity(2 * n);
        for d in &dirs {
            for (sign, inside) in [(-1.0, true), (1.0, false)] {
                sites.push([0, 1, 2].map(|i| c[i] + (r + sign * delta) * d[i]));
                labels.push(inside);
            }
        }
        // Kept in f64 (never written): float32 rounding can break the crust of so few,
        // so symmetric sites (K = 16 did), which would measure the rounding, not the sites.
        let checked = fit::crust_of(&sites, &labels, crust::output::FrameMap::Identity, crust::output::Precision::F64)
            .map_err(|e| StudyError::Run(format!("construction K = {k}: {e}")))?;
        let m = measure(&checked.written.mesh, budget.chamfer_samples, 0, TOLERANCE, EVALUATIONS)?;
        if best.as_ref().is_none_or(|(b, _)| m.hausdorff_hi < b.hausdorff_hi) {
            best = Some((m, f));
        }
    }
    let (m, f) = best.ok_or_else(|| StudyError::Run("the budget lists no construction offsets".into()))?;
    let conv = format!("- (δ = {f} × spacing)");
    Ok(Row::new("construction", format!("K={k}"), 3 * k, 0, m, (0.0, 0), f64::NAN, &conv, t.elapsed().as_secs_f64()))
}

/// Marching cubes of the sphere's exact signed distance on the decoders' grid: the best
/// any decoder's surface can be at that resolution.
fn mc_floor_run(budget: &Budget) -> Result<Row, StudyError> {
    let t = Instant::now();
    let res = budget.mc_res;
    let h = 1.0 / (res - 1) as f64;
    let grid = ndarray::Array3::from_shape_fn((res, res, res), |(i, j, k)| {
        SPHERE.distance([i as f64 * h, j as f64 * h, k as f64 * h])
    });
    let mc = baselines::McOptions { spacing: [h; 3], inside: baselines::Inside::Below, ..Default::default() };
    let mesh = baselines::marching_cubes(grid.view(), &mc).map_err(|e| StudyError::Run(format!("floor: {e}")))?;
    // Every part of this surface is about equally far from the sphere, so a tight interval
    // would take the branch and bound hundreds of millions of patches: two million give a
    // certified interval about three times as wide as its lower end, and the lower end
    // (the exact distance of the surface to the sphere, or more) is the floor the plot
    // draws: no decoder's marching-cubes surface at this resolution is closer than the
    // exact distance's, give or take the interpolation.
    let m = measure(&mesh, budget.chamfer_samples, 0, 1e-5, 2_000_000)?;
    Ok(Row::new("mc_floor", format!("res={res}"), 0, 0, m, (0.0, 0), f64::NAN, "-", t.elapsed().as_secs_f64()))
}

impl Row {
    /// The row of a run that failed: NaN distances, no surface, `failed: <why>`.
    pub fn failed(method: &str, size: String, params: usize, seed: u64, e: &StudyError) -> Self {
        let nan = f64::NAN;
        Row {
            method: method.into(),
            params,
            hausdorff_lo: nan,
            hausdorff_hi: nan,
            chamfer: nan,
            train_seconds: 0.0,
            steps: 0,
            size,
            seed,
            triangles: 0,
            watertight: false,
            final_loss: nan,
            convergence: format!("failed: {e}"),
            total_seconds: 0.0,
        }
    }

    /// Whether the run failed ([`Row::failed`]).
    pub fn is_failed(&self) -> bool {
        self.convergence.starts_with("failed")
    }

    #[allow(clippy::too_many_arguments)]
    fn new(
        method: &str,
        size: String,
        params: usize,
        seed: u64,
        m: Measured,
        (train_seconds, steps): (f64, usize),
        loss: f64,
        convergence: &str,
        total_seconds: f64,
    ) -> Self {
        Row {
            method: method.into(),
            params,
            hausdorff_lo: m.hausdorff_lo,
            hausdorff_hi: m.hausdorff_hi,
            chamfer: m.chamfer,
            train_seconds,
            steps,
            size,
            seed,
            triangles: m.triangles,
            watertight: m.watertight,
            final_loss: loss,
            convergence: convergence.into(),
            total_seconds,
        }
    }
}
