//! Frozen failures and tricky configurations, one named test each.

mod common;
use common::*;

#[test]
fn all_points_coplanar_but_one() {
    // The hull has a huge flat facet region: exercises the coplanar perturbed in-circle
    // on infinite tetrahedra.
    let mut pts: Vec<[f64; 3]> = lattice(6).into_iter().map(|p| [p[0], p[1], 0.0]).collect();
    pts.push([2.5, 2.5, 1.0]);
    let dt = build_and_check(&pts);
    brute_force_delaunay(&dt);
}

#[test]
fn points_on_hull_edge_lines() {
    // Collinear points along hull edges and beyond them: new points on the line of a
    // hull edge must not create flat tetrahedra.
    let mut pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for i in 2..20 {
        pts.push([i as f64, 0.0, 0.0]);
        pts.push([-(i as f64), 0.0, 0.0]);
        pts.push([0.0, i as f64 * 0.5, 0.0]);
    }
    let dt = build_and_check(&pts);
    brute_force_delaunay(&dt);
}

#[test]
fn cocircular_points_on_a_hull_facet() {
    // A regular octagon of integer-ish points cannot be exact; use the 8 integer points
    // of x²+y² = 25 in the plane z = 0 plus an apex: cocircular on a hull face.
    let mut pts: Vec<[f64; 3]> = vec![
        [5.0, 0.0, 0.0],
        [-5.0, 0.0, 0.0],
        [0.0, 5.0, 0.0],
        [0.0, -5.0, 0.0],
        [3.0, 4.0, 0.0],
        [-3.0, 4.0, 0.0],
        [3.0, -4.0, 0.0],
        [-3.0, -4.0, 0.0],
        [4.0, 3.0, 0.0],
        [-4.0, 3.0, 0.0],
        [4.0, -3.0, 0.0],
        [-4.0, -3.0, 0.0],
    ];
    pts.push([0.0, 0.0, 7.0]);
    let dt = build_and_check(&pts);
    brute_force_delaunay(&dt);
}

#[test]
fn subnormal_and_zero_coordinates_mixed() {
    // Zero coordinates are always allowed; a subnormal spread within range is rescaled.
    let pts: Vec<[f64; 3]> = lattice(3).into_iter().map(|p| p.map(|x| x * 1e-310)).collect();
    let dt = build_and_check(&pts);
    assert!(dt.scale_exponent() > 900);
}
