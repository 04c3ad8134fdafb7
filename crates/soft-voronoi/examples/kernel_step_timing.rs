//! Times the sparse soft-Voronoi training step (k-d tree build + reconstruction loss and
//! gradient over the batch) and prints one JSON line; `benches/compare_soft_voronoi.py`
//! runs it beside a dense numpy step of the same size.
//!
//! `cargo run --release -p soft-voronoi --example kernel_step_timing -- [K] [N] [REPEATS] [BETA]`
//! Sites uniform in the unit cube labelled by a ball of radius 0.35, samples uniform.

use std::time::Instant;

use soft_voronoi::init::paper_init;
use soft_voronoi::kernel::{Kernel, SiteIndex};
use soft_voronoi::losses;

fn main() {
    let args: Vec<f64> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let k = args.first().map_or(4096, |&x| x as usize);
    let n = args.get(1).map_or(65536, |&x| x as usize);
    let repeats = args.get(2).map_or(20, |&x| x as usize).max(1);
    let beta = args.get(3).copied().unwrap_or(10_000.0);
    let ball = |p: &[f64; 3]| ((p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2)).sqrt() < 0.35;
    let (sites, _) = paper_init(k, 1);
    let labels: Vec<bool> = sites.iter().map(ball).collect();
    let (points, _) = paper_init(n, 2);
    let occupancy: Vec<bool> = points.iter().map(ball).collect();
    let kernel = Kernel::new(beta);
    let mut grad = vec![[0.0; 3]; k];
    let mut times = Vec::new();
    let mut loss = 0.0;
    for _ in 0..repeats + 1 {
        let t = Instant::now();
        grad.iter_mut().for_each(|g| *g = [0.0; 3]);
        let index = SiteIndex::new(&sites);
        loss = losses::reconstruction(&kernel, &index, &sites, &labels, &points, &occupancy, 1.0, &mut grad);
        times.push(t.elapsed().as_secs_f64());
    }
    times.remove(0); // warm-up
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    println!(
        "{{\"k\": {k}, \"n\": {n}, \"beta\": {beta}, \"threads\": {}, \"repeats\": {repeats}, \"median_seconds\": {median}, \"steps_per_second\": {}, \"loss\": {loss}}}",
        rayon::current_num_threads(),
        1.0 / median
    );
}
