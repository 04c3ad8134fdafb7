//! Inside/outside by crossing counts against the solid-angle path on any mesh files (read
//! with mesh-io): whether the mesh is closed, disagreements, and the time of each, on the
//! issue's query sets plus up to 20,000 vertices and triangle centroids (queries on the
//! surface; `NO_SURFACE=1` leaves them out, `DEBUG=1` prints the first disagreements):
//!
//! `cargo run --release -p occupancy --example crossing_on_files -- N MESH...`
use occupancy::{Config, MeshOracle, WindingMode, Workspace};
#[path = "../tests/common/mod.rs"]
mod common;
fn main() {
    let (n, meshes) = common::count_and_meshes_from_args();
    for (name, (positions, triangles)) in meshes {
        let mut queries = common::issue_queries(&(positions.clone(), triangles.clone()), n, 42);
        if std::env::var("NO_SURFACE").is_err() {
            queries.extend(positions.iter().take(20_000));
            queries.extend(triangles.iter().take(20_000).map(|t| {
                let p = t.map(|i| positions[i as usize]);
                [0, 1, 2].map(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0)
            }));
        }
        let o = MeshOracle::new(&positions, &triangles, &Config::default()).unwrap();
        if !o.is_closed() {
            println!("{name:>22} F={:>6}: not closed (the solid-angle path is used)", triangles.len());
            continue;
        }
        let t = std::time::Instant::now();
        let a = o.inside_by_winding(&queries).unwrap();
        let ta = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let b = o.inside_by_crossings(&queries);
        let tb = t.elapsed().as_secs_f64();
        let differ: Vec<usize> = (0..a.len()).filter(|&i| a[i] != b[i]).collect();
        if std::env::var("DEBUG").is_ok() {
            let mut ws = Workspace::new();
            for &i in differ.iter().take(8) {
                let w = o.winding_number(queries[i], WindingMode::Exact, &mut ws);
                println!("  {:?}: exact winding {w}, solid angles {}, crossings {}", queries[i], a[i], b[i]);
            }
        }
        let q = queries.len() as f64;
        println!(
            "{name:>22} F={:>6}: {} queries, {} disagree; solid angles {:.2} us/q, crossings {:.2} us/q ({:.1}x)",
            triangles.len(),
            queries.len(),
            differ.len(),
            ta / q * 1e6,
            tb / q * 1e6,
            ta / tb
        );
    }
}
