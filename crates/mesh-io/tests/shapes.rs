//! Generated shapes have the topology and geometry they claim, normalisation inverts, and
//! the committed assets match the generator.

use mesh_io::{shapes, TopologyReport, UnitCubeTransform};

#[test]
fn icosphere_is_closed_genus_0_and_converges_to_the_ball() {
    let m = shapes::icosphere(5);
    assert_eq!(m.triangles.len(), 20_480);
    let r = TopologyReport::of(&m);
    assert!(r.is_closed && r.is_manifold && r.is_orientation_consistent);
    assert_eq!((r.genus, r.euler_characteristic, r.num_components), (Some(0), 2, 1));
    let ball = 4.0 / 3.0 * std::f64::consts::PI;
    assert!(r.signed_volume > 0.0 && (r.signed_volume - ball).abs() / ball < 2e-3, "{}", r.signed_volume);
}

#[test]
fn torus_and_box_with_hole_are_genus_1() {
    let t = TopologyReport::of(&shapes::torus(1.0, 0.35, 64, 32));
    assert_eq!((t.genus, t.is_closed), (Some(1), true));
    let exact = 2.0 * std::f64::consts::PI.powi(2) * 1.0 * 0.35f64.powi(2);
    assert!((t.signed_volume - exact).abs() / exact < 1e-2);
    let b = TopologyReport::of(&shapes::box_with_hole(1.0, 0.3));
    assert_eq!((b.genus, b.is_closed, b.is_manifold, b.is_orientation_consistent), (Some(1), true, true, true));
    let v = shapes::box_with_hole_volume(1.0, 0.3);
    assert!((b.signed_volume - v).abs() <= 1e-12 * v, "{} vs {v}", b.signed_volume);
}

#[test]
fn topology_counts_defects() {
    use mesh_io::TriMesh;
    // Two triangles sharing only a vertex (a bow-tie), a duplicate face, a degenerate
    // collinear face and an edge shared by three faces.
    let m = TriMesh {
        positions: vec![
            [0., 0., 0.],
            [1., 0., 0.],
            [0., 1., 0.],
            [-1., 0., 0.],
            [0., -1., 0.],
            [2., 0., 0.],
            [0., 0., 1.],
        ],
        triangles: vec![[0, 1, 2], [0, 3, 4], [0, 1, 2], [0, 1, 5], [0, 1, 6]],
    };
    let r = TopologyReport::of(&m);
    assert_eq!(r.num_duplicate_faces, 1);
    assert_eq!(r.num_degenerate_faces, 1); // 0, 1, 5 are collinear
    assert_eq!(r.num_non_manifold_edges, 1); // edge 0-1 has four faces
    assert_eq!(r.num_non_manifold_vertices, 1); // vertex 0: two fans
    assert!(!r.is_closed && !r.is_manifold);
    assert_eq!(r.genus, None);
}

#[test]
fn normalisation_fits_the_cube_and_inverts() {
    let mut m = shapes::torus(3.0, 1.0, 32, 16);
    for p in &mut m.positions {
        p[0] = p[0] * 1e3 + 12345.678;
        p[2] -= 1e-3;
    }
    let t = UnitCubeTransform::of_mesh(&m, 0.05).unwrap();
    let u = t.mesh_to_unit(&m);
    let (lo, hi) = u.bounding_box();
    assert!(lo.iter().all(|&c| c >= 0.05 - 1e-15) && hi.iter().all(|&c| c <= 0.95 + 1e-15));
    assert!((hi[0] - lo[0] - 0.9).abs() < 1e-12);
    let back = t.mesh_from_unit(&u);
    let d = m.diagonal();
    for (a, b) in m.positions.iter().zip(&back.positions) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= 1e-12 * d, "{a:?} {b:?}");
        }
    }
    // The matrices are the same maps.
    let mm = t.from_unit_matrix();
    let q = u.positions[7];
    for (row, want) in mm.iter().zip(m.positions[7]) {
        let via = row[0] * q[0] + row[1] * q[1] + row[2] * q[2] + row[3];
        assert!((via - want).abs() <= 1e-12 * d);
    }
    assert!(UnitCubeTransform::fit([1.0; 3], [1.0; 3], 0.05).is_none());
}

#[test]
fn assets_are_up_to_date() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    for (name, mesh) in shapes::asset_shapes() {
        let path = dir.join(format!("{name}.obj"));
        let read = mesh_io::read_mesh(&path)
            .unwrap_or_else(|e| panic!("{e}; regenerate with cargo run -p mesh-io --example make_assets -- assets"));
        assert_eq!(read.positions.len(), mesh.positions.len(), "{name}.obj");
        assert_eq!(
            read.canonical_triangles(),
            mesh.canonical_triangles(),
            "{name}.obj is stale: cargo run -p mesh-io --example make_assets -- assets"
        );
    }
}
