//! Winding numbers: exact hierarchical sum vs brute force, known values on closed meshes,
//! fast mode accuracy and flips on the issue's query sets.

mod common;

use occupancy::winding::exact::brute_force_solid_angle_sum;
use occupancy::{Config, MeshOracle, WindingMode, Workspace};

fn corners(mesh: &common::Mesh) -> Vec<[[f64; 3]; 3]> {
    mesh.1.iter().map(|t| t.map(|v| mesh.0[v as usize])).collect()
}

#[test]
fn bvh_validates_on_every_class() {
    for (name, mesh) in common::meshes_by_class() {
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        assert_eq!(oracle.bvh().validate(), Ok(()), "{name}");
        assert_eq!(oracle.validate(), Ok(()), "{name}");
        assert_eq!(oracle.num_triangles(), mesh.1.len());
    }
}

/// The batch functions traverse the tree in packets of nearby queries; every lane must add
/// exactly the terms of the one-query traversal, in the same order, so the values are equal
/// bit for bit. The query sets include mesh vertices (ρ = 0 at some nodes), points on the
/// triangles' planes, and counts that leave a partial last packet.
#[test]
fn packet_traversal_equals_one_query_at_a_time_bit_for_bit() {
    for (name, mesh) in common::meshes_by_class() {
        let config = Config { exact_fallback_margin: 0.0, ..Config::default() };
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &config).unwrap();
        let mut queries = common::issue_queries(&mesh, 3001, 11);
        queries.extend(mesh.0.iter().step_by(7).copied());
        for t in mesh.1.iter().step_by(13) {
            let [a, b, c] = t.map(|v| mesh.0[v as usize]);
            queries.push(std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0));
        }
        let batch = oracle.winding_numbers(&queries, WindingMode::Fast).unwrap();
        let mut ws = Workspace::new();
        for (q, w) in queries.iter().zip(&batch) {
            let one = oracle.winding_number_fast_unguarded(*q, &mut ws);
            assert!(one.to_bits() == w.to_bits() || (one == 0.0 && *w == 0.0), "{name} at {q:?}: {one:e} vs {w:e}");
        }
    }
}

/// `winding_numbers_counted` reports how many fast values fell in the exact fallback band
/// (what `voronoi-fit query --timings` and the benchmark print as the fallback share).
#[test]
fn fallback_count_is_the_number_of_fast_values_in_the_band() {
    let mut total = 0;
    for (name, mesh) in common::meshes_by_class() {
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        let queries = common::issue_queries(&mesh, 2000, 5);
        let (_, count) = oracle.winding_numbers_counted(&queries, WindingMode::Fast).unwrap();
        let mut ws = Workspace::new();
        let expected = queries
            .iter()
            .filter(|q| oracle.config().needs_exact_fallback(oracle.winding_number_fast_unguarded(**q, &mut ws)))
            .count();
        assert_eq!(count as usize, expected, "{name}");
        assert_eq!(oracle.winding_numbers_counted(&queries, WindingMode::Exact).unwrap().1, 0, "{name}");
        total += count;
    }
    // The open and soup classes put queries in the band, so the count is exercised.
    assert!(total > 0);
}

#[test]
fn exact_hierarchical_sum_equals_brute_force_on_every_class() {
    for (name, mesh) in common::meshes_by_class() {
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        let tris = corners(&mesh);
        let queries = common::issue_queries(&mesh, 1500, 7);
        let mut ws = Workspace::new();
        let mut max_diff: f64 = 0.0;
        for q in &queries {
            let w = oracle.winding_number_exact(*q, &mut ws);
            let b = brute_force_solid_angle_sum(&tris, *q) / (4.0 * std::f64::consts::PI);
            max_diff = max_diff.max((w - b).abs());
        }
        assert!(max_diff < 1e-10, "{name}: max |hierarchical - brute| = {max_diff:e}");
    }
}

#[test]
fn closed_meshes_have_winding_one_inside_and_zero_outside() {
    let sphere = common::icosphere(3);
    let oracle = MeshOracle::new(&sphere.0, &sphere.1, &Config::default()).unwrap();
    let mut ws = Workspace::new();
    for (q, want) in [
        ([0.0, 0.0, 0.0], 1.0),
        ([0.5, -0.3, 0.2], 1.0),
        ([0.0, 0.0, 0.98], 1.0),
        ([1.2, 0.0, 0.0], 0.0),
        ([0.0, 1.05, 0.1], 0.0),
        ([3.0, -4.0, 5.0], 0.0),
    ] {
        for mode in [WindingMode::Exact, WindingMode::Fast] {
            let w = oracle.winding_number(q, mode, &mut ws);
            let tol = if mode == WindingMode::Exact { 1e-12 } else { 1e-3 };
            assert!((w - want).abs() < tol, "{q:?} {mode:?}: {w}");
        }
    }
    // Torus: inside the tube is 1, in the hole is 0.
    let torus = common::torus(48, 24);
    let oracle = MeshOracle::new(&torus.0, &torus.1, &Config::default()).unwrap();
    let w_tube = oracle.winding_number_exact([1.0, 0.0, 0.0], &mut ws);
    let w_hole = oracle.winding_number_exact([0.0, 0.0, 0.0], &mut ws);
    // The torus' quads are ordered so that its normals point inward or outward depending
    // on the parametrisation; whichever, |w| is 1 in the tube and 0 in the hole.
    assert!((w_tube.abs() - 1.0).abs() < 1e-12, "{w_tube}");
    assert!(w_hole.abs() < 1e-12, "{w_hole}");
}

#[test]
fn reversing_orientation_negates_winding() {
    let (p, t) = common::icosphere(2);
    let flipped: Vec<[u32; 3]> = t.iter().map(|x| [x[0], x[2], x[1]]).collect();
    let a = MeshOracle::new(&p, &t, &Config::default()).unwrap();
    let b = MeshOracle::new(&p, &flipped, &Config::default()).unwrap();
    let queries = common::issue_queries(&(p.clone(), t.clone()), 500, 3);
    let wa = a.winding_numbers(&queries, WindingMode::Exact).unwrap();
    let wb = b.winding_numbers(&queries, WindingMode::Exact).unwrap();
    for (x, y) in wa.iter().zip(&wb) {
        assert!((x + y).abs() < 1e-12, "{x} {y}");
    }
}

#[test]
fn unwelded_soup_has_the_same_winding_as_the_welded_mesh() {
    // Regression guard for the boundary caps: an STL-style soup must weld its edges so
    // caps cancel, and in any case give the same numbers.
    let mesh = common::icosphere(3);
    let soup = common::unweld(&mesh);
    let a = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
    let b = MeshOracle::new(&soup.0, &soup.1, &Config::default()).unwrap();
    assert_eq!(a.num_cap_edges(), b.num_cap_edges());
    let queries = common::issue_queries(&mesh, 2000, 5);
    for mode in [WindingMode::Exact, WindingMode::Fast] {
        let wa = a.winding_numbers(&queries, mode).unwrap();
        let wb = b.winding_numbers(&queries, mode).unwrap();
        for (x, y) in wa.iter().zip(&wb) {
            assert!((x - y).abs() < 1e-12, "{mode:?}: {x} {y}");
        }
    }
}

#[test]
fn open_mesh_winding_is_fractional_near_the_hole() {
    // A hemisphere-like open cap: the winding number varies continuously through the hole,
    // taking values strictly between 0 and 1 there.
    let (p, t) = common::icosphere(3);
    let open: Vec<[u32; 3]> =
        t.iter().copied().filter(|tri| tri.iter().map(|&v| p[v as usize][2]).sum::<f64>() / 3.0 < 0.0).collect();
    let oracle = MeshOracle::new(&p, &open, &Config::default()).unwrap();
    let mut ws = Workspace::new();
    let w = oracle.winding_number_exact([0.0, 0.0, 0.0], &mut ws);
    assert!((w - 0.5).abs() < 0.05, "{w}");
    // Fast mode falls back to exact so close to 0.5.
    let wf = oracle.winding_number([0.0, 0.0, 0.0], WindingMode::Fast, &mut ws);
    assert_eq!(wf, w);
    assert_eq!(ws.num_exact_fallbacks, 1);
}

/// Number of queries per mesh of the issue's accuracy test: `VF_OCC_QUERIES`, default the
/// issue's 1,000,000 (about 40 s for the three meshes in the ci profile on two cores).
fn issue_query_count() -> usize {
    std::env::var("VF_OCC_QUERIES").ok().and_then(|s| s.parse().ok()).unwrap_or(1_000_000)
}

#[test]
fn fast_winding_error_below_1e_3_and_no_flips_on_issue_query_sets() {
    let n = issue_query_count();
    let mut meshes = vec![("icosphere20480".to_string(), common::icosphere(5), n)];
    // The Menger sponge (21,598 faces in many nested sheets: its β is raised, see
    // `occupancy::effective_beta`; at β = 3.5, 523 of 100k queries were above 1e-3) with a
    // tenth of the queries, as its exact winding numbers cost the most.
    for (name, count) in [("mikedh__bunny.ply", n), ("mikedh__teapot.stl", n), ("elalish__mengerSponge3.glb", n / 10)] {
        match common::shared_mesh(name) {
            Some(m) => meshes.push((name.to_string(), m, count)),
            None => panic!("{name}: the shared meshes must sit in ../shared/meshes beside the repository"),
        }
    }
    for (name, mesh, n) in meshes {
        let config = Config::default();
        let guarded = MeshOracle::new(&mesh.0, &mesh.1, &config).unwrap();
        let raw = MeshOracle::new(&mesh.0, &mesh.1, &Config { exact_fallback_margin: 0.0, ..config.clone() }).unwrap();
        let queries = common::issue_queries(&mesh, n, 2024);
        let exact = guarded.winding_numbers(&queries, WindingMode::Exact).unwrap();
        // The raw approximation on all queries: its error is the issue's bound.
        let fast_raw = raw.winding_numbers(&queries, WindingMode::Fast).unwrap();
        let max_err = fast_raw.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        // The guarded mode differs from the raw one only within the fallback band, so it is
        // run through its real code path on every query of the band and on a sample of the
        // others.
        let mut ws = Workspace::new();
        let mut flips = 0;
        let mut num_band = 0;
        for (i, q) in queries.iter().enumerate() {
            let in_band = (fast_raw[i] - config.occupancy_threshold).abs() < config.exact_fallback_margin;
            if !in_band && i % 97 != 0 {
                continue;
            }
            num_band += in_band as usize;
            let w = guarded.winding_number(*q, WindingMode::Fast, &mut ws);
            if in_band {
                assert_eq!(w, exact[i], "{name}: band query {i} not recomputed exactly");
            } else {
                assert_eq!(w, fast_raw[i], "{name}: query {i} outside the band changed");
            }
            flips += ((w >= 0.5) != (exact[i] >= 0.5)) as usize;
        }
        assert_eq!(ws.num_exact_fallbacks as usize, num_band);
        eprintln!(
            "{name}: {n} queries, max |fast - exact| = {max_err:.3e}, {num_band} in the exact \
             fallback band, flips = {flips}"
        );
        assert!(max_err <= 1e-3, "{name}: max error {max_err:e}");
        assert_eq!(flips, 0, "{name}");
        // Outside the band the raw value already decides correctly.
        let raw_flips_outside_band = fast_raw
            .iter()
            .zip(&exact)
            .filter(|(a, b)| (**a - 0.5).abs() >= config.exact_fallback_margin && (**a >= 0.5) != (**b >= 0.5))
            .count();
        assert_eq!(raw_flips_outside_band, 0, "{name}");
    }
}

#[test]
fn query_batch_columns_agree() {
    let mesh = common::icosphere(3);
    let oracle = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
    let queries = common::issue_queries(&mesh, 5000, 9);
    let batch = oracle.query(&queries, WindingMode::Fast).unwrap();
    let w = oracle.winding_numbers(&queries, WindingMode::Fast).unwrap();
    let c = oracle.closest_points(&queries).unwrap();
    assert_eq!(batch.winding, w);
    for i in 0..queries.len() {
        assert_eq!(batch.occupancy[i], (w[i] >= 0.5) as u8);
        assert_eq!(batch.squared_distance[i], c[i].squared_distance);
        assert_eq!(batch.closest[i], c[i].point);
    }
}

#[test]
fn beta_is_raised_only_on_meshes_with_much_surface_for_their_box() {
    // A single closed shape keeps the configured β (the icosphere's area is 0.52 of its
    // box's); the Menger sponge (area 4.13 times its box's) gets β·4.13^¼.
    let sphere = common::icosphere(4);
    let o = MeshOracle::new(&sphere.0, &sphere.1, &Config::default()).unwrap();
    assert_eq!(o.beta(), Config::default().beta);
    let sponge = common::shared_mesh("elalish__mengerSponge3.glb")
        .expect("the shared meshes must sit in ../shared/meshes beside the repository");
    let o = MeshOracle::new(&sponge.0, &sponge.1, &Config::default()).unwrap();
    let expected = 3.5 * 4.13f64.powf(0.25);
    assert!((o.beta() - expected).abs() < 0.01, "β = {} (expected about {expected})", o.beta());
}
