//! `voronoi-fit sample MESH -n N [--near-sigma S ...] [--uniform-fraction F] [--seed N]
//! -o OUT.npz`: training samples with ground-truth winding number, occupancy and signed
//! distance, in the input mesh's coordinates.

use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};

use crate::arrays::{vec_array, Npz};
use crate::cli_error::{CliError, InFile};
use crate::cmd_query::add_config;
use occupancy::sample::{labelled_samples, SampleSpec, SurfaceSampler};
use occupancy::{Config, MeshOracle, OccupancyError};

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
    let spec = SampleSpec {
        num_samples: args.num_samples,
        uniform_fraction: args.uniform_fraction,
        padding: args.padding,
        near_sigma: args.near_sigma.clone(),
        seed: args.seed,
        exact: args.exact,
    };
    if let Err(OccupancyError::BadSampler(m)) = spec.validate() {
        return Err(CliError::input(m));
    }
    let mesh = mesh_io::read_mesh(&args.mesh)?;
    let config = Config::default();
    let oracle = MeshOracle::from_mesh(&mesh, &config).in_file(&args.mesh)?;

    let n = args.num_samples;
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
    let labelled = labelled_samples(&oracle, || SurfaceSampler::from_mesh(&mesh), &spec, &mut |done| {
        bar.set_position(done as u64)
    });
    let samples = match labelled {
        Err(e @ OccupancyError::BadQuery { .. }) => {
            return Err(CliError::failure(format!("sampled an invalid point: {e}")));
        }
        r => r.in_file(&args.mesh)?,
    };
    bar.finish_and_clear();

    let mut npz = Npz::new();
    npz.add_rows("points", &samples.points)?;
    npz.add("winding", &vec_array(&samples.winding))?;
    npz.add("occupancy", &vec_array(&samples.occupancy))?;
    npz.add("sdf", &vec_array(&samples.sdf))?;
    npz.add("near_sigma", &vec_array(&args.near_sigma))?;
    npz.add("seed", &ndarray::arr0(args.seed))?;
    add_config(&mut npz, &config, args.exact)?;
    npz.write(&args.output)?;
    Ok(())
}
