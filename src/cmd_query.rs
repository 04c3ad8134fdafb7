//! `voronoi-fit query MESH POINTS.npy -o OUT.npz [--exact] [--timings]`: winding numbers,
//! occupancy, signed distances and closest points of given query points.

use std::path::PathBuf;
use std::time::Instant;

use crate::arrays::{read_points_npy, vec_array, Npz};
use crate::cli_error::{CliError, InFile};
use occupancy::{Config, MeshOracle, WindingMode};

#[derive(clap::Args)]
pub struct Args {
    /// Mesh file: .obj, .stl, .ply, .off, .gltf or .glb (open meshes and soups are fine).
    pub mesh: PathBuf,
    /// Query points: a .npy array of shape (n, 3), float64 or float32, in the mesh's
    /// coordinates.
    pub points: PathBuf,
    /// Output .npz with `winding` (n,) f64, `occupancy` (n,) u8, `sdf` (n,) f64 (negative
    /// inside), `closest` (n,3) f64, `squared_distance` (n,) f64, `triangle` (n,) u32, and
    /// `winding_exact_fallbacks` (how many fast values were recomputed exactly).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Exact winding numbers (sum of all solid angles) instead of the fast approximation.
    #[arg(long)]
    pub exact: bool,
    /// Print compute times as one JSON line on stderr: wall seconds of the oracle build,
    /// the winding numbers and the closest points (excluding file I/O), and CPU seconds
    /// of the last two (Linux only, else null), and the number of exact fallbacks.
    #[arg(long)]
    pub timings: bool,
}

pub fn run(args: Args) -> Result<(), CliError> {
    if args.output.extension().is_none_or(|e| !e.eq_ignore_ascii_case("npz")) {
        return Err(CliError::input(format!("{}: the output must be a .npz file.", args.output.display())));
    }
    let mesh = mesh_io::read_mesh(&args.mesh)?;
    let queries = read_points_npy(&args.points)?;
    let config = Config::default();
    let t0 = Instant::now();
    let oracle = MeshOracle::from_mesh(&mesh, &config).in_file(&args.mesh)?;
    let build_s = t0.elapsed().as_secs_f64();
    let mode = if args.exact { WindingMode::Exact } else { WindingMode::Fast };
    let t1 = Instant::now();
    let c1 = process_cpu_seconds();
    let (winding, fallbacks) = oracle.winding_numbers_counted(&queries, mode).in_file(&args.points)?;
    let winding_s = t1.elapsed().as_secs_f64();
    let winding_cpu_s = process_cpu_seconds().zip(c1).map(|(b, a)| b - a);
    let t2 = Instant::now();
    let c2 = process_cpu_seconds();
    let closest = oracle.closest_points(&queries).in_file(&args.points)?;
    let distance_s = t2.elapsed().as_secs_f64();
    let distance_cpu_s = process_cpu_seconds().zip(c2).map(|(b, a)| b - a);

    // The workspace's one inside rule (|w| ≥ 0.5), as for sampling, training and IoU.
    let occupancy: Vec<u8> = winding.iter().map(|&w| config.is_inside_winding(w) as u8).collect();
    let sdf: Vec<f64> = winding
        .iter()
        .zip(&closest)
        .map(|(&w, c)| {
            let d = c.squared_distance.sqrt();
            if config.is_inside_winding(w) {
                -d
            } else {
                d
            }
        })
        .collect();
    let points: Vec<[f64; 3]> = closest.iter().map(|c| c.point).collect();
    let sqd: Vec<f64> = closest.iter().map(|c| c.squared_distance).collect();
    let tri: Vec<u32> = closest.iter().map(|c| c.triangle).collect();

    let mut npz = Npz::new();
    npz.add("winding", &vec_array(&winding))?;
    npz.add("occupancy", &vec_array(&occupancy))?;
    npz.add("sdf", &vec_array(&sdf))?;
    npz.add_rows("closest", &points)?;
    npz.add("squared_distance", &vec_array(&sqd))?;
    npz.add("triangle", &vec_array(&tri))?;
    add_config(&mut npz, &config, args.exact)?;
    npz.add("winding_exact_fallbacks", &ndarray::arr0(fallbacks))?;
    npz.write(&args.output)?;
    if args.timings {
        let json = |x: Option<f64>| x.map_or("null".to_string(), |v| format!("{v:.3}"));
        eprintln!(
            "{{\"num_queries\": {}, \"num_triangles\": {}, \"threads\": {}, \"build_s\": {build_s:.6}, \"winding_s\": {winding_s:.6}, \"distance_s\": {distance_s:.6}, \"winding_cpu_s\": {}, \"distance_cpu_s\": {}, \"exact_fallbacks\": {fallbacks}, \"simd\": \"{}\"}}",
            queries.len(),
            oracle.num_triangles(),
            available_threads(),
            json(winding_cpu_s),
            json(distance_cpu_s),
            occupancy::winding::fast::simd_path(),
        );
    }
    Ok(())
}

/// Records the thresholds used, as 0-d arrays (STYLE: thresholds recorded in outputs).
pub fn add_config(npz: &mut Npz, config: &Config, exact: bool) -> Result<(), CliError> {
    npz.add("winding_exact", &ndarray::arr0(exact as u8))?;
    npz.add("winding_beta", &ndarray::arr0(config.beta))?;
    npz.add("winding_exact_fallback_margin", &ndarray::arr0(config.exact_fallback_margin))?;
    npz.add("occupancy_threshold", &ndarray::arr0(config.occupancy_threshold))?;
    Ok(())
}

/// CPU time of this process (user + system, all threads) in seconds, from /proc on Linux
/// (10 ms resolution); `None` elsewhere.
fn process_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit(')').next()?.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

fn available_threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}
