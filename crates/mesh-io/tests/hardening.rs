//! Input hardening: the representable range, output checks, the tolerance weld.

use std::path::{Path, PathBuf};

use mesh_io::weld::{count_near_pairs, weld_tolerance, PROBE_RELATIVE_TOLERANCE};
use mesh_io::{
    check_f32_resolution, check_output_location, check_representable, read_mesh, shapes, ErrorKind, Location,
    OutputFormat, TopologyReport, TriMesh,
};

fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// The shared meshes: `$VF_SHARED_MESHES`, else `../shared/meshes` beside the repository
/// (as the CLI tests find them).
fn shared_mesh(name: &str) -> PathBuf {
    let dir = std::env::var_os("VF_SHARED_MESHES")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/meshes"));
    let p = dir.join(name);
    assert!(p.exists(), "{}: the shared test meshes must sit beside the repository", p.display());
    p
}

fn binary_stl(corners: &[[f32; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&((corners.len() / 3) as u32).to_le_bytes());
    for t in corners.chunks(3) {
        b.extend_from_slice(&[0u8; 12]);
        for c in t {
            for x in c {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
        b.extend_from_slice(&[0, 0]);
    }
    b
}

fn binary_ply(points: &[[f64; 3]]) -> Vec<u8> {
    let mut b = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n",
        points.len()
    )
    .into_bytes();
    for p in points {
        for c in p {
            b.extend_from_slice(&c.to_le_bytes());
        }
    }
    b.push(3);
    for i in 0..3i32 {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// The error is Unrepresentable, names the file and `place`, prints the value short and
/// says how to fix it, in one line.
fn assert_range_error(e: &mesh_io::MeshError, path: &Path, place: &str, value: &str) {
    let text = e.to_string();
    assert_eq!(e.kind, ErrorKind::Unrepresentable, "{text}");
    assert!(text.starts_with(&path.display().to_string()), "{text}");
    assert!(text.contains(place), "{place:?} in {text}");
    assert!(text.contains(value), "{value:?} in {text}");
    assert!(text.contains("Rescale the mesh"), "{text}");
    assert!(text.len() < 400 && !text.contains("00000000"), "short numbers: {text}");
}

#[test]
fn obj_with_1e300_is_refused_naming_the_line() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "big.obj", b"v 0 0 0\nv 1e300 0 0\nv 0 1 0\nf 1 2 3\n");
    let e = read_mesh(&p).unwrap_err();
    assert_eq!(e.location, Location::Line(2));
    assert_range_error(&e, &p, "line 2", "x = 1.000e300");
    // Just inside the bound reads; just outside does not.
    let p = write(d.path(), "edge.obj", b"v 0 0 0\nv 0 -1e30 0\nv 0 0 1\nf 1 2 3\n");
    read_mesh(&p).unwrap();
    let p = write(d.path(), "over.obj", b"v 0 0 0\nv 0 -1.0001e30 0\nv 0 0 1\nf 1 2 3\n");
    assert_range_error(&read_mesh(&p).unwrap_err(), &p, "line 2", "y = -1.000e30");
}

#[test]
fn ascii_stl_off_and_ascii_ply_name_the_line() {
    let d = tempfile::tempdir().unwrap();
    let stl = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 -2e200\nendloop\nendfacet\nendsolid s\n";
    let p = write(d.path(), "big.stl", stl.as_bytes());
    assert_range_error(&read_mesh(&p).unwrap_err(), &p, "line 6", "z = -2.000e200");
    let off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 5e31 0\n3 0 1 2\n";
    let p = write(d.path(), "big.off", off.as_bytes());
    assert_range_error(&read_mesh(&p).unwrap_err(), &p, "line 5", "y = 5.000e31");
    let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1e300 0 0\n0 1 0\n3 0 1 2\n";
    let p = write(d.path(), "big.ply", ply.as_bytes());
    assert_range_error(&read_mesh(&p).unwrap_err(), &p, "line 11", "x = 1.000e300");
}

#[test]
fn binary_stl_with_huge_float32_is_refused_naming_the_triangle() {
    let d = tempfile::tempdir().unwrap();
    let bytes = binary_stl(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0; 3], [0.0, 3e38, 0.0], [0.0, 0.0, 1.0]]);
    let p = write(d.path(), "big.stl", &bytes);
    let e = read_mesh(&p).unwrap_err();
    assert_eq!(e.location, Location::Element { kind: "triangle", index: 1 });
    // Triangle 1 starts at byte 134, its corner 1 at 134 + 24, y 4 bytes later.
    assert_range_error(&e, &p, "corner 1 of triangle 1 (byte 162)", "y = 3.000e38");
}

#[test]
fn binary_ply_with_1e300_is_refused_naming_the_vertex() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "big.ply", &binary_ply(&[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1e300]]));
    let e = read_mesh(&p).unwrap_err();
    assert_eq!(e.location, Location::Element { kind: "vertex", index: 2 });
    assert_range_error(&e, &p, "vertex 2", "z = 1.000e300");
}

#[test]
fn nan_is_refused_as_non_finite() {
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "nan.ply", &binary_ply(&[[0.0; 3], [f64::NAN, 0.0, 0.0], [0.0, 0.0, 1.0]]));
    let e = read_mesh(&p).unwrap_err();
    assert_eq!((e.kind, e.location.clone()), (ErrorKind::NonFinite, Location::Element { kind: "vertex", index: 1 }));
    assert!(e.to_string().contains("x = NaN"), "{e}");
    let p = write(d.path(), "nan.obj", b"v 0 0 0\nv 0 nan 0\nv 0 0 1\nf 1 2 3\n");
    let e = read_mesh(&p).unwrap_err();
    assert_eq!((e.kind, e.location), (ErrorKind::NonFinite, Location::Line(2)));
    // An overflowing literal prints short, not as 400 digits.
    let long = format!("v 0 0 0\nv 1{} 0 0\nv 0 0 1\nf 1 2 3\n", "0".repeat(400));
    let p = write(d.path(), "inf.obj", long.as_bytes());
    let e = read_mesh(&p).unwrap_err();
    assert_eq!(e.kind, ErrorKind::NonFinite);
    assert!(e.to_string().len() < 300, "{e}");
}

#[test]
fn a_gltf_whose_node_transform_overflows_the_range_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let m = shapes::icosphere(0);
    let p = d.path().join("s.gltf");
    mesh_io::write_gltf(
        &p,
        &[mesh_io::SceneMesh { name: "m", mesh: &m, colors: None, normals: Default::default() }],
        mesh_io::GltfLayout::Separate,
    )
    .unwrap();
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&p).unwrap()).unwrap();
    json["nodes"][0]["scale"] = serde_json::json!([1e35, 1.0, 1.0]);
    std::fs::write(&p, serde_json::to_vec(&json).unwrap()).unwrap();
    let e = read_mesh(&p).unwrap_err();
    assert_range_error(
        &e,
        &p,
        "accessor 0: POSITION element 0 of accessor 0 (after the node transforms)",
        "x = -5.257e34",
    );
}

#[test]
fn check_representable_names_the_vertex_and_the_extent() {
    let tri = |s: f64, o: f64| TriMesh {
        positions: vec![[o, o, o], [o + s, o, o], [o, o + s, o]],
        triangles: vec![[0, 1, 2]],
    };
    let what = Path::new("built");
    check_representable(&tri(1.0, 0.0), what).unwrap();
    check_representable(&tri(1e-29, 0.0), what).unwrap();
    let e = check_representable(&tri(1e-31, 0.0), what).unwrap_err();
    assert_eq!((e.kind, e.location.clone()), (ErrorKind::Unrepresentable, Location::File));
    assert!(e.to_string().contains("spans only 1.414e-31"), "{e}");
    let e = check_representable(&tri(1.0, 2e30), what).unwrap_err();
    assert_eq!(e.location, Location::Element { kind: "vertex", index: 0 });
    // All vertices coinciding is left to later stages (they say so).
    check_representable(&tri(0.0, 5.0), what).unwrap();
    // TriMesh::validate includes the check.
    assert_eq!(tri(1.0, 2e30).validate(what).unwrap_err().kind, ErrorKind::Unrepresentable);
}

#[test]
fn f32_resolution_refuses_a_small_mesh_far_from_the_origin() {
    let tri = |s: f64, o: f64| TriMesh {
        positions: vec![[o, 0.0, 0.0], [o + s, 0.0, 0.0], [o, s, 0.0]],
        triangles: vec![[0, 1, 2]],
    };
    let what = Path::new("far.obj");
    check_f32_resolution(&tri(1.0, 0.0), what).unwrap();
    check_f32_resolution(&tri(1.0, 100.0), what).unwrap();
    check_f32_resolution(&tri(1e-20, 0.0), what).unwrap();
    // 1 mm at 1 km: float32 steps of 6.1e-5 m, 4% of the size... refused.
    let e = check_f32_resolution(&tri(1e-3, 1e3), what).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Unrepresentable);
    assert!(e.to_string().contains("steps of 6.104e-5"), "{e}");
    // Such a mesh still reads: info and lossless outputs are fine.
    let d = tempfile::tempdir().unwrap();
    let p = write(d.path(), "far.obj", b"v 1000 0 0\nv 1000.001 0 0\nv 1000 0.001 0\nf 1 2 3\n");
    read_mesh(&p).unwrap();
}

#[test]
fn every_shared_mesh_and_asset_is_representable() {
    let dir = shared_mesh("mikedh__bunny.ply").parent().unwrap().to_path_buf();
    let assets = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let mut n = 0;
    for d in [dir, assets] {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if mesh_io::Format::from_extension(&p).is_some() {
                let m = read_mesh(&p).unwrap_or_else(|e| panic!("{e}"));
                check_f32_resolution(&m, &p).unwrap();
                n += 1;
            }
        }
    }
    assert!(n >= 8);
}

#[test]
fn output_format_from_path() {
    assert_eq!(OutputFormat::from_path(Path::new("a/b.Glb")).unwrap(), OutputFormat::Glb);
    assert_eq!(OutputFormat::from_path(Path::new("b.gltf")).unwrap(), OutputFormat::Gltf);
    assert_eq!(OutputFormat::from_path(Path::new("b.OBJ")).unwrap(), OutputFormat::Obj);
    assert_eq!(OutputFormat::from_path(Path::new("b.ply")).unwrap(), OutputFormat::Ply);
    for bad in ["b.stl", "b.off", "b", "b.glb.tmp"] {
        let e = OutputFormat::from_path(Path::new(bad)).unwrap_err();
        assert_eq!(e.kind, ErrorKind::UnknownFormat);
        let text = e.to_string();
        assert!(text.starts_with(bad) && text.contains("End the output name in .glb, .gltf, .obj or .ply."), "{text}");
    }
    let only_gltf = [OutputFormat::Glb, OutputFormat::Gltf];
    assert_eq!(OutputFormat::from_path_in(Path::new("c.gltf"), &only_gltf).unwrap(), OutputFormat::Gltf);
    let e = OutputFormat::from_path_in(Path::new("c.ply"), &only_gltf).unwrap_err();
    assert!(e.to_string().contains("ends in .ply") && e.to_string().contains(".glb or .gltf."), "{e}");
    assert!(OutputFormat::Glb.stores_f32() && !OutputFormat::Ply.stores_f32());
}

#[test]
fn output_location_is_checked_and_left_clean() {
    let d = tempfile::tempdir().unwrap();
    check_output_location(&d.path().join("out.glb")).unwrap();
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0, "the probe file is removed");
    let missing = d.path().join("missing/dir/out.glb");
    let e = check_output_location(&missing).unwrap_err();
    assert_eq!(e.kind, ErrorKind::Write);
    let text = e.to_string();
    assert!(text.contains("missing/dir does not exist") && text.contains("mkdir -p"), "{text}");
    let e = check_output_location(d.path()).unwrap_err();
    assert!(e.to_string().contains("is a folder"), "{e}");
    let file = write(d.path(), "f", b"x");
    let e = check_output_location(&file.join("out.glb")).unwrap_err();
    assert!(e.to_string().contains("is not a folder"), "{e}");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let ro = d.path().join("ro");
        std::fs::create_dir(&ro).unwrap();
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
        // Root may write anyway; only check when the folder really refuses.
        if std::fs::write(ro.join("probe"), b"").is_err() {
            let e = check_output_location(&ro.join("out.glb")).unwrap_err();
            assert!(e.to_string().contains("cannot create a file in the output folder"), "{e}");
        }
        std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    // A bare file name means the current folder.
    check_output_location(Path::new("out.glb")).unwrap();
}

#[test]
fn featuretype_closes_after_welding_at_1e_minus_6() {
    let p = shared_mesh("mikedh__featuretype.STL");
    let m = read_mesh(&p).unwrap();
    let before = TopologyReport::of(&m);
    assert!(!before.is_closed);
    assert_eq!(before.num_boundary_loops, 16);
    let pairs = count_near_pairs(&m, PROBE_RELATIVE_TOLERANCE);
    assert_eq!(pairs, 288);
    let (w, stats) = weld_tolerance(&m, 1e-6);
    let after = TopologyReport::of(&w);
    assert!(after.is_closed && after.is_manifold && after.is_orientation_consistent, "{after:?}");
    assert_eq!(after.num_boundary_loops, 0);
    assert_eq!(after.genus, Some(9), "genus 9 per the shared meshes' README");
    assert_eq!(stats.vertices_before - stats.vertices_after, 288);
    assert_eq!(stats.vertices_after, w.positions.len());
    assert_eq!(stats.degenerate_triangles_dropped, m.triangles.len() - w.triangles.len());
    assert!((stats.absolute_tolerance - 1e-6 * m.diagonal()).abs() <= 1e-20);
    // Deterministic, and idempotent.
    assert_eq!(weld_tolerance(&m, 1e-6), (w.clone(), stats));
    let (again, s2) = weld_tolerance(&w, 1e-6);
    assert_eq!((again, s2.vertices_after, s2.degenerate_triangles_dropped), (w, stats.vertices_after, 0));
}

#[test]
fn weld_merges_chains_keeps_the_lowest_index_and_drops_degenerate_triangles() {
    // A unit square split in two, with vertex 4 a copy of vertex 2 moved by 1e-9 and a
    // sliver triangle (1, 2, 4) that collapses.
    let m = TriMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0 + 1e-9, 0.0]],
        triangles: vec![[0, 1, 2], [0, 4, 3], [1, 2, 4]],
    };
    let (w, s) = weld_tolerance(&m, 1e-6);
    assert_eq!(w.positions, m.positions[..4].to_vec());
    assert_eq!(w.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!((s.vertices_before, s.vertices_after, s.degenerate_triangles_dropped), (5, 4, 1));
    assert_eq!(count_near_pairs(&m, 1e-6), 1);
    assert_eq!(count_near_pairs(&m, 1e-10), 0);
    // Tolerance 0: nothing merges, nothing is dropped here.
    let (w0, s0) = weld_tolerance(&m, 0.0);
    assert_eq!((w0, s0.degenerate_triangles_dropped), (m.clone(), 0));
    // Chains: 0.4-spaced points on a line, tolerance 0.5 of ... relative to diag 2 → 1e-2
    // is 0.02 absolute; points 0.015 apart chain into one.
    let line = TriMesh {
        positions: (0..5).map(|i| [0.015 * i as f64, 0.0, 0.0]).chain([[2.0, 0.0, 0.0], [2.0, 0.1, 0.0]]).collect(),
        triangles: vec![[0, 5, 6], [4, 5, 6], [0, 4, 6]],
    };
    let (w, s) = weld_tolerance(&line, 1e-2);
    assert_eq!(s.vertices_after, 3, "{s:?}");
    assert_eq!(w.positions[0], [0.0, 0.0, 0.0]);
    assert_eq!(w.triangles, vec![[0, 1, 2], [0, 1, 2]], "the chain's ends merged; duplicates are kept");
    assert_eq!(s.degenerate_triangles_dropped, 1);
}

#[test]
#[should_panic(expected = "outside")]
fn weld_refuses_a_tolerance_out_of_range() {
    let _ = weld_tolerance(&shapes::icosphere(0), 0.5);
}
