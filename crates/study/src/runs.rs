//! The runs: Voronoi sites at each K, OccNet and DeepSDF decoders at each size.

use std::path::Path;
use std::time::Instant;

use baselines::{DecoderConfig, Mlp, Schedule};
use mesh_io::TriMesh;
use serde::Serialize;
use soft_voronoi::{Sphere, TrainConfig, Trainer};

use crate::budget::Budget;
use crate::data::{sphere_data, Data};
use crate::measure::{measure, Measured};
use crate::{StudyError, SPHERE};

/// One row of results.csv.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// `voronoi`, `occnet` or `deepsdf`.
    pub method: String,
    /// Parameters (3K for K sites).
    pub params: usize,
    /// Certified Hausdorff interval to the sphere, unit cube.
    pub hausdorff_lo: f64,
    /// Its upper end.
    pub hausdorff_hi: f64,
    /// Chamfer L1 to the sphere.
    pub chamfer: f64,
    /// Training wall time.
    pub train_seconds: f64,
    /// Training steps.
    pub steps: usize,
    /// `K=…` or `W×D`.
    pub size: String,
    /// Triangles of the surface.
    pub triangles: usize,
    /// Closed and manifold.
    pub watertight: bool,
    /// Last training loss (reconstruction for Voronoi).
    pub final_loss: f64,
}

impl Row {
    fn new(
        method: &str,
        size: String,
        params: usize,
        m: Measured,
        train_seconds: f64,
        steps: usize,
        loss: f64,
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
            triangles: m.triangles,
            watertight: m.watertight,
            final_loss: loss,
        }
    }
}

/// Receives the study's progress.
pub trait StudyProgress {
    /// A run starts (its label, e.g. "Voronoi K = 64").
    fn start(&mut self, _label: &str) {}
    /// A run finished.
    fn done(&mut self) {}
}

impl StudyProgress for () {}

/// Runs every size of every method under `budget`, writing each surface as
/// `meshes_dir/<method>_<size>.glb`; returns the rows in run order.
///
/// # Errors
/// [`StudyError`] naming the failing run, or an output that cannot be written.
pub fn run(
    budget: &Budget,
    seed: u64,
    meshes_dir: &Path,
    progress: &mut dyn StudyProgress,
) -> Result<Vec<Row>, StudyError> {
    let data = sphere_data(budget.samples, seed);
    let mut rows = Vec::with_capacity(budget.num_runs());
    for &k in &budget.voronoi_sites {
        progress.start(&format!("Voronoi K = {k}"));
        let (row, mesh) = voronoi_run(&data, k, budget, seed)?;
        mesh_io::write_mesh(&meshes_dir.join(format!("voronoi_{k}.glb")), &mesh)?;
        rows.push(row);
        progress.done();
    }
    for name in ["occnet", "deepsdf"] {
        for &(width, depth) in &budget.mlp_sizes {
            progress.start(&format!("{name} {width}x{depth}"));
            let (row, mesh) = mlp_run(&data, name, width, depth, budget, seed)?;
            if !mesh.triangles.is_empty() {
                mesh_io::write_mesh(&meshes_dir.join(format!("{name}_{width}x{depth}.glb")), &mesh)?;
            }
            rows.push(row);
            progress.done();
        }
    }
    Ok(rows)
}

/// K sites, default training settings with the budget's steps, the main job's crust.
fn voronoi_run(data: &Data, k: usize, budget: &Budget, seed: u64) -> Result<(Row, TriMesh), StudyError> {
    let fail = |e: soft_voronoi::TrainError| StudyError::Run(format!("Voronoi K = {k}: {e}"));
    let mut config = TrainConfig::default_for(k);
    config.steps = budget.voronoi_steps;
    config.seed = seed;
    let sphere: Sphere = SPHERE;
    let t = Instant::now();
    let mut trainer = Trainer::new(config, &data.voronoi, &sphere).map_err(fail)?;
    let mut last = 0.0;
    while !trainer.is_done() {
        last = trainer.step().map_err(fail)?.reconstruction;
    }
    let train_seconds = t.elapsed().as_secs_f64();
    let (sites, labels, _) = trainer.final_sites();
    // The study's surfaces stay in the unit cube, written as GLB (float32).
    let checked = fit::crust_of(&sites, &labels, crust::output::FrameMap::Identity, crust::output::Precision::F32)
        .map_err(|e| StudyError::Run(format!("K = {k}: {e}")))?;
    let mesh = checked.written.mesh;
    let m = measure(&mesh, budget.chamfer_samples, seed)?;
    Ok((Row::new("voronoi", format!("K={k}"), 3 * k, m, train_seconds, budget.voronoi_steps, last), mesh))
}

/// One decoder: trained on the sphere's data, marching cubes of its field on the
/// budget's grid over the unit cube (network coordinates [−1, 1]³).
fn mlp_run(
    data: &Data,
    name: &str,
    width: usize,
    depth: usize,
    budget: &Budget,
    seed: u64,
) -> Result<(Row, TriMesh), StudyError> {
    let fail = |e: baselines::BaselineError| StudyError::Run(format!("{name} {width}x{depth}: {e}"));
    let config = if name == "occnet" {
        DecoderConfig::occnet(width, depth)
    } else {
        DecoderConfig::deepsdf(width, depth, None, 0.1)
    };
    let mut model: Mlp<f32> = Mlp::new(config, seed).map_err(fail)?;
    let train_config = baselines::TrainConfig {
        steps: budget.mlp_steps,
        batch: budget.mlp_batch,
        lr: budget.mlp_lr,
        schedule: Schedule::Cosine { min_lr: budget.mlp_lr * 0.01 },
        seed,
        ..Default::default()
    };
    let t = Instant::now();
    let report = baselines::train(&mut model, &data.mlp, &train_config, |_| std::ops::ControlFlow::Continue(()))
        .map_err(fail)?;
    let train_seconds = t.elapsed().as_secs_f64();
    let grid = model.eval_grid_box(budget.mc_res, [-1.0; 3], [1.0; 3]).map_err(fail)?;
    let inside = if name == "occnet" { baselines::Inside::Above } else { baselines::Inside::Below };
    let mc = baselines::McOptions { spacing: [1.0 / (budget.mc_res - 1) as f64; 3], inside, ..Default::default() };
    let mesh = baselines::marching_cubes(grid.view(), &mc).map_err(fail)?;
    let m = measure(&mesh, budget.chamfer_samples, seed)?;
    let loss = report.losses.last().copied().unwrap_or(f64::NAN);
    let row = Row::new(name, format!("{width}x{depth}"), model.num_params(), m, train_seconds, budget.mlp_steps, loss);
    Ok((row, mesh))
}
