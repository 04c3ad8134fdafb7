//! `voronoi-fit study sphere [--quick] --out DIR`: the seed paper's headline experiment.
//! Overfit a sphere (radius 0.35, centred in the unit cube) with Voronoi sites and with
//! OccNet- and DeepSDF-style MLP decoders of many sizes, and compare Hausdorff distance to
//! the analytic sphere against parameter count.
//!
//! Every run gets a fixed, documented budget (see [`Budget`]). Surfaces: the Voronoi
//! crust (exact, watertight) and marching cubes of the decoders on a grid. Distances: a
//! certified Hausdorff interval to the analytic sphere ([`sphere_hausdorff`]) and a
//! sampled Chamfer L1 distance. Outputs (atomically): DIR/results.csv,
//! DIR/hausdorff_vs_params.svg and .png, DIR/table.md, DIR/meshes/*.glb.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::anyhow;
use baselines::{DecoderConfig, Mlp, Schedule};
use mesh_io::TriMesh;
use occupancy::sample::rng::ChunkRng;
use occupancy::sample::SurfaceSampler;
use occupancy::{MeshOracle, Workspace};
use rayon::prelude::*;
use serde::Serialize;
use soft_voronoi::{Sphere, TrainConfig, Trainer, TrainingData};

use crate::cli_error::CliError;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The study: `sphere`.
    #[arg(value_parser = ["sphere"])]
    pub study: String,
    /// Output directory (created if missing).
    #[arg(long)]
    pub out: PathBuf,
    /// Small sizes and budgets (under 2 minutes; what CI runs).
    #[arg(long)]
    pub quick: bool,
    /// Seed of the samples and of every model.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
}

const CENTER: [f64; 3] = [0.5, 0.5, 0.5];
const RADIUS: f64 = 0.35;

/// The budgets and sizes of a study.
#[derive(Clone, Debug, Serialize)]
pub struct Budget {
    /// Voronoi site counts K (3K parameters).
    pub voronoi_sites: Vec<usize>,
    /// Voronoi training steps (default preset otherwise: 16,384 samples per step).
    pub voronoi_steps: usize,
    /// MLP (width, depth = hidden layers) pairs, for both decoders.
    pub mlp_sizes: Vec<(usize, usize)>,
    /// MLP training steps.
    pub mlp_steps: usize,
    /// MLP batch size.
    pub mlp_batch: usize,
    /// MLP learning rate (cosine decay to 1% of it).
    pub mlp_lr: f64,
    /// Marching-cubes grid resolution (points per axis over the unit cube).
    pub mc_res: usize,
    /// Training points (half uniform in the cube, half near the sphere).
    pub samples: usize,
    /// Surface samples per side for the Chamfer distance.
    pub chamfer_samples: usize,
}

impl Budget {
    fn full() -> Self {
        Budget {
            voronoi_sites: vec![8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192],
            voronoi_steps: 600,
            mlp_sizes: vec![(4, 2), (8, 2), (16, 3), (32, 3), (64, 3), (128, 3), (256, 3), (512, 3), (512, 4)],
            mlp_steps: 1000,
            mlp_batch: 8192,
            mlp_lr: 1e-3,
            mc_res: 128,
            samples: 1_000_000,
            chamfer_samples: 100_000,
        }
    }

    fn quick() -> Self {
        Budget {
            voronoi_sites: vec![8, 64, 512],
            voronoi_steps: 100,
            mlp_sizes: vec![(16, 2), (32, 2)],
            mlp_steps: 400,
            mlp_batch: 4096,
            mlp_lr: 3e-3,
            mc_res: 48,
            samples: 200_000,
            chamfer_samples: 20_000,
        }
    }
}

/// One row of results.csv.
#[derive(Clone, Debug, Serialize)]
struct Row {
    method: String,
    params: usize,
    hausdorff_lo: f64,
    hausdorff_hi: f64,
    chamfer: f64,
    train_seconds: f64,
    steps: usize,
    size: String,
    triangles: usize,
    watertight: bool,
    final_loss: f64,
}

/// The sphere's training data, analytically labelled.
struct Data {
    voronoi: TrainingData,
    mlp: baselines::TrainingData,
}

fn unit_dir(rng: &mut ChunkRng) -> [f64; 3] {
    loop {
        let d = [0, 1, 2].map(|_| 2.0 * rng.uniform() - 1.0);
        let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        if l > 1e-6 && l <= 1.0 {
            return d.map(|x| x / l);
        }
    }
}

fn sphere_data(n: usize, seed: u64) -> Data {
    let mut rng = ChunkRng::for_chunk(seed, 301, 0);
    let sigmas = [0.01, 0.003];
    let mut points = Vec::with_capacity(n);
    let mut surface = Vec::with_capacity(n / 2);
    let mut normals = Vec::with_capacity(n / 2);
    for i in 0..n {
        if i < n / 2 {
            points.push([rng.uniform(), rng.uniform(), rng.uniform()]);
        } else {
            let d = unit_dir(&mut rng);
            let s = [0, 1, 2].map(|c| CENTER[c] + RADIUS * d[c]);
            let sigma = sigmas[i % 2];
            points.push([0, 1, 2].map(|c| (s[c] + sigma * rng.normal()).clamp(0.0, 1.0)));
            surface.push(s);
            normals.push(d);
        }
    }
    let dist = |p: &[f64; 3]| {
        ((p[0] - CENTER[0]).powi(2) + (p[1] - CENTER[1]).powi(2) + (p[2] - CENTER[2]).powi(2)).sqrt() - RADIUS
    };
    let inside: Vec<bool> = points.iter().map(|p| dist(p) <= 0.0).collect();
    let sdf: Vec<f64> = points.iter().map(dist).collect();
    let occ: Vec<f64> = inside.iter().map(|&b| if b { 1.0 } else { 0.0 }).collect();
    Data {
        voronoi: TrainingData { points: points.clone(), occupancy: inside, surface, normals },
        // The decoders see coordinates in [−1, 1]³ (centred inputs, as OccNet and DeepSDF
        // use; on raw [0, 1]³ inputs the small OccNets here stayed at the constant
        // prediction for the whole budget). SDF targets stay in unit-cube lengths.
        mlp: baselines::TrainingData {
            points: points.iter().map(|p| p.map(|x| 2.0 * x - 1.0)).collect(),
            occupancy: Some(occ),
            sdf: Some(sdf),
        },
    }
}

/// A certified interval [lo, hi] containing the Hausdorff distance between the surface of
/// `mesh` and the sphere (CENTER, RADIUS), with hi − lo ≤ `tol` (plus a rounding margin).
///
/// - mesh → sphere, exactly per triangle: |‖x − c‖ − r| is largest at a vertex for the
///   outward part (‖x − c‖ is convex) and at the triangle's closest point to c for the
///   inward part, so h₁ = max_T max(max_v ‖v − c‖ − r, r − d(c, T));
/// - sphere → mesh, branch and bound over spherical triangles (an icosahedron's faces,
///   split 4-way): a patch's points lie within R = r·max_i ‖ŝ − â_i‖ of its centre ŝ's
///   point (the farthest point of a small spherical triangle from its centre is a
///   corner), so d(y, M) ≤ d(s, M) + R on it; d(s, M) itself is a lower bound. Patches
///   whose bound exceeds the best lower bound by more than `tol` are split.
///
/// f64 rounding is covered by widening both ends by 64 ε (1 + r + ‖c‖).
pub fn sphere_hausdorff(mesh: &TriMesh, oracle: &MeshOracle, tol: f64) -> (f64, f64) {
    use occupancy::distance::closest_point_triangle::closest_point_triangle;
    let norm =
        |a: [f64; 3], b: [f64; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt();
    let h1 = mesh
        .triangles
        .par_iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let out = [a, b, c].iter().map(|&v| norm(v, CENTER) - RADIUS).fold(f64::NEG_INFINITY, f64::max);
            let inw = RADIUS - norm(closest_point_triangle(CENTER, a, b, c), CENTER);
            out.max(inw)
        })
        .reduce(|| f64::NEG_INFINITY, f64::max);

    #[derive(PartialEq)]
    struct Patch {
        ub: f64,
        corners: [[f64; 3]; 3],
    }
    impl Eq for Patch {}
    impl PartialOrd for Patch {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Patch {
        fn cmp(&self, o: &Self) -> Ordering {
            self.ub.total_cmp(&o.ub)
        }
    }
    let normalize = |v: [f64; 3]| {
        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        v.map(|x| x / l)
    };
    let on_sphere = |u: [f64; 3]| [0, 1, 2].map(|k| CENTER[k] + RADIUS * u[k]);
    // Evaluates a patch: (lower bound, upper bound).
    let eval = |corners: &[[f64; 3]; 3], ws: &mut Workspace| {
        let s = normalize([0, 1, 2].map(|k| corners[0][k] + corners[1][k] + corners[2][k]));
        let d = oracle.closest_point(on_sphere(s), ws).squared_distance.sqrt();
        let r = corners.iter().map(|&a| norm(s, a)).fold(0.0, f64::max) * RADIUS;
        (d, d + r)
    };
    // The starting patches: the icosahedron's faces (unit vectors, counter-clockwise).
    let icosahedron = mesh_io::shapes::icosphere(0);
    let mut ws = Workspace::new();
    let mut lo2: f64 = 0.0;
    let mut heap = BinaryHeap::new();
    for f in &icosahedron.triangles {
        let corners = f.map(|i| icosahedron.positions[i as usize]);
        let (lo, ub) = eval(&corners, &mut ws);
        lo2 = lo2.max(lo);
        heap.push(Patch { ub, corners });
    }
    let mut evaluations = 0usize;
    while let Some(top) = heap.peek() {
        if top.ub <= lo2 + tol || evaluations > 20_000_000 {
            break;
        }
        let Some(p) = heap.pop() else { break };
        let [a, b, c] = p.corners;
        let (ab, bc, ca) = (
            normalize([0, 1, 2].map(|k| a[k] + b[k])),
            normalize([0, 1, 2].map(|k| b[k] + c[k])),
            normalize([0, 1, 2].map(|k| c[k] + a[k])),
        );
        for corners in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]] {
            let (lo, ub) = eval(&corners, &mut ws);
            evaluations += 1;
            lo2 = lo2.max(lo);
            if ub > lo2 + tol {
                heap.push(Patch { ub, corners });
            }
        }
    }
    let hi2 = heap.peek().map_or(lo2, |p| p.ub.max(lo2));
    let margin = 64.0 * f64::EPSILON * (1.0 + RADIUS + 1.0);
    let lo = h1.max(lo2) - margin;
    let hi = h1.max(hi2) + margin;
    (lo.max(0.0), hi)
}

/// Chamfer L1: ½ (mean over mesh samples of the distance to the sphere + mean over sphere
/// samples of the distance to the mesh), `n` seeded samples per side.
fn sphere_chamfer(mesh: &TriMesh, oracle: &MeshOracle, n: usize, seed: u64) -> Result<f64, CliError> {
    let sampler = SurfaceSampler::from_mesh(mesh).map_err(|e| CliError::Failure(e.into()))?;
    let on_mesh = sampler.sample(n, seed);
    let d1: f64 = on_mesh
        .points
        .par_iter()
        .map(|p| {
            (((p[0] - CENTER[0]).powi(2) + (p[1] - CENTER[1]).powi(2) + (p[2] - CENTER[2]).powi(2)).sqrt() - RADIUS)
                .abs()
        })
        .sum::<f64>()
        / n as f64;
    let mut rng = ChunkRng::for_chunk(seed, 302, 0);
    let on_sphere: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            let d = unit_dir(&mut rng);
            [0, 1, 2].map(|k| CENTER[k] + RADIUS * d[k])
        })
        .collect();
    let d2: f64 = oracle
        .closest_points(&on_sphere)
        .map_err(|e| CliError::Failure(e.into()))?
        .iter()
        .map(|c| c.squared_distance.sqrt())
        .sum::<f64>()
        / n as f64;
    Ok(0.5 * (d1 + d2))
}

/// Hausdorff interval, Chamfer, triangle count and closedness of a surface; NaN distances
/// for an empty surface.
fn measure(mesh: &TriMesh, budget: &Budget, seed: u64) -> Result<(f64, f64, f64, usize, bool), CliError> {
    if mesh.triangles.is_empty() {
        return Ok((f64::NAN, f64::NAN, f64::NAN, 0, false));
    }
    let oracle = MeshOracle::from_mesh(mesh, &occupancy::Config::default()).map_err(|e| CliError::Failure(e.into()))?;
    let (lo, hi) = sphere_hausdorff(mesh, &oracle, 1e-6 * 3f64.sqrt());
    let chamfer = sphere_chamfer(mesh, &oracle, budget.chamfer_samples, seed)?;
    let report = mesh_io::TopologyReport::of(mesh);
    Ok((lo, hi, chamfer, mesh.triangles.len(), report.is_closed && report.is_manifold))
}

fn write_text(path: &Path, text: &str) -> Result<(), CliError> {
    mesh_io::atomic_write(path, |w| std::io::Write::write_all(w, text.as_bytes()))?;
    Ok(())
}

pub fn run(args: Args) -> Result<(), CliError> {
    let t_all = Instant::now();
    let budget = if args.quick { Budget::quick() } else { Budget::full() };
    std::fs::create_dir_all(args.out.join("meshes"))
        .map_err(|e| CliError::Failure(anyhow!("{}: cannot create the output directory ({e})", args.out.display())))?;
    let data = sphere_data(budget.samples, args.seed);
    let sphere = Sphere { center: CENTER, radius: RADIUS };
    let runs = budget.voronoi_sites.len() + 2 * budget.mlp_sizes.len();
    let bar = if args.quiet { indicatif::ProgressBar::hidden() } else { indicatif::ProgressBar::new(runs as u64) };
    bar.set_style(
        indicatif::ProgressStyle::with_template("study {bar:30} {pos}/{len} runs, {msg}, {elapsed} (ETA {eta})")
            .map_err(anyhow::Error::from)?,
    );
    let mut rows: Vec<Row> = Vec::new();

    for &k in &budget.voronoi_sites {
        bar.set_message(format!("Voronoi K = {k}"));
        let mut config = TrainConfig::default_for(k);
        config.steps = budget.voronoi_steps;
        config.seed = args.seed;
        let t = Instant::now();
        let mut trainer = Trainer::new(config, &data.voronoi, &sphere).map_err(|e| CliError::Failure(e.into()))?;
        let mut last = 0.0;
        while !trainer.is_done() {
            last = trainer.step().map_err(|e| CliError::Failure(e.into()))?.reconstruction;
        }
        let train_seconds = t.elapsed().as_secs_f64();
        let (mut sites, labels, _) = trainer.final_sites();
        let (crust, _, _) = crate::cmd_fit::checked_crust(&mut sites, &labels, args.seed)
            .map_err(|e| CliError::Failure(anyhow!("K = {k}: {e}")))?;
        let (lo, hi, chamfer, triangles, watertight) = measure(&crust.mesh, &budget, args.seed)?;
        mesh_io::write_mesh(&args.out.join(format!("meshes/voronoi_{k}.glb")), &crust.mesh)?;
        rows.push(Row {
            method: "voronoi".into(),
            params: 3 * k,
            hausdorff_lo: lo,
            hausdorff_hi: hi,
            chamfer,
            train_seconds,
            steps: budget.voronoi_steps,
            size: format!("K={k}"),
            triangles,
            watertight,
            final_loss: last,
        });
        bar.inc(1);
    }

    for (name, make) in [
        ("occnet", (|w, d| DecoderConfig::occnet(w, d)) as fn(usize, usize) -> DecoderConfig),
        ("deepsdf", |w, d| DecoderConfig::deepsdf(w, d, None, 0.1)),
    ] {
        for &(width, depth) in &budget.mlp_sizes {
            bar.set_message(format!("{name} {width}x{depth}"));
            let config = make(width, depth);
            let mut model: Mlp<f32> = Mlp::new(config, args.seed).map_err(|e| CliError::Failure(e.into()))?;
            let train_config = baselines::TrainConfig {
                steps: budget.mlp_steps,
                batch: budget.mlp_batch,
                lr: budget.mlp_lr,
                schedule: Schedule::Cosine { min_lr: budget.mlp_lr * 0.01 },
                seed: args.seed,
                ..Default::default()
            };
            let t = Instant::now();
            let report =
                baselines::train(&mut model, &data.mlp, &train_config, |_| std::ops::ControlFlow::Continue(()))
                    .map_err(|e| CliError::Failure(e.into()))?;
            let train_seconds = t.elapsed().as_secs_f64();
            // Marching cubes of the decoder on the res³ grid of the unit cube (network
            // coordinates [−1, 1]³), the mesh in unit-cube coordinates.
            let grid =
                model.eval_grid_box(budget.mc_res, [-1.0; 3], [1.0; 3]).map_err(|e| CliError::Failure(e.into()))?;
            let inside = if name == "occnet" { baselines::Inside::Above } else { baselines::Inside::Below };
            let mc =
                baselines::McOptions { spacing: [1.0 / (budget.mc_res - 1) as f64; 3], inside, ..Default::default() };
            let mesh = baselines::marching_cubes(grid.view(), &mc).map_err(|e| CliError::Failure(e.into()))?;
            let (lo, hi, chamfer, triangles, watertight) = measure(&mesh, &budget, args.seed)?;
            if !mesh.triangles.is_empty() {
                mesh_io::write_mesh(&args.out.join(format!("meshes/{name}_{width}x{depth}.glb")), &mesh)?;
            }
            rows.push(Row {
                method: name.into(),
                params: model.num_params(),
                hausdorff_lo: lo,
                hausdorff_hi: hi,
                chamfer,
                train_seconds,
                steps: budget.mlp_steps,
                size: format!("{width}x{depth}"),
                triangles,
                watertight,
                final_loss: report.losses.last().copied().unwrap_or(f64::NAN),
            });
            bar.inc(1);
        }
    }
    bar.finish_and_clear();

    // results.csv
    let mut csv = String::from(
        "method,params,hausdorff_lo,hausdorff_hi,chamfer,train_seconds,steps,size,triangles,watertight,final_loss\n",
    );
    for r in &rows {
        csv += &format!(
            "{},{},{:e},{:e},{:e},{:.3},{},{},{},{},{:e}\n",
            r.method,
            r.params,
            r.hausdorff_lo,
            r.hausdorff_hi,
            r.chamfer,
            r.train_seconds,
            r.steps,
            r.size,
            r.triangles,
            r.watertight,
            r.final_loss
        );
    }
    write_text(&args.out.join("results.csv"), &csv)?;

    // The plot.
    let labels = [("voronoi", "Voronoi sites (3K)"), ("occnet", "OccNet MLP"), ("deepsdf", "DeepSDF MLP")];
    let series = labels
        .iter()
        .map(|(m, label)| {
            let mut pts: Vec<&Row> = rows.iter().filter(|r| r.method == *m && r.hausdorff_hi.is_finite()).collect();
            pts.sort_by_key(|r| r.params);
            plot::Series {
                name: label.to_string(),
                points: pts.iter().map(|r| (r.params as f64, 0.5 * (r.hausdorff_lo + r.hausdorff_hi))).collect(),
                band: Some(pts.iter().map(|r| (r.hausdorff_lo, r.hausdorff_hi)).collect()),
            }
        })
        .filter(|s| !s.points.is_empty())
        .collect();
    let chart = plot::Chart {
        title: format!(
            "Sphere r = 0.35: Hausdorff distance vs parameters ({})",
            if args.quick { "quick budget" } else { "full budget" }
        ),
        x_label: "parameters".into(),
        y_label: "Hausdorff distance (unit cube, certified)".into(),
        log_x: true,
        log_y: true,
        series,
    };
    chart.write_svg(&args.out.join("hausdorff_vs_params.svg")).map_err(|e| CliError::Failure(anyhow!("{e}")))?;
    chart.write_png(&args.out.join("hausdorff_vs_params.png")).map_err(|e| CliError::Failure(anyhow!("{e}")))?;

    // table.md
    let mut md = String::new();
    md += &format!(
        "Sphere of radius 0.35 in the unit cube; budgets: Voronoi {} steps × 16,384 samples (default preset), MLPs {} \
         steps × {} samples (Adam, lr {} cosine to 1%), marching cubes at {}³; {} training samples; seed {}.\n\n",
        budget.voronoi_steps,
        budget.mlp_steps,
        budget.mlp_batch,
        budget.mlp_lr,
        budget.mc_res,
        budget.samples,
        args.seed
    );
    md += "| method | size | parameters | Hausdorff [lo, hi] | Chamfer L1 | triangles | watertight | train s |\n";
    md += "|---|---|---|---|---|---|---|---|\n";
    for r in &rows {
        md += &format!(
            "| {} | {} | {} | [{:.3e}, {:.3e}] | {:.3e} | {} | {} | {:.1} |\n",
            r.method,
            r.size,
            r.params,
            r.hausdorff_lo,
            r.hausdorff_hi,
            r.chamfer,
            r.triangles,
            if r.watertight { "yes" } else { "no" },
            r.train_seconds
        );
    }
    md += "\nParameters needed to reach a Hausdorff distance (certified upper bound) at or below h:\n\n";
    md += "| h | Voronoi | OccNet | DeepSDF |\n|---|---|---|---|\n";
    for h in [0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001] {
        let need = |m: &str| {
            rows.iter()
                .filter(|r| r.method == m && r.hausdorff_hi <= h)
                .map(|r| r.params)
                .min()
                .map_or("not reached".to_string(), |p| p.to_string())
        };
        md += &format!("| {h} | {} | {} | {} |\n", need("voronoi"), need("occnet"), need("deepsdf"));
    }
    write_text(&args.out.join("table.md"), &md)?;
    let budget_json = serde_json::to_string_pretty(&budget).map_err(anyhow::Error::from)?;
    write_text(&args.out.join("budget.json"), &budget_json)?;

    let bad: Vec<&Row> = rows.iter().filter(|r| r.method == "voronoi" && !r.watertight).collect();
    crate::output::out!(
        "study sphere ({}): {} runs in {:.1} s; wrote {}/results.csv, hausdorff_vs_params.svg/.png, table.md and \
         meshes/. Every Voronoi crust is watertight: {}.",
        if args.quick { "quick" } else { "full" },
        rows.len(),
        t_all.elapsed().as_secs_f64(),
        args.out.display(),
        if bad.is_empty() { "yes" } else { "NO" }
    );
    Ok(())
}
