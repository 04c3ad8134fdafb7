//! Criterion benchmarks: `delaunay/<class>/<n>`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use delaunay3::Delaunay3;

fn uniform(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut s = seed;
    let mut next = move || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n).map(|_| [next(), next(), next()]).collect()
}

fn lattice(k: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::with_capacity(k * k * k);
    for x in 0..k {
        for y in 0..k {
            for z in 0..k {
                v.push([x as f64, y as f64, z as f64]);
            }
        }
    }
    v
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("delaunay");
    g.sample_size(10);
    for &n in &[10_000usize, 100_000, 1_000_000] {
        let pts = uniform(n, 1);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::new("uniform", n), &pts, |b, pts| {
            b.iter(|| Delaunay3::new(pts).unwrap().num_finite_tets())
        });
    }
    let pts = lattice(30);
    g.throughput(Throughput::Elements(pts.len() as u64));
    g.bench_with_input(BenchmarkId::new("lattice", pts.len()), &pts, |b, pts| {
        b.iter(|| Delaunay3::new(pts).unwrap().num_finite_tets())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
