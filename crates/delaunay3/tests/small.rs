//! Small and degenerate cases, with an independent brute-force global check.

mod common;
use common::*;
use delaunay3::{Delaunay3, DelaunayError};

#[test]
fn single_tetrahedron() {
    let dt = build_and_check(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
    assert_eq!(dt.num_finite_tets(), 1);
    assert_eq!(dt.num_tets(), 5);
    brute_force_delaunay(&dt);
}

#[test]
fn ten_uniform_points() {
    let dt = build_and_check(&uniform(10, 1));
    brute_force_delaunay(&dt);
}

#[test]
fn cube_corners_and_centre() {
    let mut pts = lattice(2);
    let dt = build_and_check(&pts);
    brute_force_delaunay(&dt);
    pts.push([0.5, 0.5, 0.5]);
    let dt = build_and_check(&pts);
    assert_eq!(dt.num_finite_tets(), 12);
    brute_force_delaunay(&dt);
}

#[test]
fn small_lattices() {
    for k in 2..7 {
        let dt = build_and_check(&lattice(k));
        brute_force_delaunay(&dt);
        // Every lattice tetrahedralization of a k³ grid fills (k−1)³ unit cubes of
        // volume 1 each: check the total volume exactly (integer coordinates).
        let vol6: i64 = dt
            .finite_tets()
            .map(|t| {
                let p = t.map(|v| dt.vertex(v).map(|x| x as i64));
                let d = |i: usize| [0, 1, 2].map(|k| p[i][k] - p[0][k]);
                let (b, c, e) = (d(1), d(2), d(3));
                b[0] * (c[1] * e[2] - c[2] * e[1]) - b[1] * (c[0] * e[2] - c[2] * e[0])
                    + b[2] * (c[0] * e[1] - c[1] * e[0])
            })
            .sum();
        assert_eq!(vol6, 6 * ((k - 1) as i64).pow(3));
    }
}

#[test]
fn degenerate_inputs_are_typed_errors() {
    let e = Delaunay3::new(&[]).unwrap_err();
    assert!(matches!(e, DelaunayError::Degenerate { dimension: -1, .. }));
    let e = Delaunay3::new(&[[1.0, 2.0, 3.0]; 7]).unwrap_err();
    assert!(matches!(e, DelaunayError::Degenerate { dimension: 0, .. }));
    let line: Vec<[f64; 3]> = (0..10).map(|i| [i as f64, 2.0 * i as f64, 3.0]).collect();
    let e = Delaunay3::new(&line).unwrap_err();
    assert!(matches!(e, DelaunayError::Degenerate { dimension: 1, .. }));
    let plane: Vec<[f64; 3]> = lattice(4).into_iter().map(|p| [p[0], p[1], 7.0]).collect();
    let e = Delaunay3::new(&plane).unwrap_err();
    assert!(matches!(e, DelaunayError::Degenerate { dimension: 2, .. }), "{e}");
    assert!(e.to_string().contains("coplanar"));
    // Three points only.
    let e = Delaunay3::new(&uniform(3, 5)).unwrap_err();
    assert!(matches!(e, DelaunayError::Degenerate { .. }));
}

#[test]
fn non_finite_inputs_are_typed_errors() {
    let mut pts = uniform(20, 3);
    pts[13][1] = f64::NAN;
    match Delaunay3::new(&pts).unwrap_err() {
        DelaunayError::NonFinite { index, .. } => assert_eq!(index, 13),
        e => panic!("unexpected {e}"),
    }
    pts[13][1] = f64::INFINITY;
    assert!(matches!(Delaunay3::new(&pts).unwrap_err(), DelaunayError::NonFinite { index: 13, .. }));
}

#[test]
fn too_wide_range_is_a_typed_error() {
    let mut pts = uniform(20, 3);
    pts[4] = [1e-200, 0.5, 0.5];
    pts[5] = [1e200, 0.5, 0.5];
    let e = Delaunay3::new(&pts).unwrap_err();
    assert!(matches!(e, DelaunayError::RangeTooWide { .. }), "{e}");
}

#[test]
fn extreme_magnitudes_are_rescaled() {
    for s in [1e-300, 1e-150, 1e150, 1e300, 5e-324 * 1e10] {
        let dt = build_and_check(&scaled(&lattice(4), s));
        assert_ne!(dt.scale_exponent(), 0);
    }
    // Subnormal inputs: integer multiples of the smallest subnormal.
    let pts: Vec<[f64; 3]> = lattice(3).iter().map(|p| p.map(|x| x * 5e-324)).collect();
    build_and_check(&pts);
}

#[test]
fn duplicates_are_merged() {
    let base = uniform(50, 9);
    let pts = with_duplicates(&base, 3, 2);
    let dt = build_and_check(&pts);
    assert_eq!(dt.num_vertices(), 50);
    let first = Delaunay3::new(&base).unwrap();
    assert_eq!(tet_set_by_coords(&dt), tet_set_by_coords(&first));
    // -0.0 and 0.0 are the same point.
    let mut pts = lattice(2);
    pts.push([-0.0, 0.0, -0.0]);
    let dt = build_and_check(&pts);
    assert_eq!(dt.num_vertices(), 8);
    assert_eq!(dt.vertex_of_input(8), dt.vertex_of_input(0));
}

#[test]
fn edges_and_rings() {
    let pts = uniform(300, 11);
    let dt = build_and_check(&pts);
    let edges = dt.edges();
    // Euler on the 3-sphere (V+1) − E_all + F − T = 0 with F = 2T, so E_all = V + 1 + T.
    // Hull edges and the V_h edges to infinity are extra in E_all.
    let t_all = dt.num_tets();
    let hull_vertices = {
        let mut h: Vec<u32> = dt.infinite_tets().flat_map(|t| [t[0], t[1], t[2]]).collect();
        h.sort_unstable();
        h.dedup();
        h.len()
    };
    assert_eq!(edges.len() + hull_vertices, dt.num_vertices() + 1 + t_all);
    let mut ring = Vec::new();
    let mut incidences = 0usize;
    for e in &edges {
        let [a, b] = e.vertices;
        dt.tets_around_edge(e.tet, a, b, &mut ring);
        assert!(ring.len() >= 3);
        for w in 0..ring.len() {
            let (t, u) = (ring[w], ring[(w + 1) % ring.len()]);
            assert!(dt.neighbors(t).contains(&u));
            if !dt.is_infinite(t) {
                incidences += 1;
            }
        }
        // Positive rotation: consecutive finite ring members turn positively around a→b.
        let finite: Vec<u32> = ring.iter().copied().filter(|&t| !dt.is_infinite(t)).collect();
        for &t in &finite {
            let v = dt.tet(t);
            let others: Vec<u32> = v.iter().copied().filter(|&x| x != a && x != b).collect();
            let p = |x: u32| dt.vertex(x);
            let o1 = delaunay3::predicates::orient(&p(a), &p(b), &p(others[0]), &p(others[1]));
            assert_ne!(o1, 0);
        }
    }
    assert_eq!(incidences, 6 * dt.num_finite_tets());
}
