//! `voronoi-fit batch`: one folder per mesh and summary.csv; bad meshes recorded and the
//! batch goes on; reruns skip, redo on changed options, and resume a killed fit from its
//! checkpoint to the same result as an uninterrupted one; `--jobs` does not change results.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

mod common;
use common::{bin, root, shared_meshes};

/// Small and fast fit options for the tests.
const FIT: [&str; 11] =
    ["--", "--sites", "256", "--steps", "20", "--samples", "20000", "--eval-samples", "2000", "--polish-steps", "100"];

fn summary(dir: &Path) -> Vec<std::collections::HashMap<String, String>> {
    let text = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap().split(',').map(String::from).collect();
    lines
        .map(|l| {
            // Quoted fields (errors) may hold commas: split only the unquoted ones.
            let mut fields = Vec::new();
            let (mut cur, mut quoted) = (String::new(), false);
            for c in l.chars() {
                match c {
                    '"' => quoted = !quoted,
                    ',' if !quoted => fields.push(std::mem::take(&mut cur)),
                    _ => cur.push(c),
                }
            }
            fields.push(cur);
            assert_eq!(fields.len(), header.len(), "{l}");
            header.iter().cloned().zip(fields).collect()
        })
        .collect()
}

fn inputs(dir: &Path) -> PathBuf {
    let d = dir.join("in");
    std::fs::create_dir_all(&d).unwrap();
    for m in ["bunny.obj", "torus.obj"] {
        std::fs::copy(root().join("assets").join(m), d.join(m)).unwrap();
    }
    // A soup from the shared meshes, and two broken files.
    let soup = shared_meshes().into_iter().find(|p| p.file_name().unwrap() == "mikedh__soup.stl").unwrap();
    std::fs::copy(soup, d.join("soup.stl")).unwrap();
    for bad in ["nan_vertex.obj", "truncated.glb"] {
        std::fs::copy(root().join("tests/malformed").join(bad), d.join(bad)).unwrap();
    }
    d
}

fn file_bytes(p: PathBuf) -> Vec<u8> {
    std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn a_batch_records_bad_meshes_goes_on_and_reruns_skip_or_redo() {
    let tmp = tempfile::tempdir().unwrap();
    let input = inputs(tmp.path());
    let out = tmp.path().join("out");
    let o = bin().arg("batch").arg(&input).arg("--out").arg(&out).arg("--quiet").args(FIT).output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "two meshes are broken: {stderr}");
    assert!(stderr.contains("nan_vertex.obj") && stderr.contains("truncated.glb"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let rows = summary(&out);
    assert_eq!(rows.len(), 5);
    for r in &rows {
        let good = ["bunny", "torus", "soup"].contains(&r["name"].as_str());
        if good {
            assert_eq!(r["status"], "fitted", "{r:?}");
            let folder = out.join(&r["name"]);
            for suffix in ["glb", "sites.npz", "report.json", "png"] {
                assert!(folder.join(format!("{}.voronoi.{suffix}", r["name"])).is_file(), "{r:?}: {suffix}");
            }
            assert!(r["hausdorff_of_diagonal"].parse::<f64>().unwrap() > 0.0, "{r:?}");
            assert!(r["triangles"].parse::<u64>().unwrap() > 0, "{r:?}");
            // The solid fitted and why, per mesh; the closed meshes hold no band.
            assert!(["winding", "shell", "flood"].contains(&r["solid"].as_str()), "{r:?}");
            assert!(r["solid_chosen_by"].starts_with("auto"), "{r:?}");
            if r["name"] != "soup" {
                assert_eq!(
                    (r["solid"].as_str(), r["band_half_thickness_of_diagonal"].as_str()),
                    ("winding", ""),
                    "{r:?}"
                );
            } else if r["solid"] == "winding" {
                // An open mesh's winding solid has caps, and their share is given.
                assert!(r["cap_area_share"].parse::<f64>().is_ok(), "{r:?}");
            }
            if r["name"] == "torus" {
                // A clean closed input: its genus, and the crust's handles against it.
                assert_eq!(r["input_genus"], "1", "{r:?}");
                let closed: i64 = r["handles_closed"].parse().unwrap();
                let added: i64 = r["handles_added"].parse().unwrap();
                assert_eq!(closed - added, 1 - r["genus"].parse::<i64>().unwrap(), "{r:?}");
            }
        } else {
            assert_eq!(r["status"], "bad input", "{r:?}");
            assert!(r["error"].contains(&r["name"]), "the error names the file: {r:?}");
            assert!(!out.join(&r["name"]).exists(), "no folder for a failed mesh");
        }
    }
    // Nothing half made is left in the work area.
    assert_eq!(std::fs::read_dir(out.join(".work")).unwrap().count(), 0);

    // Rerun: the three results are kept as they are; the two broken meshes are tried again.
    let before = file_bytes(out.join("torus/torus.voronoi.glb"));
    let o = bin().arg("batch").arg(&input).arg("--out").arg(&out).arg("--quiet").args(FIT).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("0 fitted now") && stdout.contains("3 already done"), "{stdout}");
    let rows = summary(&out);
    assert_eq!(rows.iter().filter(|r| r["status"] == "done earlier").count(), 3);
    assert_eq!(rows.iter().filter(|r| r["status"] == "bad input").count(), 2);

    // Fixed inputs and other options: everything is fitted again, old folders replaced.
    for bad in ["nan_vertex.obj", "truncated.glb"] {
        std::fs::remove_file(input.join(bad)).unwrap();
    }
    let mut other = FIT.to_vec();
    other[4] = "21";
    let o = bin().arg("batch").arg(&input).arg("--out").arg(&out).arg("--quiet").args(&other).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = summary(&out);
    assert_eq!(rows.len(), 3);
    assert!(rows.iter().all(|r| r["status"] == "fitted"), "{rows:?}");
    let report: serde_json::Value =
        serde_json::from_slice(&file_bytes(out.join("torus/torus.voronoi.report.json"))).unwrap();
    assert_eq!(report["settings"]["train"]["steps"], 21);
    assert_ne!(before, file_bytes(out.join("torus/torus.voronoi.glb")));
}

#[test]
fn a_killed_batch_resumes_from_the_checkpoint_to_the_same_result() {
    let tmp = tempfile::tempdir().unwrap();
    let input = inputs(tmp.path());
    let bunny = input.join("bunny.obj");
    let fit = [
        "--",
        "--sites",
        "1024",
        "--steps",
        "400",
        "--checkpoint-every",
        "5",
        "--samples",
        "50000",
        "--eval-samples",
        "2000",
        "--polish-steps",
        "100",
    ];
    // The uninterrupted result.
    let clean = tmp.path().join("clean");
    let o = bin().arg("batch").arg(&bunny).arg("--out").arg(&clean).arg("--quiet").args(fit).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // Killed (SIGKILL: no chance to clean up) once a checkpoint is on disk, then rerun.
    let out = tmp.path().join("out");
    let mut child = bin().arg("batch").arg(&bunny).arg("--out").arg(&out).arg("--quiet").args(fit).spawn().unwrap();
    let ckpt = out.join(".work/bunny/bunny.voronoi.ckpt.npz");
    let t = Instant::now();
    while !ckpt.exists() && t.elapsed() < Duration::from_secs(120) {
        std::thread::sleep(Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(ckpt.exists(), "no checkpoint appeared");
    assert!(!out.join("bunny").exists(), "a killed fit must not look finished");
    let o = bin().arg("batch").arg(&bunny).arg("--out").arg(&out).arg("--quiet").args(fit).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = summary(&out);
    assert_eq!(rows[0]["status"], "fitted (resumed)", "{rows:?}");
    assert_eq!(
        file_bytes(out.join("bunny/bunny.voronoi.glb")),
        file_bytes(clean.join("bunny/bunny.voronoi.glb")),
        "the resumed crust differs from the uninterrupted one"
    );
    assert!(!out.join(".work/bunny").exists());
}

#[test]
fn jobs_do_not_change_results_and_bad_options_exit_2() {
    let tmp = tempfile::tempdir().unwrap();
    let input = inputs(tmp.path());
    let list = tmp.path().join("list.txt");
    std::fs::write(&list, "# two meshes\nin/bunny.obj\n\nin/torus.obj\n").unwrap();
    let run = |jobs: &str, out: &Path| {
        let o = bin()
            .arg("batch")
            .arg(format!("@{}", list.display()))
            .arg("--out")
            .arg(out)
            .args(["--quiet", "--jobs", jobs])
            .args(FIT)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (one, two) = (tmp.path().join("one"), tmp.path().join("two"));
    run("1", &one);
    run("2", &two);
    for m in ["bunny", "torus"] {
        let f = format!("{m}/{m}.voronoi.glb");
        assert_eq!(file_bytes(one.join(&f)), file_bytes(two.join(&f)), "{m}: --jobs changed the crust");
    }
    let bad: [&[&str]; 5] = [
        &["--", "-o", "x.glb"],
        &["--", "--resume", "x.npz"],
        &["--", "--sites", "many"],
        &["--jobs", "0"],
        &["--", "--no-such-option"],
    ];
    for args in bad {
        let o = bin().arg("batch").arg(&input).arg("--out").arg(tmp.path().join("bad")).args(args).output().unwrap();
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(!tmp.path().join("bad").exists(), "{args:?}: nothing written on a usage error");
    }
    let o =
        bin().arg("batch").arg(tmp.path().join("nowhere")).arg("--out").arg(tmp.path().join("bad")).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    std::fs::write(&list, "in/missing.obj\n").unwrap();
    let o = bin()
        .arg("batch")
        .arg(format!("@{}", list.display()))
        .arg("--out")
        .arg(tmp.path().join("bad"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr.contains("line 1") && stderr.contains("list.txt"), "{stderr}");
}

/// The arrays of an uncompressed `.npz` (numpy's `savez`, the project's writer): name →
/// (dtype descriptor, shape, data bytes).
fn npz_arrays(bytes: &[u8]) -> std::collections::HashMap<String, (String, Vec<usize>, Vec<u8>)> {
    let u16_at = |i: usize| u16::from_le_bytes([bytes[i], bytes[i + 1]]) as usize;
    let u32_at = |i: usize| u32::from_le_bytes(bytes[i..i + 4].try_into().unwrap()) as usize;
    let mut out = std::collections::HashMap::new();
    let mut i = 0;
    while bytes[i..].starts_with(b"PK\x03\x04") {
        assert_eq!(u16_at(i + 8), 0, "stored, not compressed");
        let (size, name_len, extra_len) = (u32_at(i + 18), u16_at(i + 26), u16_at(i + 28));
        let name = String::from_utf8(bytes[i + 30..i + 30 + name_len].to_vec()).unwrap();
        let data = &bytes[i + 30 + name_len + extra_len..i + 30 + name_len + extra_len + size];
        assert!(data.starts_with(b"\x93NUMPY\x01\x00"), "{name}");
        let header = std::str::from_utf8(&data[10..10 + u16::from_le_bytes([data[8], data[9]]) as usize]).unwrap();
        let field = |key: &str, end: char| {
            let rest = &header[header.find(key).unwrap() + key.len()..];
            rest[..rest.find(end).unwrap()].to_string()
        };
        let descr = field("'descr': '", '\'');
        let shape = field("'shape': (", ')').split(',').filter_map(|s| s.trim().parse().ok()).collect();
        out.insert(name.trim_end_matches(".npy").to_string(), (descr, shape, data[10 + header.len()..].to_vec()));
        i += 30 + name_len + extra_len + size;
    }
    out
}

/// IEEE half precision → f64.
fn f16_to_f64(h: u16) -> f64 {
    let sign = if h >> 15 == 1 { -1.0 } else { 1.0 };
    let (e, m) = (((h >> 10) & 0x1f) as i32, (h & 0x3ff) as f64);
    sign * match e {
        0 => m * 2f64.powi(-24),
        31 => f64::NAN,
        _ => (1.0 + m / 1024.0) * 2f64.powi(e - 15),
    }
}

/// `-- --occupancy N`: each folder gets NAME.voronoi.points.npz in Occupancy Networks'
/// layout (float16 points in the normalised frame, packed bits, loc and scale), listed in
/// the report and summary.csv; the uniform points' labels are the written crust's inside
/// by its own winding number (off only within float16 rounding of the crust).
#[test]
fn a_batch_writes_occupancy_samples_of_the_fitted_solid() {
    let tmp = tempfile::tempdir().unwrap();
    let input = tmp.path().join("in");
    std::fs::create_dir_all(&input).unwrap();
    std::fs::copy(root().join("assets/torus.obj"), input.join("torus.obj")).unwrap();
    let soup = shared_meshes().into_iter().find(|p| p.file_name().unwrap() == "mikedh__soup.stl").unwrap();
    std::fs::copy(soup, input.join("soup.stl")).unwrap();
    let out = tmp.path().join("out");
    let n = 20_000;
    let o = bin()
        .arg("batch")
        .arg(&input)
        .arg("--out")
        .arg(&out)
        .arg("--quiet")
        .args(FIT)
        .args(["--occupancy", &n.to_string()])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let rows = summary(&out);
    assert_eq!(rows.len(), 2);
    for r in &rows {
        let name = &r["name"];
        let path = out.join(name).join(format!("{name}.voronoi.points.npz"));
        assert_eq!(Path::new(&r["occupancy"]), path, "{r:?}");
        let report: serde_json::Value =
            serde_json::from_slice(&file_bytes(out.join(name).join(format!("{name}.voronoi.report.json")))).unwrap();
        assert!(report["outputs"]["occupancy"].as_str().unwrap().ends_with(&format!("{name}.voronoi.points.npz")));

        let arrays = npz_arrays(&file_bytes(path));
        let mut keys: Vec<&str> = arrays.keys().map(String::as_str).collect();
        keys.sort();
        assert_eq!(keys, ["loc", "occupancies", "points", "scale"]);
        let (descr, shape, points) = &arrays["points"];
        assert_eq!((descr.as_str(), shape.as_slice()), ("<f2", &[n, 3][..]));
        let (descr, shape, packed) = &arrays["occupancies"];
        assert_eq!((descr.as_str(), shape.as_slice()), ("|u1", &[n.div_ceil(8)][..]));
        let (descr, shape, loc) = &arrays["loc"];
        assert_eq!((descr.as_str(), shape.as_slice()), ("<f4", &[3][..]));
        let (descr, shape, scale) = &arrays["scale"];
        assert_eq!((descr.as_str(), shape.len()), ("<f4", 0));
        let loc: Vec<f64> = loc.chunks(4).map(|b| f32::from_le_bytes(b.try_into().unwrap()) as f64).collect();
        let scale = f32::from_le_bytes(scale[..4].try_into().unwrap()) as f64;
        let labels: Vec<bool> = (0..n).map(|i| packed[i / 8] >> (7 - i % 8) & 1 == 1).collect();
        let inside = labels.iter().filter(|&&b| b).count();
        assert!(inside > 0 && inside < n, "{name}: both labels ({inside} of {n} inside)");
        let unit: Vec<[f64; 3]> = points
            .chunks(6)
            .map(|b| [0, 1, 2].map(|k| f16_to_f64(u16::from_le_bytes([b[2 * k], b[2 * k + 1]]))))
            .collect();
        // The mesh normalised: its box centred at the origin with its longest side 1; the
        // uniform points fill the cube of side 1.1.
        let uniform = n / 2;
        assert!(unit[..uniform].iter().flatten().all(|c| c.abs() <= 0.55 + 1e-3), "{name}");
        let near_inside = labels[uniform..].iter().filter(|&&b| b).count() as f64 / (n - uniform) as f64;
        assert!((0.2..0.8).contains(&near_inside), "{name}: near-surface points inside {near_inside}");

        // The crust as written decides inside by its winding number.
        let crust = mesh_io::read_mesh(&out.join(name).join(format!("{name}.voronoi.glb"))).unwrap();
        let oracle = occupancy::MeshOracle::from_mesh(&crust, &occupancy::Config::default()).unwrap();
        let queries: Vec<[f64; 3]> = unit[..uniform].iter().map(|u| [0, 1, 2].map(|k| u[k] * scale + loc[k])).collect();
        let truth = oracle.query(&queries, occupancy::WindingMode::Exact).unwrap();
        let rounding = 1e-3 * scale;
        let mut off = 0;
        for (i, &label) in labels[..uniform].iter().enumerate() {
            if (truth.occupancy[i] == 1) != label {
                off += 1;
                assert!(truth.sdf[i].abs() < rounding, "{name}: point {i} is {} from the crust", truth.sdf[i]);
            }
        }
        assert!(off * 1000 <= uniform, "{name}: {off} of {uniform} uniform labels disagree with the crust");
    }
    // Options out of range are refused before any work.
    for bad in [["--occupancy", "0"], ["--occupancy-uniform-fraction", "1.5"]] {
        let o = bin()
            .arg("batch")
            .arg(&input)
            .arg("--out")
            .arg(tmp.path().join("bad"))
            .args(["--", "--occupancy", "10"])
            .args(bad)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {stderr}");
        assert!(stderr.contains(bad[0]), "{stderr}");
        assert!(!tmp.path().join("bad").exists(), "{bad:?}: nothing written");
    }
}
