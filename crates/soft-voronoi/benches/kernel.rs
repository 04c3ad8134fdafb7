//! Criterion benches: one training step (reconstruction term) at K = 4096 sites and
//! N = 65,536 samples, β = 10,000, sparse kernel; the polish's 11-nearest query.

use criterion::{criterion_group, criterion_main, Criterion};
use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;
use soft_voronoi::init::paper_init;
use soft_voronoi::kernel::{Kernel, SiteIndex};
use soft_voronoi::knn::KnnTree;
use soft_voronoi::losses;
use std::num::NonZero;

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
    // The polish's query: the 11 nearest sites of each of 20,000 points, with this crate's
    // exact fixed-k tree and with kiddo's k-nearest query (what the polish used before).
    let (queries, _) = paper_init(20_000, 3);
    g.bench_function("knn11_k4096_q20000_knntree", |b| {
        b.iter(|| {
            let tree = KnnTree::new(&sites);
            let mut out = Vec::new();
            queries
                .iter()
                .map(|&x| {
                    tree.k_nearest(x, 11, &mut out);
                    out[10].1 as u64
                })
                .sum::<u64>()
        })
    });
    g.bench_function("knn11_k4096_q20000_kiddo", |b| {
        b.iter(|| {
            let tree: ImmutableKdTree<f64, u32, 3, 32> = ImmutableKdTree::new_from_slice(&sites);
            let k = NonZero::new(11).unwrap();
            queries.iter().map(|x| tree.nearest_n::<SquaredEuclidean>(x, k)[10].item as u64).sum::<u64>()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
