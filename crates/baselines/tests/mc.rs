//! Marching cubes: closed, oriented, manifold output on smooth fields and on noise (all
//! ambiguity rules), exact-zero grids, the border, vertex placement, errors, and
//! `extract_mesh` on a decoder.

use baselines::{extract_mesh, marching_cubes, Ambiguity, BaselineError, Decoder, DecoderConfig, Inside, McOptions};
use mesh_io::TopologyReport;
use ndarray::Array3;

fn field(n: usize, f: impl Fn([f64; 3]) -> f64) -> Array3<f64> {
    let h = 1.0 / (n - 1) as f64;
    Array3::from_shape_fn((n, n, n), |(i, j, k)| f([i as f64 * h, j as f64 * h, k as f64 * h]))
}

fn sphere_sdf(p: [f64; 3]) -> f64 {
    ((p[0] - 0.5).powi(2) + (p[1] - 0.47).powi(2) + (p[2] - 0.52).powi(2)).sqrt() - 0.31
}

fn torus_sdf(p: [f64; 3]) -> f64 {
    let (x, y, z) = (p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
    ((x * x + y * y).sqrt() - 0.28).hypot(z) - 0.11
}

/// Uniform noise in [-1, 1] with the outer layer set to `outside` (so the surface is closed).
fn noise(n: usize, seed: u64, outside: f64) -> Array3<f64> {
    let mut s = seed | 1;
    Array3::from_shape_fn((n, n, n), |(i, j, k)| {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let v = (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0;
        if [i, j, k].iter().any(|&c| c == 0 || c == n - 1) {
            outside
        } else {
            v
        }
    })
}

fn assert_closed_manifold(rep: &TopologyReport, what: &str) {
    assert!(rep.num_faces > 0, "{what}: empty");
    assert!(rep.is_closed, "{what}: not closed ({} boundary edges)", rep.num_boundary_edges);
    assert!(
        rep.is_manifold,
        "{what}: non-manifold ({} edges, {} vertices)",
        rep.num_non_manifold_edges, rep.num_non_manifold_vertices
    );
    assert!(rep.is_orientation_consistent, "{what}: inconsistent orientation");
    assert_eq!(rep.num_duplicate_faces, 0, "{what}");
}

#[test]
fn sphere_and_torus_are_closed_with_the_right_topology_and_volume() {
    for n in [16, 33, 64] {
        let h = 1.0 / (n - 1) as f64;
        let g = field(n, sphere_sdf);
        let m = marching_cubes(g.view(), &McOptions { spacing: [h; 3], inside: Inside::Below, ..Default::default() })
            .unwrap();
        let rep = TopologyReport::of(&m);
        assert_closed_manifold(&rep, "sphere");
        assert_eq!(rep.genus, Some(0));
        assert_eq!(rep.num_components, 1);
        let v = 4.0 / 3.0 * std::f64::consts::PI * 0.31f64.powi(3);
        assert!(
            (rep.signed_volume - v).abs() < 0.05 * v * (16.0 / n as f64),
            "n {n}: volume {} vs {v}",
            rep.signed_volume
        );
        // Every vertex lies on the sphere up to the interpolation error.
        let worst = m.positions.iter().map(|&p| sphere_sdf(p).abs()).fold(0.0, f64::max);
        assert!(worst < 0.1 * h, "n {n}: vertex off the sphere by {worst}");
        // The other orientation is the exact reverse.
        let m2 = marching_cubes(g.view(), &McOptions { spacing: [h; 3], inside: Inside::Above, ..Default::default() })
            .unwrap();
        assert!((TopologyReport::of(&m2).signed_volume + rep.signed_volume).abs() < 1e-12);

        let t = marching_cubes(
            field(n, torus_sdf).view(),
            &McOptions { spacing: [h; 3], inside: Inside::Below, ..Default::default() },
        )
        .unwrap();
        let rep = TopologyReport::of(&t);
        assert_closed_manifold(&rep, "torus");
        assert_eq!(rep.genus, Some(1), "n {n}");
        assert!(rep.signed_volume > 0.0);
    }
}

#[test]
fn noise_is_closed_and_manifold_for_every_ambiguity_rule() {
    for (n, seed) in [(8, 1), (16, 2), (33, 3)] {
        let g = noise(n, seed, -1.0);
        for ambiguity in [Ambiguity::AsymptoticDecider, Ambiguity::SeparateAbove, Ambiguity::JoinAbove] {
            let m = marching_cubes(g.view(), &McOptions { ambiguity, ..Default::default() }).unwrap();
            let rep = TopologyReport::of(&m);
            assert_closed_manifold(&rep, &format!("noise {n} {ambiguity:?}"));
            assert!(rep.signed_volume > 0.0, "solid above → outward orientation");
            // Vertices: exactly one per crossed grid edge.
            let crossings: usize = (0..3)
                .map(|ax| {
                    g.indexed_iter()
                        .filter(|&(idx, &a)| {
                            let mut jdx = [idx.0, idx.1, idx.2];
                            jdx[ax] += 1;
                            jdx[ax] < n && (a > 0.0) != (g[jdx] > 0.0)
                        })
                        .count()
                })
                .sum();
            // Polygon centres (added where no fan avoids the cell faces) are off the grid edges.
            let on_edges = m.positions.iter().filter(|p| p.iter().filter(|c| c.fract() == 0.0).count() >= 2).count();
            assert_eq!(on_edges, crossings);
        }
    }
}

/// Levels equal to grid values: integer noise at integer levels. Every directed edge stays
/// paired and orientation consistent; vertices sit on grid points where the value is the level.
#[test]
fn exact_zeros_stay_closed() {
    let mut s = 77u64;
    let n = 20;
    let g = Array3::from_shape_fn((n, n, n), |(i, j, k)| {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        if [i, j, k].iter().any(|&c| c == 0 || c == n - 1) {
            -3.0
        } else {
            ((s >> 33) % 5) as f64 - 2.0
        }
    });
    for level in [-1.0, 0.0, 1.0] {
        let m = marching_cubes(g.view(), &McOptions { level, ..Default::default() }).unwrap();
        let rep = TopologyReport::of(&m);
        assert!(rep.num_faces > 0);
        assert_eq!(rep.num_degenerate_faces, 0, "level {level}");
        assert_eq!(unpaired_directed_edges(&m), 0, "level {level}");
        eprintln!(
            "level {level}: {} faces, {} non-manifold edges, {} non-manifold vertices",
            rep.num_faces, rep.num_non_manifold_edges, rep.num_non_manifold_vertices
        );
        for p in &m.positions {
            let on_point = p.iter().all(|c| c.fract() == 0.0);
            if on_point {
                assert_eq!(g[[p[0] as usize, p[1] as usize, p[2] as usize]], level);
            }
        }
    }
    // A sphere sampled so that grid points fall exactly on it.
    let g = Array3::from_shape_fn((9, 9, 9), |(i, j, k)| {
        let (x, y, z) = (i as f64 - 4.0, j as f64 - 4.0, k as f64 - 4.0);
        x * x + y * y + z * z - 9.0
    });
    let m = marching_cubes(g.view(), &McOptions { inside: Inside::Below, ..Default::default() }).unwrap();
    let rep = TopologyReport::of(&m);
    assert_eq!(unpaired_directed_edges(&m), 0);
    assert!(rep.signed_volume > 0.0, "{rep:?}");
    assert!(m.positions.contains(&[4.0, 4.0, 7.0]));
}

/// Directed edges a→b without a matching b→a (counted with multiplicity).
fn unpaired_directed_edges(m: &mesh_io::TriMesh) -> usize {
    let mut count: std::collections::HashMap<(u32, u32), i64> = Default::default();
    for t in &m.triangles {
        for q in 0..3 {
            let (a, b) = (t[q], t[(q + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
        }
    }
    count.values().map(|c| c.unsigned_abs() as usize).sum()
}

#[test]
fn border_leaves_the_surface_open() {
    // A half space: the solid touches the border, so the mesh is a plane with boundary.
    let g = field(10, |p| p[0] - 0.53);
    let m = marching_cubes(g.view(), &McOptions::default()).unwrap();
    let rep = TopologyReport::of(&m);
    assert!(!rep.is_closed && rep.is_orientation_consistent && rep.is_manifold);
    assert_eq!(rep.num_boundary_loops, 1);
    assert!(m.positions.iter().all(|p| (p[0] - 4.77).abs() < 1e-12));
}

#[test]
fn vertex_placement_origin_and_spacing() {
    let mut g = Array3::from_elem((2, 2, 2), -1.0);
    g[[1, 1, 1]] = 3.0;
    let m = marching_cubes(
        g.view(),
        &McOptions { origin: [1.0, 2.0, 3.0], spacing: [0.5, 2.0, 1.0], ..Default::default() },
    )
    .unwrap();
    assert_eq!(m.triangles.len(), 1);
    let mut ps = m.positions.clone();
    ps.sort_by(|a, b| a.partial_cmp(b).unwrap());
    // t = 0.75 from the corner at -1 on each edge into (1,1,1).
    assert_eq!(ps, vec![[1.0 + 0.5 * 0.25, 2.0 + 2.0, 3.0 + 1.0], [1.5, 2.0 + 2.0 * 0.25, 4.0], [1.5, 4.0, 3.25]]);
    // Oriented with the solid (the above corner) behind the triangle.
    let t = m.triangles[0].map(|i| m.positions[i as usize]);
    let (u, v) = ([0, 1, 2].map(|k| t[1][k] - t[0][k]), [0, 1, 2].map(|k| t[2][k] - t[0][k]));
    let nrm = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
    assert!(nrm.iter().all(|&c| c < 0.0), "{nrm:?}");
    // No crossing: empty mesh.
    let m = marching_cubes(Array3::from_elem((3, 3, 3), 1.0).view(), &McOptions::default()).unwrap();
    assert!(m.triangles.is_empty() && m.positions.is_empty());
}

#[test]
fn errors() {
    let g = Array3::from_elem((1, 4, 4), 0.0);
    assert!(matches!(
        marching_cubes(g.view(), &McOptions::default()),
        Err(BaselineError::Config { field: "grid", .. })
    ));
    let mut g = Array3::from_elem((3, 3, 3), 0.0);
    g[[1, 2, 0]] = f64::NAN;
    assert!(matches!(marching_cubes(g.view(), &McOptions::default()), Err(BaselineError::Data(_))));
    let g = Array3::from_elem((3, 3, 3), 0.0);
    for o in [
        McOptions { level: f64::INFINITY, ..Default::default() },
        McOptions { spacing: [1.0, 0.0, 1.0], ..Default::default() },
        McOptions { origin: [f64::NAN, 0.0, 0.0], ..Default::default() },
    ] {
        assert!(matches!(marching_cubes(g.view(), &o), Err(BaselineError::Config { .. })));
    }
}

#[test]
fn extract_mesh_of_a_fitted_decoder() {
    // An untrained decoder still has a level set somewhere or none; use a trained one.
    use std::ops::ControlFlow;
    let mut s = 5u64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let points: Vec<[f64; 3]> = (0..20_000).map(|_| [r(), r(), r()]).collect();
    let occ = points.iter().map(|&p| (sphere_sdf(p) < 0.0) as u8 as f64).collect();
    let data = baselines::TrainingData { points, occupancy: Some(occ), sdf: None };
    let mut m = Decoder::new(DecoderConfig::occnet(32, 3), 1).unwrap();
    let tc = baselines::TrainConfig { steps: 600, batch: 4096, lr: 3e-3, ..Default::default() };
    baselines::train(&mut m, &data, &tc, |_| ControlFlow::Continue(())).unwrap();
    let mesh = extract_mesh(&m, 33).unwrap();
    let rep = TopologyReport::of(&mesh);
    assert_closed_manifold(&rep, "decoder");
    let v = 4.0 / 3.0 * std::f64::consts::PI * 0.31f64.powi(3);
    assert!((rep.signed_volume - v).abs() < 0.15 * v, "volume {} vs {v}", rep.signed_volume);
}

/// One cell with two diagonally opposite corners above the level (case 4), inside a grid
/// whose other values are below: when the trilinear interpolant joins the two corners
/// through the cell (centre value > 0), the decider mode makes one tube (one closed
/// component); otherwise, and always in the fixed-rule modes, two separate caps.
#[test]
fn interior_test_makes_tubes() {
    let grid = |corner: f64, rest: f64| {
        Array3::from_shape_fn((4, 4, 4), |(i, j, k)| {
            if (i, j, k) == (1, 1, 1) || (i, j, k) == (2, 2, 2) {
                corner
            } else if (1..=2).contains(&i) && (1..=2).contains(&j) && (1..=2).contains(&k) {
                rest
            } else {
                -1.0
            }
        })
    };
    let components = |g: &Array3<f64>, ambiguity| {
        let m = marching_cubes(g.view(), &McOptions { ambiguity, ..Default::default() }).unwrap();
        let rep = TopologyReport::of(&m);
        assert_closed_manifold(&rep, &format!("{ambiguity:?}"));
        assert!(rep.signed_volume > 0.0);
        rep.num_components
    };
    let tube = grid(1.0, -0.1);
    assert_eq!(components(&tube, Ambiguity::AsymptoticDecider), 1);
    assert_eq!(components(&tube, Ambiguity::SeparateAbove), 2);
    let apart = grid(1.0, -1.0);
    assert_eq!(components(&apart, Ambiguity::AsymptoticDecider), 2);
    // The complement: two below corners joined by a tube of below values.
    let neg = tube.mapv(|v| -v);
    let m = marching_cubes(neg.view(), &McOptions { inside: Inside::Below, ..Default::default() }).unwrap();
    let rep = TopologyReport::of(&m);
    assert_closed_manifold(&rep, "complement");
    assert_eq!(rep.num_components, 1);
}
