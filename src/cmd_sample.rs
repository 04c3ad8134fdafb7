//! `voronoi-fit sample MESH -n N [--near-sigma S ...] [--uniform-fraction F] [--seed N]
//! -o OUT.npz`: training samples with ground-truth winding number, occupancy and signed
//! distance, in the input mesh's coordinates.

use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};

use crate::arrays::{vec_array, Npz};
use crate::cli_error::{CliError, InFile};
use crate::cmd_query::add_config;
use occupancy::sample::{near_surface, uniform_in_box, SurfaceSampler};
use occupancy::{Config, MeshOracle, WindingMode};

/// Queries per progress-bar step.
const PROGRESS_CHUNK: usize = 1 << 16;

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file: .obj, .stl, .ply, .off, .gltf or .glb (open meshes and soups are fine).
    pub mesh: PathBuf,
    /// Number of samples.
    #[arg(short = 'n', long = "num-samples")]
    pub num_samples: usize,
    /// Standard deviations of the near-surface Gaussian offsets, as fractions of the mesh's
    /// bounding-box diagonal; near-surface samples are split evenly between them.
    #[arg(long = "near-sigma", num_args = 1.., default_values_t = vec![0.01])]
    pub near_sigma: Vec<f64>,
    /// Fraction of the samples drawn uniformly in the bounding box grown by --padding;
    /// the rest are near-surface samples.
    #[arg(long, default_value_t = 0.5)]
    pub uniform_fraction: f64,
    /// Growth of the uniform box on each side, as a fraction of the box's extent along
    /// each axis (0.05 grows every extent by 10%).
    #[arg(long, default_value_t = 0.05)]
    pub padding: f64,
    /// Seed of the samplers; the output depends only on the arguments, not on the
    /// number of threads.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Exact winding numbers instead of the fast approximation (slower).
    #[arg(long)]
    pub exact: bool,
    /// Output .npz: `points` (N,3) f64, `winding` (N,) f64, `occupancy` (N,) u8, `sdf`
    /// (N,) f64 (negative inside), plus the thresholds used.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(args: Args) -> Result<(), CliError> {
    if args.output.extension().is_none_or(|e| !e.eq_ignore_ascii_case("npz")) {
        return Err(CliError::input(format!("{}: the output must be a .npz file.", args.output.display())));
    }
    if args.num_samples == 0 {
        return Err(CliError::input("-n must be at least 1."));
    }
    if !(0.0..=1.0).contains(&args.uniform_fraction) {
        return Err(CliError::input(format!("--uniform-fraction {} is outside [0, 1].", args.uniform_fraction)));
    }
    if !(args.padding.is_finite() && args.padding >= 0.0) {
        return Err(CliError::input(format!("--padding {} must be finite and >= 0.", args.padding)));
    }
    if let Some(s) = args.near_sigma.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
        return Err(CliError::input(format!("--near-sigma {s} must be finite and >= 0.")));
    }
    let mesh = mesh_io::read_mesh(&args.mesh)?;
    let config = Config::default();
    let oracle = MeshOracle::from_mesh(&mesh, &config).in_file(&args.mesh)?;

    let n = args.num_samples;
    let num_uniform = ((n as f64) * args.uniform_fraction).round() as usize;
    let num_near = n - num_uniform;
    let (lo, hi) = oracle.bounding_box();
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let mut glo = lo;
    let mut ghi = hi;
    for k in 0..3 {
        let pad = args.padding * (hi[k] - lo[k]);
        glo[k] -= pad;
        ghi[k] += pad;
    }
    let mut points = uniform_in_box(glo, ghi, num_uniform, args.seed).in_file(&args.mesh)?;
    if num_near > 0 {
        let sampler = SurfaceSampler::from_mesh(&mesh).in_file(&args.mesh)?;
        let sigmas: Vec<f64> = args.near_sigma.iter().map(|s| s * diag).collect();
        points.extend(near_surface(&sampler, num_near, &sigmas, args.seed).in_file(&args.mesh)?);
    }

    let mode = if args.exact { WindingMode::Exact } else { WindingMode::Fast };
    let bar = if n >= 100_000 {
        let bar = ProgressBar::new(n as u64);
        if let Ok(style) = ProgressStyle::with_template("{spinner} {msg} [{bar:40}] {pos}/{len} ({per_sec}, eta {eta})")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar.set_message("sampling");
        bar
    } else {
        ProgressBar::hidden()
    };
    let mut winding = Vec::with_capacity(n);
    let mut occupancy = Vec::with_capacity(n);
    let mut sdf = Vec::with_capacity(n);
    for chunk in points.chunks(PROGRESS_CHUNK) {
        let batch =
            oracle.query(chunk, mode).map_err(|e| CliError::failure(format!("sampled an invalid point: {e}")))?;
        winding.extend(batch.winding);
        occupancy.extend(batch.occupancy);
        sdf.extend(batch.sdf);
        bar.inc(chunk.len() as u64);
    }
    bar.finish_and_clear();

    let mut npz = Npz::new();
    npz.add_rows("points", &points)?;
    npz.add("winding", &vec_array(&winding))?;
    npz.add("occupancy", &vec_array(&occupancy))?;
    npz.add("sdf", &vec_array(&sdf))?;
    npz.add("near_sigma", &vec_array(&args.near_sigma))?;
    npz.add("seed", &ndarray::arr0(args.seed))?;
    add_config(&mut npz, &config, args.exact)?;
    npz.write(&args.output)?;
    Ok(())
}
