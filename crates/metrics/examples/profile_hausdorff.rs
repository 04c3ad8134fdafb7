//! Where the certified Hausdorff time goes: BVH builds vs the search.
//!
//!     cargo run --release -p metrics --example profile_hausdorff -- A B

use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let a = mesh_io::read_mesh(std::path::Path::new(&args[1])).expect("A");
    let b = mesh_io::read_mesh(std::path::Path::new(&args[2])).expect("B");
    for _ in 0..3 {
        let t = Instant::now();
        let da = metrics::DistanceMesh::with_preset(&a, "A", occupancy::BvhPreset::VeryFast).expect("A");
        let t_a = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let db = metrics::DistanceMesh::with_preset(&b, "B", occupancy::BvhPreset::VeryFast).expect("B");
        let t_b = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let r = metrics::hausdorff::certify_prepared(&da, &db, &Default::default()).expect("certify");
        let t_c = t.elapsed().as_secs_f64();
        println!(
            "build A {t_a:.3} s, build B {t_b:.3} s, search {t_c:.3} s: [{}, {}] depth {} cells {} queries {}",
            r.lo, r.hi, r.depth, r.cells_evaluated, r.queries
        );
    }
}
