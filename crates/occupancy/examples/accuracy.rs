//! Measures the fast winding number's error against the exact one on the issue's query
//! sets, for several β, and the time of each mode.
//!
//! `cargo run --release -p occupancy --example accuracy -- [NUM_QUERIES] [BETA...]`

use std::time::Instant;

use occupancy::{Config, MeshOracle, WindingMode};

#[path = "../tests/common/mod.rs"]
mod common;

/// Process CPU time (user + system, all threads) in seconds, from /proc (Linux).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    if f.len() < 13 {
        return f64::NAN;
    }
    let ticks: f64 = f[11].parse::<f64>().unwrap() + f[12].parse::<f64>().unwrap();
    ticks / 100.0
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(1_000_000);
    let betas: Vec<f64> =
        if args.len() > 2 { args[2..].iter().map(|s| s.parse().unwrap()).collect() } else { vec![2.0, 2.5, 3.0] };
    let mut meshes = vec![("icosphere20480".to_string(), common::icosphere(5))];
    for name in ["mikedh__bunny.ply", "mikedh__teapot.stl", "mikedh__soup.stl"] {
        if let Some(m) = common::shared_mesh(name) {
            meshes.push((name.to_string(), m));
        }
    }
    println!("queries per mesh: {n}");
    println!("mesh | faces | beta | max |fast-exact| | flips (unguarded) | flips (guarded) | fallbacks | t_exact s | t_fast s");
    for (name, mesh) in &meshes {
        let queries = common::issue_queries(mesh, n, 42);
        let exact_oracle = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        let t = Instant::now();
        let c0 = cpu_seconds();
        let exact = exact_oracle.winding_numbers(&queries, WindingMode::Exact).unwrap();
        let t_exact = t.elapsed().as_secs_f64();
        let cpu_exact = cpu_seconds() - c0;
        for &beta in &betas {
            let leaf: u32 = std::env::var("LEAF").ok().map(|s| s.parse().unwrap()).unwrap_or(2);
            let raw_config = Config { beta, winding_leaf_size: leaf, exact_fallback_margin: 0.0, ..Config::default() };
            let guarded_config = Config { beta, winding_leaf_size: leaf, ..Config::default() };
            let raw = MeshOracle::new(&mesh.0, &mesh.1, &raw_config).unwrap();
            let guarded = MeshOracle::new(&mesh.0, &mesh.1, &guarded_config).unwrap();
            let t = Instant::now();
            let c0 = cpu_seconds();
            let fast_raw = raw.winding_numbers(&queries, WindingMode::Fast).unwrap();
            let t_fast = t.elapsed().as_secs_f64();
            let cpu_fast = cpu_seconds() - c0;
            let batch = guarded.query(&queries, WindingMode::Fast).unwrap();
            let mut ws = occupancy::Workspace::new();
            let mut work_fast = [0u64; 3];
            let mut work_exact = [0u64; 3];
            for q in queries.iter().step_by(10) {
                let a = raw.winding_work(*q, WindingMode::Fast, &mut ws);
                let b = raw.winding_work(*q, WindingMode::Exact, &mut ws);
                for k in 0..3 {
                    work_fast[k] += a[k];
                    work_exact[k] += b[k];
                }
            }
            let m = queries.iter().step_by(10).count() as f64;
            println!(
                "  work per query: fast nodes {:.0} expansions {:.0} triangles {:.0}; exact nodes {:.0} cap tris {:.0} triangles {:.0}; cap edges stored {}",
                work_fast[0] as f64 / m, work_fast[1] as f64 / m, work_fast[2] as f64 / m,
                work_exact[0] as f64 / m, work_exact[1] as f64 / m, work_exact[2] as f64 / m,
                raw.num_cap_edges()
            );
            let max_err = fast_raw.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            let flips_raw = fast_raw.iter().zip(&exact).filter(|(a, b)| (**a >= 0.5) != (**b >= 0.5)).count();
            let flips = batch.winding.iter().zip(&exact).filter(|(a, b)| (**a >= 0.5) != (**b >= 0.5)).count();
            println!(
                "{name} | {} | {beta} | {max_err:.3e} | {flips_raw} | {flips} | {} | {t_exact:.3} ({cpu_exact:.2} cpu) | {t_fast:.3} ({cpu_fast:.2} cpu)",
                mesh.1.len(),
                batch.num_exact_fallbacks
            );
        }
    }
}
