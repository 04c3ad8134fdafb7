//! Criterion benches: one training step (reconstruction term) at K = 4096 sites and
//! N = 65,536 samples, β = 10,000, sparse kernel.

use criterion::{criterion_group, criterion_main, Criterion};
use soft_voronoi::init::paper_init;
use soft_voronoi::kernel::{Kernel, SiteIndex};
use soft_voronoi::losses;

fn bench(c: &mut Criterion) {
    let (sites, labels) = paper_init(4096, 1);
    let (points, occ) = paper_init(65536, 2);
    let kernel = Kernel::new(10_000.0);
    let mut g = c.benchmark_group("soft_voronoi");
    g.sample_size(10);
    g.bench_function("step_k4096_n65536", |b| {
        b.iter(|| {
            let index = SiteIndex::new(&sites);
            let mut grad = vec![[0.0; 3]; sites.len()];
            losses::reconstruction(&kernel, &index, &sites, &labels, &points, &occ, 1.0, &mut grad)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
