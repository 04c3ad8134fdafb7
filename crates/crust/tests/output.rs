//! What is checked is what is written: `crust::output::finalize` maps the crust to the
//! output frame, rounds it as the file stores it, repairs or refuses, and the file read
//! back (readers weld coincident positions) passes the exact check.

use std::path::Path;

use crust::check::check_crust;
use crust::output::{finalize, finalize_mesh, FrameMap, Precision};
use crust::{Crust, CrustConfig, CrustError};
use mesh_io::{TopologyReport, TriMesh, UnitCubeTransform};

/// xorshift64*: deterministic uniform sites in the open unit cube.
fn uniform(seed: u64, k: usize) -> Vec<[f64; 3]> {
    let mut s = seed | 1;
    let mut r = || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        ((s.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..k).map(|_| [r(), r(), r()]).collect()
}

fn ball_crust(seed: u64, k: usize) -> Crust {
    let sites = uniform(seed, k);
    let inside: Vec<bool> = sites
        .iter()
        .map(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2) < 0.35 * 0.35)
        .collect();
    Crust::extract(&sites, &inside, &CrustConfig::default()).unwrap()
}

/// The crust mapped and rounded naively (what was written before), welded as a reader
/// welds it.
fn naive(mesh: &TriMesh, t: &UnitCubeTransform, precision: Precision) -> TriMesh {
    mesh_io::weld::weld_exact(&TriMesh {
        positions: mesh.positions.iter().map(|&p| t.from_unit(p).map(|x| precision.round(x))).collect(),
        triangles: mesh.triangles.clone(),
    })
}

/// Write `mesh` to `name` in a temporary folder, read it back, check it, and compare.
fn write_and_reread(mesh: &TriMesh, name: &str) -> TriMesh {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    mesh_io::write_mesh(&path, mesh).unwrap();
    let back = mesh_io::read_mesh(&path).unwrap();
    check_crust(&back).unwrap_or_else(|e| panic!("{name} read back: {e}"));
    assert_eq!(&back, mesh, "{name}: the file read back differs from the mesh checked");
    back
}

#[test]
fn a_crust_that_rounding_does_not_break_is_written_as_mapped() {
    let c = ball_crust(1, 2000);
    let t = UnitCubeTransform::fit([-3.0, 2.0, 10.0], [5.0, 7.5, 12.0], 0.05).unwrap();
    let f = finalize(&c, t, Precision::F32).unwrap();
    assert_eq!(f.mesh.triangles, c.mesh.triangles);
    let expected: Vec<[f64; 3]> = c.mesh.positions.iter().map(|&p| t.from_unit(p).map(|x| x as f32 as f64)).collect();
    assert_eq!(f.mesh.positions, expected);
    assert_eq!((f.num_merged_vertices, f.num_separated_vertices), (0, 0));
    // The mesh-only form agrees when rounding breaks nothing.
    assert_eq!(finalize_mesh(&c.mesh, t, Precision::F32).unwrap().mesh, f.mesh);
    write_and_reread(&f.mesh, "crust.glb");
    write_and_reread(&f.mesh, "crust.gltf");
    // Lossless formats: the f64 map itself.
    let f = finalize(&c, FrameMap::from(&t), Precision::of_path(Path::new("x.obj")).unwrap()).unwrap();
    assert_eq!(f.mesh.positions, c.mesh.positions.iter().map(|&p| t.from_unit(p)).collect::<Vec<_>>());
    write_and_reread(&f.mesh, "crust.obj");
    write_and_reread(&f.mesh, "crust.ply");
}

#[test]
fn f32_rounding_far_from_the_origin_is_repaired() {
    // A 10-unit part 1e4 units from the origin: float32 steps of 1e-3, and among 17,000
    // crust triangles some vertices closer than that. Rounded naively, the file is not
    // closed (distinct vertices weld into one) and has degenerate faces.
    let c = ball_crust(7, 20_000);
    let t = UnitCubeTransform::fit([1e4; 3], [1e4 + 10.0; 3], 0.05).unwrap();
    let bad = naive(&c.mesh, &t, Precision::F32);
    let r = TopologyReport::of(&bad);
    assert!(!r.is_closed && r.num_degenerate_faces > 0, "the case no longer breaks naive rounding: {r:?}");
    assert!(check_crust(&bad).is_err());

    let f = finalize(&c, t, Precision::F32).unwrap();
    assert!(f.num_merged_vertices > 0);
    assert!(f.mesh.positions.iter().flatten().all(|&x| x as f32 as f64 == x), "not float32");
    assert_eq!((f.check.report.num_components, f.check.report.genus), (1, Some(0)));
    // The volume moves by rounding only (about 1e-3 units on a ball of radius 3.3).
    let v0 = TopologyReport::of(&t.mesh_from_unit(&c.mesh)).signed_volume;
    assert!((f.check.report.signed_volume - v0).abs() < 1e-3 * v0, "{} vs {v0}", f.check.report.signed_volume);
    write_and_reread(&f.mesh, "far.glb");
}

#[test]
fn mirrored_pairs_in_millimetres_are_written_valid() {
    // Mirrored pairs across a sphere (nearly degenerate everywhere), mapped to an 80 mm part
    // at (250, 120, 40) mm, written as GLB.
    let k = 2048;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let d = 0.25 * 0.3 * (4.0 * std::f64::consts::PI / k as f64).sqrt();
    let mut sites = Vec::new();
    let mut inside = Vec::new();
    for i in 0..k {
        let z = 1.0 - (2.0 * i as f64 + 1.0) / k as f64;
        let rho = (1.0 - z * z).sqrt();
        let n = [rho * (golden * i as f64).cos(), rho * (golden * i as f64).sin(), z];
        for (s, label) in [(0.3 - d, true), (0.3 + d, false)] {
            sites.push(n.map(|x| 0.5 + s * x));
            inside.push(label);
        }
    }
    let c = Crust::extract(&sites, &inside, &CrustConfig::default()).unwrap();
    let t = UnitCubeTransform::fit([210.0, 80.0, 0.0], [290.0, 160.0, 80.0], 0.05).unwrap();
    let f = finalize(&c, t, Precision::F32).unwrap();
    assert_eq!((f.check.report.num_components, f.check.report.genus), (1, Some(0)));
    write_and_reread(&f.mesh, "pairs.glb");
}

#[test]
fn a_precision_too_coarse_for_the_crust_is_refused() {
    // A 10-unit part 1e6 units from the origin: float32 steps of 0.06, coarser than much
    // of the crust; naive rounding leaves hundreds of degenerate faces.
    let c = ball_crust(3, 2000);
    let t = UnitCubeTransform::fit([1e6; 3], [1e6 + 10.0; 3], 0.05).unwrap();
    assert!(TopologyReport::of(&naive(&c.mesh, &t, Precision::F32)).num_degenerate_faces > 100);
    match finalize(&c, t, Precision::F32) {
        Err(CrustError::Unwritable(m)) => assert!(m.contains(".obj or .ply"), "{m}"),
        Err(e) => panic!("wrong error {e}"),
        // Repaired instead: then it must be valid as written.
        Ok(f) => {
            write_and_reread(&f.mesh, "coarse.glb");
        }
    }
    // The same crust written losslessly is fine.
    let f = finalize(&c, t, Precision::F64).unwrap();
    write_and_reread(&f.mesh, "coarse.obj");
}

#[test]
fn coordinates_the_output_cannot_hold_are_refused() {
    let c = ball_crust(5, 500);
    // A scale of 1e300 (unit cube → 1e300 units): infinite in f32, beyond ±1e30 in f64.
    let m = [[1e300, 0.0, 0.0, 0.0], [0.0, 1e300, 0.0, 0.0], [0.0, 0.0, 1e300, 0.0], [0.0, 0.0, 0.0, 1.0]];
    for precision in [Precision::F32, Precision::F64] {
        let e = finalize(&c, m, precision).unwrap_err();
        assert!(matches!(e, CrustError::Unwritable(_)), "{e}");
        assert!(e.to_string().contains("maps to"), "{e}");
    }
    let e = finalize(&c, m, Precision::F32).unwrap_err().to_string();
    assert!(e.contains("not a finite number"), "{e}");
    // The same through a UnitCubeTransform (its scale is unit lengths per input length).
    let t = UnitCubeTransform { center: [0.0; 3], scale: 1e-300 };
    assert!(matches!(finalize(&c, t, Precision::F32), Err(CrustError::Unwritable(_))));
    // A singular or non-finite map.
    let mut singular = m;
    singular[2][2] = 0.0;
    assert!(matches!(finalize(&c, singular, Precision::F64), Err(CrustError::Unwritable(_))));
    let t = UnitCubeTransform { center: [f64::NAN, 0.0, 0.0], scale: 1.0 };
    assert!(matches!(finalize(&c, t, Precision::F64), Err(CrustError::Unwritable(_))));
}

fn lattice(n: usize) -> Vec<[f64; 3]> {
    let mut v = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                v.push([(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64, (k as f64 + 0.5) / n as f64]);
            }
        }
    }
    v
}

#[test]
fn split_vertices_are_moved_apart_for_a_file() {
    // A checkerboard of cubes touching along edges: the crust splits vertices (copies share
    // a position), which every reader would weld into non-manifold vertices.
    let s = lattice(4);
    let checker: Vec<bool> = (0..s.len()).map(|i| (i / 16 + (i / 4) % 4 + i % 4) % 2 == 0).collect();
    let c = Crust::extract(&s, &checker, &CrustConfig::default()).unwrap();
    assert!(c.stats.num_split_vertices > 0);
    assert!(check_crust(&mesh_io::weld::weld_exact(&c.mesh)).is_err(), "welded, the crust is not manifold");
    for (precision, name) in
        [(Precision::F64, "checker.obj"), (Precision::F64, "checker.ply"), (Precision::F32, "checker.glb")]
    {
        let f = finalize(&c, FrameMap::Identity, precision).unwrap();
        assert!(f.num_separated_vertices > 0);
        let r = &f.check.report;
        assert_eq!((r.num_components, r.genus), (c.check.report.num_components, c.check.report.genus));
        // Copies move by a few units in the last place into their own cube.
        let tolerance = if precision == Precision::F32 { 1e-5 } else { 1e-12 };
        assert!((r.signed_volume - 0.5).abs() < tolerance, "{}", r.signed_volume);
        write_and_reread(&f.mesh, name);
        // From the triangles alone too.
        let f = finalize_mesh(&c.mesh, FrameMap::Identity, precision).unwrap();
        write_and_reread(&f.mesh, name);
    }
    // And through a transform that mirrors: still counter-clockwise seen from outside.
    let t = UnitCubeTransform { center: [3.0, -2.0, 1.0], scale: -0.5 };
    let f = finalize(&c, t, Precision::F32).unwrap();
    assert!(f.check.report.signed_volume > 0.0);
    assert!(((f.check.report.signed_volume - 4.0) / 4.0).abs() < 1e-4, "{}", f.check.report.signed_volume);
    write_and_reread(&f.mesh, "mirrored.glb");
}

#[test]
fn an_empty_crust_stays_empty() {
    let c = Crust::extract(&uniform(9, 50), &[false; 50], &CrustConfig::default()).unwrap();
    let f = finalize(&c, FrameMap::Identity, Precision::F32).unwrap();
    assert!(f.mesh.triangles.is_empty() && f.mesh.positions.is_empty());
}

#[test]
fn glb_and_ply_of_the_reference_cases_agree() {
    // As tests/reference/test_crust.py writes them: scale 2, offset (−1, 5, 0.25); GLB and
    // PLY hold the same triangles, and the checkerboard in its own frame has volume 1/2.
    let m = [[2.0, 0.0, 0.0, -1.0], [0.0, 2.0, 0.0, 5.0], [0.0, 0.0, 2.0, 0.25], [0.0, 0.0, 0.0, 1.0]];
    let s = lattice(6);
    let checker: Vec<bool> = (0..s.len()).map(|i| (i / 36 + (i / 6) % 6 + i % 6) % 2 == 0).collect();
    let u = uniform(20261122, 3000);
    let ball: Vec<bool> =
        u.iter().map(|p| (p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2) < 0.35 * 0.35).collect();
    for (sites, labels) in [(&s, &checker), (&u, &ball)] {
        let c = Crust::extract(sites, labels, &CrustConfig::default()).unwrap();
        let glb = finalize(&c, m, Precision::F32).unwrap();
        let ply = finalize(&c, m, Precision::F64).unwrap();
        assert_eq!(glb.mesh.triangles.len(), ply.mesh.triangles.len());
        assert!((ply.check.report.signed_volume - 8.0 * c.check.report.signed_volume).abs() < 1e-9);
        write_and_reread(&glb.mesh, "reference.glb");
        write_and_reread(&ply.mesh, "reference.ply");
    }
    let c = Crust::extract(&s, &checker, &CrustConfig::default()).unwrap();
    let f = finalize(&c, FrameMap::Identity, Precision::F64).unwrap();
    assert!((f.check.report.signed_volume - 0.5).abs() < 1e-12, "{}", f.check.report.signed_volume);
}

/// Frozen cases from the main job on `../shared/meshes/mikedh__soup.stl` (sites near the
/// failure cut out of its sites file, so the crust there is the one the full run made),
/// which once failed as float32 GLB with "the crust cannot be written".
fn soup_case(name: &str) -> (Crust, [[f64; 4]; 4]) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name);
    let file = crust::SitesFile::read(&path).unwrap();
    (Crust::extract(&file.sites, &file.inside, &CrustConfig::default()).unwrap(), file.transform)
}

#[test]
fn a_nearly_straight_corner_is_not_the_middle_of_a_sliver() {
    // 311 sites: Voronoi faces with corners all but straight. Fans from a fixed corner made
    // those corners the middle of slivers thinner than a float32 step, which folded onto
    // their neighbours once rounded; the best-shaped triangulation uses them as apexes.
    let (c, m) = soup_case("soup_f32_sliver.sites.npz");
    let f = finalize(&c, m, Precision::F32).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(f.topology_before, None);
    assert_eq!((f.check.report.num_components, f.check.report.genus), (1, Some(5)));
    write_and_reread(&f.mesh, "sliver.glb");
    write_and_reread(&finalize(&c, m, Precision::F64).unwrap().mesh, "sliver.ply");
}

#[test]
fn a_handle_thinner_than_float32_closes_and_is_reported() {
    // 425 sites whose exact crust has a handle about one float32 step thick: it cannot stay
    // open in the file, so the merge closes it and says so, instead of refusing to write.
    let (c, m) = soup_case("soup_f32_thin_handle.sites.npz");
    assert_eq!((c.check.report.num_components, c.check.report.genus), (1, Some(22)));
    let f = finalize(&c, m, Precision::F32).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(f.topology_before, Some((1, 22)));
    assert_eq!((f.check.report.num_components, f.check.report.genus), (1, Some(21)));
    assert!(f.merge_distance <= 4.0 * 2f64.powi(-23) * 1.2, "{}", f.merge_distance);
    write_and_reread(&f.mesh, "handle.glb");
    // In float64 nothing is that thin: the exact topology.
    let f = finalize(&c, m, Precision::F64).unwrap();
    assert_eq!((f.topology_before, f.check.report.genus), (None, Some(22)));
}
