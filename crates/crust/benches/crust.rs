//! Crust extraction against the Delaunay tetrahedralization it rests on, for ball-labelled
//! uniform sites (the benchmark: crust ≤ 1.5 × Delaunay time at 100,000 sites).
//!
//!     cargo bench -p crust

use criterion::{criterion_group, criterion_main, Criterion};
use crust::{Crust, CrustConfig};

fn sites(k: usize) -> (Vec<[f64; 3]>, Vec<bool>) {
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    let mut r = || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        ((s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let pts: Vec<[f64; 3]> = (0..k).map(|_| [r(), r(), r()]).collect();
    let inside =
        pts.iter().map(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2) < 0.35 * 0.35).collect();
    (pts, inside)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("crust");
    g.sample_size(10);
    for k in [10_000usize, 100_000] {
        let (pts, inside) = sites(k);
        g.bench_function(format!("delaunay/ball/{k}"), |b| b.iter(|| delaunay3::Delaunay3::new(&pts).unwrap()));
        g.bench_function(format!("extract/ball/{k}"), |b| {
            b.iter(|| Crust::extract(&pts, &inside, &CrustConfig::default()).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
