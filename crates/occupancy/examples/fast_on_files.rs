//! The fast winding number on any mesh files (read with mesh-io): the β used
//! (`MeshOracle::beta`), max error against the exact one, queries above 1e-3, inside/outside
//! flips, the share of queries the exact fallback band recomputes, work per query and time,
//! on the issue's query sets (half uniform in the box grown 10%, half surface samples +
//! N(0, (1% diag)²)):
//!
//! `cargo run --release -p occupancy --example fast_on_files -- N MESH...`
//!
//! `VF_BETA=B` sets `Config::beta` (default 3.5; the mesh's β is then B·max(1, A/A_box)^¼).
//!
//! Exact values are cached in /tmp (`exact_STEM_#V_#F_N.bin`) between runs.
use occupancy::{Config, MeshOracle, WindingMode};
#[path = "../tests/common/mod.rs"]
mod common;
fn main() {
    let (n, meshes) = common::count_and_meshes_from_args();
    for (name, mesh) in meshes {
        let queries = common::issue_queries(&mesh, n, 42);
        let cache = format!("/tmp/exact_{name}_{}_{}_{n}.bin", mesh.0.len(), mesh.1.len());
        let exact: Vec<f64> = if let Ok(b) = std::fs::read(&cache) {
            b.chunks(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect()
        } else {
            let e = MeshOracle::new(&mesh.0, &mesh.1, &Config::default())
                .unwrap()
                .winding_numbers(&queries, WindingMode::Exact)
                .unwrap();
            std::fs::write(&cache, e.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>()).unwrap();
            e
        };
        let beta = std::env::var("VF_BETA").ok().map(|s| s.parse().unwrap()).unwrap_or(3.5);
        let cfg = Config { exact_fallback_margin: 0.0, beta, ..Config::default() };
        let o = MeshOracle::new(&mesh.0, &mesh.1, &cfg).unwrap();
        let t = std::time::Instant::now();
        let w = o.winding_numbers(&queries, WindingMode::Fast).unwrap();
        let s = t.elapsed().as_secs_f64();
        let sampled: Vec<[f64; 3]> = queries.iter().step_by(20).copied().collect();
        let work = common::fast_work_per_query(&o, &sampled);
        let errs: Vec<f64> = w.iter().zip(&exact).map(|(a, b)| (a - b).abs()).collect();
        let max = errs.iter().cloned().fold(0.0, f64::max);
        let over = errs.iter().filter(|e| **e > 1e-3).count();
        let flips = w.iter().zip(&exact).filter(|(a, b)| (a.abs() >= 0.5) != (b.abs() >= 0.5)).count();
        let g = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        let (_, fb) = g.winding_numbers_counted(&queries, WindingMode::Fast).unwrap();
        println!("{:>14} F={:>6} beta {:.2} maxerr {:.2e} >1e-3: {:>4} flips {:>3} | fallback {:.3}% | visited {:>6.1} exp {:>6.1} tris {:>6.1} | {:.2} us/q",
            name, mesh.1.len(), o.beta(), max, over, flips, fb as f64 / n as f64 * 100.0, work[0], work[1], work[2], s / n as f64 * 1e6);
    }
}
