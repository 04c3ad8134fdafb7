//! Times the polish's 11-nearest query on a grid against the k-d tree, on sites laid out as
//! the polish sees them (inside/outside pairs about a surface) with queries on the surface.
//! `cargo run --profile ci -p soft-voronoi --example grid_timing [SITES]`
use std::time::Instant;

use soft_voronoi::grid::{cell_for, KnnGrid};
use soft_voronoi::knn::KnnTree;
use vf_common::rng::{ChunkRng, Stream};

fn main() {
    let k_sites: usize = std::env::args().nth(1).and_then(|a| a.parse().ok()).unwrap_or(8192);
    let mut rng = ChunkRng::for_chunk(1, Stream::TrainBatch, 0);
    let mut u = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
    let mut on_sphere = |r: f64| {
        let (z, t) = (2.0 * u() - 1.0, std::f64::consts::TAU * u());
        let s = (1.0 - z * z).sqrt();
        [0.5 + r * s * t.cos(), 0.5 + r * s * t.sin(), 0.5 + r * z]
    };
    // Pairs 0.3 spacings apart across a sphere of radius 0.4.
    let spacing = (4.0 * std::f64::consts::PI * 0.16 / (k_sites as f64 / 2.0)).sqrt();
    let mut sites = Vec::new();
    for _ in 0..k_sites / 2 {
        let p = on_sphere(1.0);
        for side in [-1.0, 1.0] {
            let r = 0.4 + side * 0.3 * spacing;
            sites.push([0.5 + (p[0] - 0.5) * r, 0.5 + (p[1] - 0.5) * r, 0.5 + (p[2] - 0.5) * r]);
        }
    }
    let queries: Vec<[f64; 3]> = (0..20_000).map(|_| on_sphere(0.4)).collect();
    let tree = KnnTree::new(&sites);
    let mut out = Vec::new();
    let mut acc = 0.0;
    let reps = 5;
    let t = Instant::now();
    for _ in 0..reps {
        for &x in &queries {
            tree.k_nearest(x, 11, &mut out);
            acc += out[10].0;
        }
    }
    let per = |t: Instant| t.elapsed().as_secs_f64() / (reps * queries.len()) as f64 * 1e6;
    println!("tree: {:.2} µs a query", per(t));
    let base = cell_for(&sites, &queries, 11);
    let mut sorted = queries.clone();
    for factor in [0.5, 0.75, 1.0, 1.25, 1.5] {
        let grid = KnnGrid::new(&sites, base * factor);
        sorted.sort_by_key(|&x| grid.cell_key(x));
        let mut buf = Vec::new();
        let mut alone = 0usize;
        let t = Instant::now();
        for _ in 0..reps {
            for &x in &sorted {
                alone += usize::from(grid.k_nearest_with(x, 11, &mut out, &mut buf));
                acc += out[10].0;
            }
        }
        println!(
            "grid, cell {factor} × the 80th percentile: {:.2} µs a query, {:.1}% answered alone",
            per(t),
            100.0 * alone as f64 / (reps * queries.len()) as f64
        );
    }
    println!("(checksum {acc:.3})");
}
