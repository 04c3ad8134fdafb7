//! The binary on hostile or awkward input: unrepresentable coordinates, bad output paths,
//! float32 resolution, hairline cracks and `--weld-tolerance`.

use std::path::{Path, PathBuf};
use std::process::Output;

mod common;
use common::{bin, root, shared_meshes};

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn featuretype() -> PathBuf {
    shared_meshes().into_iter().find(|p| p.file_name().unwrap() == "mikedh__featuretype.STL").unwrap()
}

/// Exit 2, one line naming the file, numbers short.
fn assert_refused(o: &Output, input: &Path, expect: &str) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains(&input.display().to_string()), "the message must name the file: {e}");
    assert!(e.contains(expect), "{expect:?} in {e}");
    assert_eq!(e.trim_end().lines().count(), 1, "one paragraph: {e}");
    assert!(!e.contains("0000000000") && !e.contains("panicked"), "{e}");
}

#[test]
fn info_and_convert_refuse_coordinates_beyond_1e30() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "big.obj", "v 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\nf 1 2 3\n");
    let out_dir = tempfile::tempdir().unwrap();
    let o = bin().arg("info").arg(&input).output().unwrap();
    assert_refused(&o, &input, "line 1: the vertex has x = 1.000e300, beyond the ±1e30");
    assert!(stderr(&o).contains("Rescale the mesh"));
    assert!(o.stdout.is_empty());
    for ext in ["glb", "ply"] {
        let out = out_dir.path().join(format!("out.{ext}"));
        let o = bin().arg("convert").arg(&input).arg("-o").arg(&out).output().unwrap();
        assert_refused(&o, &input, "1.000e300");
        assert_eq!(std::fs::read_dir(out_dir.path()).unwrap().count(), 0, "no output, no temporary file");
    }
    // A binary STL's float32 can hold 3e38: refused too, naming the triangle.
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&1u32.to_le_bytes());
    stl.extend_from_slice(&[0u8; 12]);
    for c in [[0.0f32, 0.0, 0.0], [3e38, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        c.iter().for_each(|x| stl.extend_from_slice(&x.to_le_bytes()));
    }
    stl.extend_from_slice(&[0, 0]);
    let input = d.path().join("big.stl");
    std::fs::write(&input, stl).unwrap();
    let o = bin().arg("info").arg(&input).output().unwrap();
    assert_refused(&o, &input, "triangle 0: corner 1 of triangle 0 (byte 108) has x = 3.000e38");
}

#[test]
fn convert_checks_the_output_before_reading_the_input() {
    let d = tempfile::tempdir().unwrap();
    // The input does not even exist: the output is refused first.
    let input = d.path().join("no-such-input.obj");
    let out = d.path().join("missing/dir/out.glb");
    let o = bin().arg("convert").arg(&input).arg("-o").arg(&out).output().unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "an output that cannot be written exits 1, as before: {e}");
    assert!(e.contains("missing/dir does not exist") && e.contains("mkdir -p"), "{e}");
    assert!(!d.path().join("missing").exists());
    let o = bin().arg("convert").arg(&input).arg("-o").arg(d.path().join("out.stl")).output().unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert!(e.contains("out.stl") && e.contains("End the output name in .glb, .gltf, .obj or .ply."), "{e}");
    assert_eq!(std::fs::read_dir(d.path()).unwrap().count(), 0);
}

#[test]
fn convert_to_glb_refuses_a_mesh_float32_cannot_resolve() {
    let d = tempfile::tempdir().unwrap();
    // 1 mm at 1 km: float32 steps of 6e-5, 4% of the mesh.
    let input = write(d.path(), "far.obj", "v 1000 0 0\nv 1000.001 0 0\nv 1000 0.001 0\nf 1 2 3\n");
    let glb = d.path().join("far.glb");
    let o = bin().arg("convert").arg(&input).arg("-o").arg(&glb).output().unwrap();
    assert_refused(&o, &input, "steps of 6.104e-5");
    assert!(!glb.exists());
    // Lossless outputs and a normalised GLB are fine; info reads it and says why.
    let ply = d.path().join("far.ply");
    assert!(bin().arg("convert").arg(&input).arg("-o").arg(&ply).status().unwrap().success());
    let o = bin().arg("convert").arg(&input).arg("-o").arg(&glb).arg("--normalize").output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let o = bin().arg("info").arg(&input).output().unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("note: the mesh spans"));
}

#[test]
fn info_hints_at_the_weld_and_the_weld_closes_featuretype() {
    let feature = featuretype();
    let o = bin().arg("info").arg(&feature).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains("hint: 288 vertex pairs lie within 1e-6 of the diagonal: try --weld-tolerance 1e-6"),
        "{text}"
    );
    // A closed mesh gets no hint.
    let o = bin().arg("info").arg(root().join("assets/icosphere.obj")).output().unwrap();
    assert!(!String::from_utf8_lossy(&o.stdout).contains("hint:"));

    let o = bin().args(["info", "--json", "--weld-tolerance", "1e-6"]).arg(&feature).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!((v["is_closed"].as_bool(), v["num_boundary_loops"].as_u64()), (Some(true), Some(0)));
    assert_eq!(v["genus"], 9);
    assert_eq!(v["num_near_vertex_pairs"], 0);
    let w = &v["weld"];
    assert_eq!(w["relative_tolerance"], 1e-6);
    assert_eq!(w["vertices_before"].as_u64().unwrap() - w["vertices_after"].as_u64().unwrap(), 288);
    let o = bin().args(["info", "--json"]).arg(&feature).output().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["num_near_vertex_pairs"], 288);
    assert!(v.get("weld").is_none());

    // convert writes the welded mesh, which reads back closed.
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("welded.ply");
    let o = bin().arg("convert").arg(&feature).arg("-o").arg(&out).args(["--weld-tolerance", "1e-6"]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("degenerate triangles dropped"));
    let o = bin().args(["info", "--json"]).arg(&out).output().unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["is_closed"], true);
}

#[test]
fn weld_tolerance_out_of_range_is_a_usage_error() {
    let input = root().join("assets/icosphere.obj");
    for bad in ["0.5", "-1e-6", "nan", "1e-20", "x"] {
        let o = bin().arg("info").arg(&input).arg(format!("--weld-tolerance={bad}")).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{bad}: {}", stderr(&o));
        assert!(stderr(&o).contains("--weld-tolerance"), "{}", stderr(&o));
    }
}

/// The main job refuses the 1e300 mesh before any work (it used to fit it and write a GLB
/// of infinite vertices), and writes nothing.
#[test]
fn the_main_job_refuses_coordinates_beyond_1e30() {
    let d = tempfile::tempdir().unwrap();
    let input = write(d.path(), "big.obj", "v 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\nf 1 2 3\n");
    let out_dir = tempfile::tempdir().unwrap();
    let o = bin().arg(&input).arg("-o").arg(out_dir.path().join("big.glb")).arg("--quiet").output().unwrap();
    assert_refused(&o, &input, "1.000e300");
    assert_eq!(std::fs::read_dir(out_dir.path()).unwrap().count(), 0, "no output, no temporary file");
}
