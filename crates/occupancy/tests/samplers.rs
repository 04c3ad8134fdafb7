//! Samplers: deterministic whatever the thread count, and distributed as documented.

mod common;

use occupancy::sample::{near_surface, uniform_in_box, SurfaceSampler, SAMPLE_CHUNK};
use occupancy::{Config, MeshOracle, OccupancyError};

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
}

#[test]
fn samplers_do_not_depend_on_thread_count() {
    let (p, t) = common::icosphere(3);
    let n = 3 * SAMPLE_CHUNK + 17;
    let run = || {
        let u = uniform_in_box([-1.0, -2.0, 0.0], [1.0, 2.0, 3.0], n, 99).unwrap();
        let s = SurfaceSampler::new(&p, &t).unwrap();
        let surf = s.sample(n, 99);
        let near = near_surface(&s, n, &[0.01, 0.1], 99).unwrap();
        (u, surf, near)
    };
    let one = in_pool(1, run);
    let three = in_pool(3, run);
    assert!(one == three);
    // A different seed changes everything.
    let other = uniform_in_box([-1.0, -2.0, 0.0], [1.0, 2.0, 3.0], n, 100).unwrap();
    assert_ne!(one.0, other);
    // A prefix request reproduces the prefix (chunks are independent of n) for uniform.
    let prefix = uniform_in_box([-1.0, -2.0, 0.0], [1.0, 2.0, 3.0], 100, 99).unwrap();
    assert_eq!(&one.0[..100], &prefix[..]);
}

#[test]
fn uniform_points_fill_the_box() {
    let lo = [-1.0, 2.0, 10.0];
    let hi = [3.0, 2.5, 11.0];
    let pts = uniform_in_box(lo, hi, 100_000, 1).unwrap();
    let mut mean = [0.0; 3];
    for p in &pts {
        for k in 0..3 {
            assert!(p[k] >= lo[k] && p[k] < hi[k]);
            mean[k] += p[k] / pts.len() as f64;
        }
    }
    for k in 0..3 {
        let c = 0.5 * (lo[k] + hi[k]);
        assert!((mean[k] - c).abs() < 0.01 * (hi[k] - lo[k]), "{mean:?}");
    }
}

#[test]
fn surface_samples_lie_on_their_triangles_with_unit_normals() {
    for (name, (p, t)) in common::meshes_by_class() {
        let s = SurfaceSampler::new(&p, &t).unwrap();
        let samples = s.sample(2000, 5);
        let oracle = MeshOracle::new(&p, &t, &Config::default()).unwrap();
        let (lo, hi) = oracle.bounding_box();
        let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let closest = oracle.closest_points(&samples.points).unwrap();
        for i in 0..samples.points.len() {
            assert!(closest[i].squared_distance.sqrt() < 1e-12 * diag, "{name}");
            let n = samples.normals[i];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-12, "{name}");
            let [a, b, c] = t[samples.triangles[i] as usize].map(|v| p[v as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            // Normal is perpendicular to both edges and the point is on the plane.
            let d1 = n[0] * e1[0] + n[1] * e1[1] + n[2] * e1[2];
            let d2 = n[0] * e2[0] + n[1] * e2[1] + n[2] * e2[2];
            assert!(d1.abs() < 1e-9 * diag && d2.abs() < 1e-9 * diag, "{name}");
        }
    }
}

#[test]
fn surface_samples_are_area_weighted() {
    // Two triangles, the second with 3× the area, get samples in ratio 1:3.
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [5.0, 0.0, 0.0], [8.0, 0.0, 0.0], [5.0, 1.0, 0.0]];
    let t = [[0, 1, 2], [3, 4, 5]];
    let s = SurfaceSampler::new(&p, &t).unwrap();
    let samples = s.sample(100_000, 3);
    let second = samples.triangles.iter().filter(|&&x| x == 1).count() as f64;
    assert!((second / 100_000.0 - 0.75).abs() < 0.01, "{second}");
}

#[test]
fn near_surface_offsets_follow_their_sigmas() {
    let (p, t) = common::icosphere(4);
    let s = SurfaceSampler::new(&p, &t).unwrap();
    let sigmas = [0.001, 0.05];
    let n = 40_000;
    let pts = near_surface(&s, n, &sigmas, 8).unwrap();
    let oracle = MeshOracle::new(&p, &t, &Config::default()).unwrap();
    let closest = oracle.closest_points(&pts).unwrap();
    for (b, sigma) in sigmas.iter().enumerate() {
        let block = &closest[b * n / 2..(b + 1) * n / 2];
        // The distance to a locally flat surface is |normal component| of the offset,
        // so its mean square is σ² (curvature changes this by < 10% here).
        let ms = block.iter().map(|c| c.squared_distance).sum::<f64>() / block.len() as f64;
        let ratio = ms.sqrt() / sigma;
        assert!((0.9..1.1).contains(&ratio), "sigma {sigma}: rms distance ratio {ratio}");
    }
}

#[test]
fn sampler_errors_explain_the_problem() {
    let p = [[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let e = SurfaceSampler::new(&p, &[[0, 1, 2]]).unwrap_err();
    assert!(matches!(e, OccupancyError::BadSampler(_)), "{e}");
    let (p, t) = common::icosphere(1);
    let s = SurfaceSampler::new(&p, &t).unwrap();
    assert!(near_surface(&s, 10, &[], 1).is_err());
    assert!(near_surface(&s, 10, &[f64::NAN], 1).is_err());
    assert!(uniform_in_box([1.0; 3], [0.0; 3], 10, 1).is_err());
    assert!(matches!(SurfaceSampler::new(&p, &[[0, 1, 99]]), Err(OccupancyError::VertexOutOfRange { .. })));
}

/// The labelled set of `voronoi-fit sample`: the uniform points first (in the padded box),
/// then the near-surface ones; labels by the one inside rule, the signed distance negative
/// exactly where the label is inside; reproducible from the seed; out-of-range specs named.
#[test]
fn labelled_samples_are_the_box_then_the_surface_with_consistent_labels() {
    use occupancy::sample::{labelled_samples, SampleSpec, SurfaceSampler};
    let mesh = mesh_io::shapes::cuboid([0.0; 3], [1.0, 2.0, 3.0]);
    let oracle = occupancy::MeshOracle::from_mesh(&mesh, &occupancy::Config::default()).unwrap();
    let spec = SampleSpec {
        num_samples: 10_001,
        uniform_fraction: 0.3,
        padding: 0.1,
        near_sigma: vec![0.01, 0.003],
        seed: 7,
        exact: false,
    };
    let mut reports = Vec::new();
    let s = labelled_samples(&oracle, || SurfaceSampler::from_mesh(&mesh), &spec, &mut |n| reports.push(n)).unwrap();
    assert_eq!(s.points.len(), 10_001);
    assert_eq!((s.winding.len(), s.occupancy.len(), s.sdf.len()), (10_001, 10_001, 10_001));
    assert_eq!(reports.last(), Some(&10_001));
    let num_uniform = 3_000; // round(10,001 × 0.3)
    let (lo, hi) = ([-0.1, -0.2, -0.3], [1.1, 2.2, 3.3]);
    for p in &s.points[..num_uniform] {
        assert!((0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]), "{p:?} outside the padded box");
    }
    let inside_box = |p: &[f64; 3]| (0..3).all(|k| p[k] > 0.0 && p[k] < [1.0, 2.0, 3.0][k]);
    let mut wrong = 0;
    for i in 0..s.points.len() {
        assert_eq!(s.occupancy[i] == 1, s.winding[i].abs() >= 0.5, "label of point {i}");
        assert!(s.sdf[i] == 0.0 || (s.sdf[i] < 0.0) == (s.occupancy[i] == 1), "sdf sign of point {i}");
        wrong += usize::from(inside_box(&s.points[i]) != (s.occupancy[i] == 1));
    }
    // The fast winding number may differ from the box test only on the surface itself.
    assert!(wrong <= 2, "{wrong} labels disagree with the box");
    let diag = (1.0f64 + 4.0 + 9.0).sqrt();
    let near = &s.sdf[num_uniform..];
    let mean = near.iter().map(|d| d.abs()).sum::<f64>() / near.len() as f64;
    assert!(mean < 0.02 * diag, "near-surface points are near: mean |sdf| {mean}");
    let again = labelled_samples(&oracle, || SurfaceSampler::from_mesh(&mesh), &spec, &mut |_| {}).unwrap();
    assert_eq!(again, s, "the same seed gives the same set");
    for (bad, flag) in [
        (SampleSpec { num_samples: 0, ..spec.clone() }, "-n"),
        (SampleSpec { uniform_fraction: 1.5, ..spec.clone() }, "--uniform-fraction"),
        (SampleSpec { padding: f64::NAN, ..spec.clone() }, "--padding"),
        (SampleSpec { near_sigma: vec![-1.0], ..spec.clone() }, "--near-sigma"),
    ] {
        let e = labelled_samples(&oracle, || SurfaceSampler::from_mesh(&mesh), &bad, &mut |_| {}).unwrap_err();
        assert!(e.to_string().contains(flag), "{e}");
    }
}
