//! Runs one query kind on one mesh, single-threaded friendly, for profilers:
//! `cargo run --release -p occupancy --example profile -- fast|exact|distance MESH_FILE N [BETA]
//! [WINDING_LEAF_SIZE] [veryfast|fast|medium] [MAX_LEAF_SIZE]`
//! (MESH_FILE `icosphere` builds the 20,480-face icosphere). Prints CPU-independent work
//! counts and the wall time.

use std::time::Instant;

use occupancy::{Config, MeshOracle, WindingMode};

#[path = "../tests/common/mod.rs"]
mod common;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let kind = args.get(1).map(String::as_str).unwrap_or("fast");
    let mesh_name = args.get(2).map(String::as_str).unwrap_or("mikedh__bunny.ply");
    let n: usize = args.get(3).map(|s| s.parse().unwrap()).unwrap_or(200_000);
    let mut config = Config::default();
    if let Some(b) = args.get(4) {
        config.beta = b.parse().unwrap();
    }
    if let Some(l) = args.get(5) {
        config.winding_leaf_size = l.parse().unwrap();
    }
    if let Some(l) = args.get(7) {
        config.max_leaf_size = l.parse().unwrap();
    }
    if let Some(p) = args.get(6) {
        config.bvh_preset = match p.as_str() {
            "veryfast" => occupancy::BvhPreset::VeryFast,
            "fast" => occupancy::BvhPreset::Fast,
            _ => occupancy::BvhPreset::Medium,
        };
    }
    let mesh =
        if mesh_name == "icosphere" { common::icosphere(5) } else { common::shared_mesh(mesh_name).expect("mesh") };
    let queries = common::issue_queries(&mesh, n, 42);
    let oracle = MeshOracle::new(&mesh.0, &mesh.1, &config).unwrap();
    let t = Instant::now();
    let checksum: f64 = match kind {
        "fast" => oracle.winding_numbers(&queries, WindingMode::Fast).unwrap().iter().sum(),
        "exact" => oracle.winding_numbers(&queries, WindingMode::Exact).unwrap().iter().sum(),
        "distance" => oracle.closest_points(&queries).unwrap().iter().map(|c| c.squared_distance).sum(),
        _ => panic!("kind must be fast, exact or distance"),
    };
    let s = t.elapsed().as_secs_f64();
    if kind == "fast" {
        let [visited, expansions, exact] = common::fast_work_per_query(&oracle, &queries[..n.min(20_000)]);
        println!("per query: visited {visited:.1}, expansions {expansions:.1}, exact tris {exact:.1}");
    }
    println!("{kind} {mesh_name} n={n}: {s:.3} s, {:.3} us/query (checksum {checksum:.6})", s / n as f64 * 1e6);
}
