//! Tail of the fast winding number's error distribution (how many queries exceed a given
//! error) for several β: `cargo run --release -p occupancy --example error_tail -- N BETA...`

use occupancy::{Config, MeshOracle, WindingMode};

#[path = "../tests/common/mod.rs"]
mod common;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(100_000);
    let betas: Vec<f64> = args[2..].iter().map(|s| s.parse().unwrap()).collect();
    let mut meshes = vec![("icosphere20480".to_string(), common::icosphere(5))];
    for name in ["mikedh__bunny.ply", "mikedh__teapot.stl"] {
        if let Some(m) = common::shared_mesh(name) {
            meshes.push((name.to_string(), m));
        }
    }
    for (name, mesh) in &meshes {
        let queries = common::issue_queries(mesh, n, 42);
        let exact = MeshOracle::new(&mesh.0, &mesh.1, &Config::default())
            .unwrap()
            .winding_numbers(&queries, WindingMode::Exact)
            .unwrap();
        for &beta in &betas {
            let config = Config { beta, exact_fallback_margin: 0.0, ..Config::default() };
            let fast = MeshOracle::new(&mesh.0, &mesh.1, &config)
                .unwrap()
                .winding_numbers(&queries, WindingMode::Fast)
                .unwrap();
            let mut err: Vec<f64> = fast.iter().zip(&exact).map(|(a, b)| (a - b).abs()).collect();
            err.sort_by(f64::total_cmp);
            let count = |t: f64| err.iter().filter(|&&e| e > t).count();
            println!(
                "{name} beta {beta}: median {:.1e} p99 {:.1e} p99.9 {:.1e} max {:.1e}; >1e-3: {} >5e-4: {} >2e-4: {}",
                err[n / 2],
                err[n * 99 / 100],
                err[n * 999 / 1000],
                err[n - 1],
                count(1e-3),
                count(5e-4),
                count(2e-4)
            );
        }
    }
}
