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
