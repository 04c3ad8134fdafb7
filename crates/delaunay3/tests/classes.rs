//! validate() on every point-set class of the issue, at its scale, and on the same sets
//! scaled by 1e-150 and 1e150 (which exercises the exact power-of-two normalisation).

mod common;
use common::*;

/// Build and validate `pts` and its two extreme rescalings; returns the finite tet
/// counts.
fn check_with_scalings(pts: &[[f64; 3]]) -> [usize; 3] {
    let a = build_and_check(pts).num_finite_tets();
    let b = build_and_check(&scaled(pts, 1e-150)).num_finite_tets();
    let c = build_and_check(&scaled(pts, 1e150)).num_finite_tets();
    [a, b, c]
}

#[test]
fn uniform_10() {
    check_with_scalings(&uniform(10, 10));
}

#[test]
fn uniform_1000() {
    let pts = uniform(1000, 1000);
    let dt = build_and_check(&pts);
    brute_force_delaunay(&dt);
    check_with_scalings(&pts);
}

#[test]
fn uniform_100_000() {
    check_with_scalings(&uniform(100_000, 100_000));
}

#[test]
fn uniform_1_000_000() {
    // The rescaled copies are different point sets (1e150 is not a power of two), so
    // all three are triangulated and validated.
    let counts = check_with_scalings(&uniform(1_000_000, 1_000_000));
    // Random points: about 6.77 tetrahedra per point.
    assert!(counts.iter().all(|&c| (6_600_000..6_900_000).contains(&c)), "{counts:?}");
}

#[test]
fn lattice_30() {
    let pts = lattice(30);
    let counts = check_with_scalings(&pts);
    // Exact: integer lattice; every unit cube is split into 5 or 6 tets, so the count
    // is between 5·29³ and 6·29³.
    let cubes = 29usize.pow(3);
    assert!((5 * cubes..=6 * cubes).contains(&counts[0]), "{counts:?}");
    // CGAL 6.0.1's Delaunay_triangulation_3 uses the same symbolic perturbation
    // (lexicographic order on the lifted coordinate), so it picks the same
    // triangulation: it reports 146,334 finite cells for this lattice
    // (benches/compare_delaunay.py).
    assert_eq!(counts[0], 146_334);
}

#[test]
fn cospherical_20_000() {
    // 11,895,939 ≡ 3 (mod 8) is a sum of three squares in many ways.
    let pts = cospherical(11_895_939, 20_000, 42);
    let dt = build_and_check(&pts);
    // All points on the sphere: every point is a hull vertex and all finite tets
    // share the same circumsphere.
    let hull_vertices: std::collections::HashSet<u32> = dt.infinite_tets().flat_map(|t| [t[0], t[1], t[2]]).collect();
    assert_eq!(hull_vertices.len(), 20_000);
    // Euler for a triangulated ball with all vertices on the boundary:
    // hull facets F = 2V − 4; and T = F + V − ... we only check F here.
    assert_eq!(dt.num_tets() - dt.num_finite_tets(), 2 * 20_000 - 4);
    check_with_scalings(&pts);
}

#[test]
fn points_on_few_planes() {
    let pts = planes(2000, 3);
    let dt = build_and_check(&pts);
    assert!(dt.num_vertices() < pts.len()); // some coincide by construction
    check_with_scalings(&pts);
}

#[test]
fn exponentially_clustered() {
    let pts = exponential_clusters(300, 15, 8); // spacing down to 2^-42
    check_with_scalings(&pts);
}

#[test]
fn duplicates_large() {
    let base = uniform(20_000, 77);
    let pts = with_duplicates(&base, 2, 5);
    let dt = build_and_check(&pts);
    assert_eq!(dt.num_vertices(), 20_000);
    let reference = build_and_check(&base);
    assert_eq!(tet_set_by_coords(&dt), tet_set_by_coords(&reference));
    check_with_scalings(&pts);
    // Lattice with duplicates.
    let pts = with_duplicates(&lattice(12), 1, 6);
    assert_eq!(build_and_check(&pts).num_vertices(), 12 * 12 * 12);
}
