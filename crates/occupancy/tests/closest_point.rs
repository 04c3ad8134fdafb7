//! Closest points and signed distances: the BVH branch-and-bound equals brute force.

mod common;

use occupancy::distance::closest_point_triangle::closest_point_triangle;
use occupancy::{Config, MeshOracle, WindingMode, Workspace};

#[test]
fn bvh_closest_point_equals_brute_force_on_every_class() {
    for (name, mesh) in common::meshes_by_class() {
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
        let queries = common::issue_queries(&mesh, 3000, 11);
        let got = oracle.closest_points(&queries).unwrap();
        for (q, c) in queries.iter().zip(&got) {
            let mut best = f64::INFINITY;
            for t in &mesh.1 {
                let [a, b, cc] = t.map(|v| mesh.0[v as usize]);
                let p = closest_point_triangle(*q, a, b, cc);
                let d2 = (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>();
                best = best.min(d2);
            }
            // Same per-triangle arithmetic, so the minimum is bit-identical.
            assert_eq!(c.squared_distance, best, "{name} at {q:?}");
            let d2 = (0..3).map(|k| (q[k] - c.point[k]).powi(2)).sum::<f64>();
            assert_eq!(d2, c.squared_distance, "{name}: point and distance disagree");
            // The reported triangle holds the point.
            let [a, b, cc] = mesh.1[c.triangle as usize].map(|v| mesh.0[v as usize]);
            let p = closest_point_triangle(*q, a, b, cc);
            let dt = (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>();
            assert_eq!(dt, best, "{name}: triangle {} is not a closest one", c.triangle);
        }
    }
}

#[test]
fn signed_distance_of_sphere_is_radius_offset() {
    let (p, t) = common::icosphere(4);
    let oracle = MeshOracle::new(&p, &t, &Config::default()).unwrap();
    let mut ws = Workspace::new();
    // The icosphere is inscribed in the unit sphere; faces lie within 1e-2 of it.
    for (q, want) in [([0.0, 0.0, 0.0], -1.0), ([0.0, 2.0, 0.0], 1.0), ([0.3, 0.0, 0.0], -0.7)] {
        let d = oracle.signed_distance(q, WindingMode::Fast, &mut ws);
        assert!((d - want).abs() < 1e-2, "{q:?}: {d}");
    }
    let batch = oracle.query(&common::issue_queries(&(p, t), 4000, 1), WindingMode::Exact).unwrap();
    for i in 0..batch.sdf.len() {
        assert_eq!(batch.sdf[i].abs(), batch.squared_distance[i].sqrt());
        assert_eq!(batch.sdf[i] < 0.0 || batch.sdf[i] == 0.0 && batch.occupancy[i] == 1, batch.occupancy[i] == 1);
    }
}

/// The tree is built with the smaller of the two leaf sizes and the box traversals stop at
/// subtrees of `max_leaf_size` triangles; whatever the pair, closest points stay exact,
/// the exact winding number stays the brute-force one, the inside rule does not change and
/// the fast winding number stays within 1e-3 of it.
#[test]
fn every_leaf_size_pair_gives_the_same_answers() {
    let mesh = common::icosphere(3);
    let reference = MeshOracle::new(&mesh.0, &mesh.1, &Config::default()).unwrap();
    let queries = common::issue_queries(&mesh, 1500, 3);
    let want_points = reference.closest_points(&queries).unwrap();
    let want_exact = reference.winding_numbers(&queries, WindingMode::Exact).unwrap();
    for (winding_leaf_size, max_leaf_size) in [(1, 1), (1, 8), (2, 8), (8, 8), (8, 2), (4, 30), (30, 30)] {
        let config = Config { winding_leaf_size, max_leaf_size, ..Config::default() };
        let oracle = MeshOracle::new(&mesh.0, &mesh.1, &config).unwrap();
        assert_eq!(oracle.bvh().validate(), Ok(()));
        let points = oracle.closest_points(&queries).unwrap();
        let exact = oracle.winding_numbers(&queries, WindingMode::Exact).unwrap();
        let fast = oracle.winding_numbers(&queries, WindingMode::Fast).unwrap();
        for i in 0..queries.len() {
            let tag = format!("leaves ({winding_leaf_size}, {max_leaf_size}) at {:?}", queries[i]);
            assert_eq!(points[i].squared_distance, want_points[i].squared_distance, "{tag}");
            assert!((exact[i] - want_exact[i]).abs() < 1e-12, "{tag}: {} vs {}", exact[i], want_exact[i]);
            assert!((fast[i] - want_exact[i]).abs() < 1e-3, "{tag}: fast {} vs {}", fast[i], want_exact[i]);
        }
    }
}
