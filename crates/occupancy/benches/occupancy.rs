//! Criterion benches of the core loops. Ids: `area/variant/mesh`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use occupancy::{Config, MeshOracle, WindingMode};

#[path = "../tests/common/mod.rs"]
mod common;

const NUM_QUERIES: usize = 20_000;

fn bench_meshes() -> Vec<(&'static str, common::Mesh)> {
    let mut out = vec![("icosphere20480", common::icosphere(5))];
    if let Some(m) = common::shared_mesh("mikedh__bunny.ply") {
        out.push(("bunny", m));
    }
    if let Some(m) = common::shared_mesh("mikedh__teapot.stl") {
        out.push(("teapot", m));
    }
    out
}

fn benches(c: &mut Criterion) {
    for (name, mesh) in bench_meshes() {
        let queries = common::issue_queries(&mesh, NUM_QUERIES, 1);
        let config = Config::default();
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &config).unwrap();
        let mut group = c.benchmark_group("occupancy");
        group.sample_size(10);
        group.throughput(Throughput::Elements(queries.len() as u64));
        group.bench_function(BenchmarkId::new("winding/fast", name), |b| {
            b.iter(|| oracle.winding_numbers(&queries, WindingMode::Fast).unwrap())
        });
        group.bench_function(BenchmarkId::new("winding/exact", name), |b| {
            b.iter(|| oracle.winding_numbers(&queries, WindingMode::Exact).unwrap())
        });
        group.bench_function(BenchmarkId::new("distance/closest", name), |b| {
            b.iter(|| oracle.closest_points(&queries).unwrap())
        });
        group.bench_function(BenchmarkId::new("build/medium", name), |b| {
            b.iter(|| MeshOracle::new(&mesh.0, &mesh.1, &config).unwrap())
        });
        group.finish();
    }
}

criterion_group!(occupancy_benches, benches);
criterion_main!(occupancy_benches);
