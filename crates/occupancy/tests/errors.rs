//! Bad input is refused at the boundary with errors that say how to fix it.

use occupancy::{Config, MeshOracle, OccupancyError, WindingMode, MAX_COORDINATE};

fn tetra() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    (
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    )
}

#[test]
fn mesh_errors() {
    let (p, t) = tetra();
    let c = Config::default();
    assert_eq!(MeshOracle::new(&p, &[], &c).err(), Some(OccupancyError::NoTriangles));
    let e = MeshOracle::new(&p, &[[0, 1, 9]], &c).err().unwrap();
    assert_eq!(e.to_string(), "triangle 0 refers to vertex 9 but the mesh has 4 vertices");
    let mut bad = p.clone();
    bad[2][1] = f64::NAN;
    assert!(matches!(MeshOracle::new(&bad, &t, &c), Err(OccupancyError::BadVertex { vertex: 2, .. })));
    bad[2][1] = 2.0 * MAX_COORDINATE;
    assert!(MeshOracle::new(&bad, &t, &c).is_err());
    for config in [
        Config { beta: 1.0, ..Config::default() },
        Config { beta: f64::NAN, ..Config::default() },
        Config { exact_fallback_margin: -1.0, ..Config::default() },
        Config { max_leaf_size: 0, ..Config::default() },
        Config { winding_leaf_size: 0, ..Config::default() },
        Config { winding_leaf_size: 256, ..Config::default() },
    ] {
        assert!(matches!(MeshOracle::new(&p, &t, &config), Err(OccupancyError::BadConfig(_))));
    }
}

#[test]
fn query_errors() {
    let (p, t) = tetra();
    let o = MeshOracle::new(&p, &t, &Config::default()).unwrap();
    let q = [[0.1, 0.1, 0.1], [f64::INFINITY, 0.0, 0.0]];
    assert!(matches!(o.winding_numbers(&q, WindingMode::Fast), Err(OccupancyError::BadQuery { index: 1, .. })));
    assert!(o.closest_points(&q).is_err());
    assert!(o.query(&q, WindingMode::Exact).is_err());
}

#[test]
fn single_triangle_mesh_works() {
    // Regression: obvhs builds a lone leaf as the root.
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let o = MeshOracle::new(&p, &[[0, 1, 2]], &Config::default()).unwrap();
    assert_eq!(o.bvh().validate(), Ok(()));
    let c = o.closest_points(&[[0.2, 0.2, 1.0]]).unwrap();
    assert_eq!(c[0].squared_distance, 1.0);
    let w = o.winding_numbers(&[[0.2, 0.2, -1e-3]], WindingMode::Exact).unwrap();
    assert!(w[0] > 0.4 && w[0] < 0.5, "{}", w[0]);
}
