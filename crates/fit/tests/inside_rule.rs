//! The one inside rule (|w| ≥ 0.5) through the whole main job: a closed body whose
//! triangles all face inward and a soup of unconnected triangles fit like the ordinary
//! sphere, and the report's IoU agrees (it used w ≥ 0.5 before and said 0 for them).

mod common;

use fit::{FitConfig, NoProgress};
use mesh_io::shapes::icosphere;
use mesh_io::TriMesh;
use occupancy::{Config, MeshOracle, WindingMode, Workspace};

fn small(name: &str) -> FitConfig {
    common::small(name, 512, 60, 40_000, 40_000)
}

fn inverted(m: &TriMesh) -> TriMesh {
    TriMesh { positions: m.positions.clone(), triangles: m.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect() }
}

/// Every triangle with its own three vertices: no shared edges at all.
fn soup(m: &TriMesh) -> TriMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for t in &m.triangles {
        let base = positions.len() as u32;
        positions.extend(t.map(|v| m.positions[v as usize]));
        triangles.push([base, base + 1, base + 2]);
    }
    TriMesh { positions, triangles }
}

fn iou(out: &fit::FitOutput) -> f64 {
    match &out.report.metrics {
        fit::report::MetricsReport::Done(m) => m.iou.as_ref().and_then(|i| i.iou).expect("an IoU"),
        other => panic!("no metrics: {other:?}"),
    }
}

#[test]
fn inward_facing_and_soup_spheres_fit_like_the_sphere() {
    let sphere = icosphere(3);
    let base = fit::fit(&sphere, &small("sphere"), &mut NoProgress).unwrap();
    for (name, mesh) in [("inverted", inverted(&sphere)), ("soup", soup(&sphere))] {
        let out = fit::fit(&mesh, &small(name), &mut NoProgress).unwrap();
        let (a, b) = (base.report.quality.misclassification, out.report.quality.misclassification);
        assert!(b < 0.05 && (a - b).abs() < 0.01, "{name}: misclassification {b} against the sphere's {a}");
        assert!(iou(&out) > 0.9, "{name}: IoU {}", iou(&out));
        assert!(out.report.crust.is_closed && out.report.crust.is_manifold, "{name}");
        // The same solid: as many inside sites (the inverted normals only swap each pair).
        let count = |o: &fit::FitOutput| o.sites.inside.iter().filter(|&&l| l).count();
        assert_eq!(count(&out), count(&base), "{name}");
    }
}

/// The fast path falls back to the exact winding number on both sides of ±0.5: on an
/// inward-facing open body (a sphere with a hole, so w takes every value in [−1, 0]),
/// points near w = −0.5 are decided exactly, and fast and exact modes never disagree about
/// inside/outside.
#[test]
fn fast_inside_matches_exact_near_minus_one_half() {
    let sphere = inverted(&icosphere(3));
    let keep: Vec<[u32; 3]> = sphere
        .triangles
        .iter()
        .copied()
        .filter(|t| t.iter().map(|&v| sphere.positions[v as usize][2]).sum::<f64>() / 3.0 < 0.6)
        .collect();
    let mesh = TriMesh { positions: sphere.positions.clone(), triangles: keep };
    let oracle = MeshOracle::from_mesh(&mesh, &Config::default()).unwrap();
    let mut ws = Workspace::new();
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut near_half = 0;
    for _ in 0..20_000 {
        let q = [0.9 * (2.0 * uniform() - 1.0), 0.9 * (2.0 * uniform() - 1.0), 0.3 + 0.7 * uniform()];
        let exact = oracle.winding_number(q, WindingMode::Exact, &mut ws);
        near_half += ((exact + 0.5).abs() < 0.01) as usize;
        assert_eq!(oracle.is_inside(q, WindingMode::Fast, &mut ws), exact.abs() >= 0.5, "at {q:?} (exact w {exact})");
    }
    assert!(near_half > 0, "no query near w = −0.5: the test does not exercise the fallback");
    assert!(
        ws.num_exact_fallbacks >= near_half as u64,
        "{} fallbacks, {near_half} queries within 0.01 of −0.5",
        ws.num_exact_fallbacks
    );
}
