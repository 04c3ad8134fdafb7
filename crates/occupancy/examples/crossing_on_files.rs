//! Inside/outside by crossing counts against the solid-angle path on any mesh files (read
//! with mesh-io): whether the mesh is closed, disagreements (there must be none), and the
//! time of each, on the issue's query sets plus every vertex and triangle centroid (queries
//! on the surface):
//!
//! `cargo run --release -p occupancy --example crossing_on_files -- N MESH...`
use occupancy::{Config, MeshOracle};
#[path = "../tests/common/mod.rs"]
mod common;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args[1].parse().unwrap();
    for path in &args[2..] {
        let m = mesh_io::read_mesh(std::path::Path::new(path)).unwrap();
        let mesh = (m.positions.clone(), m.triangles.clone());
        let mut queries = common::issue_queries(&mesh, n, 42);
        let surface = std::env::var("NO_SURFACE").is_err();
        if surface {
            queries.extend(m.positions.iter().take(20_000));
            queries.extend(m.triangles.iter().take(20_000).map(|t| {
                let p = t.map(|i| m.positions[i as usize]);
                [0, 1, 2].map(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0)
            }));
        }
        let o = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        let name = std::path::Path::new(path).file_stem().unwrap().to_string_lossy().to_string();
        if !o.is_closed() {
            println!("{name:>22} F={:>6}: not closed (the solid-angle path is used)", mesh.1.len());
            continue;
        }
        let t = std::time::Instant::now();
        let a = o.inside_by_winding(&queries).unwrap();
        let ta = t.elapsed().as_secs_f64();
        let t = std::time::Instant::now();
        let b = o.inside_by_crossings(&queries);
        let tb = t.elapsed().as_secs_f64();
        let diff = a.iter().zip(&b).filter(|(x, y)| x != y).count();
        if std::env::var("DEBUG").is_ok() {
            let mut ws = occupancy::Workspace::new();
            for (i, _) in a.iter().zip(&b).enumerate().filter(|(_, (x, y))| x != y).take(8) {
                let q = queries[i];
                let we = o.winding_number(q, occupancy::WindingMode::Exact, &mut ws);
                let wf = o.winding_number(q, occupancy::WindingMode::Fast, &mut ws);
                println!("  q#{i} {:?} exact {we} fast {wf} winding-path {} crossing-path {}", q, a[i], b[i]);
            }
        }
        let q = queries.len() as f64;
        println!(
            "{name:>22} F={:>6}: {} queries, {diff} disagree; solid angles {:.2} us/q, crossings {:.2} us/q ({:.1}x)",
            mesh.1.len(),
            queries.len(),
            ta / q * 1e6,
            tb / q * 1e6,
            ta / tb
        );
    }
}
