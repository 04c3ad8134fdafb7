//! `voronoi-fit study sphere --quick`: every method under two seeds, the reference lines,
//! finite results, every Voronoi crust watertight, the summary and the plot written.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::process::Command;

#[test]
fn quick_sphere_study_writes_finite_results_and_watertight_crusts() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("study");
    let o = Command::new(env!("CARGO_BIN_EXE_voronoi-fit"))
        .args(["study", "sphere", "--quick", "--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        &header[..7],
        &["method", "params", "hausdorff_lo", "hausdorff_hi", "chamfer", "train_seconds", "steps"]
    );
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let mut runs: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let method = f[0];
        runs.entry(method.to_string()).or_default().insert(f[col("seed")].to_string());
        let num = |c: &str| f[col(c)].parse::<f64>().unwrap();
        let (lo, hi, chamfer) = (num("hausdorff_lo"), num("hausdorff_hi"), num("chamfer"));
        assert!(lo.is_finite() && hi.is_finite() && chamfer.is_finite(), "{line}: every run has a surface");
        // The runs' intervals are certified to 1e-6·√3; the floor's search is cut short (a
        // valid interval, wider).
        let width = if method == "mc_floor" { 4.0 * lo } else { 1e-5 };
        assert!(0.0 <= lo && lo <= hi && hi - lo <= width, "{line}: interval");
        assert!(chamfer <= hi + 1e-12, "{line}: the Chamfer distance cannot exceed the Hausdorff distance");
        assert!(num("triangles") > 0.0 && num("total_seconds") >= 0.0);
        let convergence = f[col("convergence")];
        match method {
            "voronoi" => {
                assert_eq!(f[col("watertight")], "true", "{line}: every crust is watertight");
                // Whether the loss flattened, then which iterate the main job kept.
                let (flat, kept) = convergence.split_once("; ").unwrap_or((convergence, ""));
                assert!(["flattened", "not flattened"].contains(&flat) && kept.starts_with("kept "), "{line}");
                assert!(num("steps") >= 100.0 && num("params") > 0.0);
            }
            "occnet" | "deepsdf" => {
                assert!(["plateau", "capped"].contains(&convergence), "{line}");
                let steps = num("steps");
                assert!((100.0..=400.0).contains(&steps), "{line}: the quick plateau rule's bounds");
            }
            "construction" => assert_eq!(f[col("watertight")], "true", "{line}"),
            "mc_floor" => assert!(lo > 1e-4 && lo < 1e-3, "{line}: marching cubes of the exact distance at 48³"),
            other => panic!("unexpected method {other}"),
        }
    }
    let methods: Vec<&str> = runs.keys().map(String::as_str).collect();
    assert_eq!(methods, ["construction", "deepsdf", "mc_floor", "occnet", "voronoi"]);
    for m in ["voronoi", "occnet", "deepsdf"] {
        assert_eq!(runs[m].len(), 2, "{m}: two seeds in the quick study");
    }
    let summary = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let sh: Vec<&str> = summary.lines().next().unwrap().split(',').collect();
    let scol = |name: &str| sh.iter().position(|h| *h == name).unwrap();
    let mut groups = 0;
    for line in summary.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let x = |c: &str| f[scol(c)].parse::<f64>().unwrap();
        assert!(x("hausdorff_hi_min") <= x("hausdorff_hi_median") && x("hausdorff_hi_median") <= x("hausdorff_hi_max"));
        if ["voronoi", "occnet", "deepsdf"].contains(&f[0]) {
            assert_eq!(x("runs"), 2.0, "{line}");
        }
        groups += 1;
    }
    // 3 Voronoi sizes, 2 × 2 decoders, 3 constructions, 1 floor.
    assert_eq!(groups, 11);
    let svg = std::fs::read_to_string(out.join("hausdorff_vs_params.svg")).unwrap();
    assert!(svg.starts_with("<?xml") || svg.starts_with("<svg"));
    for name in ["Voronoi", "OccNet", "DeepSDF", "construction", "marching-cubes floor"] {
        assert!(svg.contains(name), "the plot names {name}");
    }
    let png = std::fs::read(out.join("hausdorff_vs_params.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let table = std::fs::read_to_string(out.join("table.md")).unwrap();
    assert!(table.contains("| voronoi |") && table.contains("Parameters needed") && table.contains("OccNet / Voronoi"));
    assert!(table.contains("Wall time of this run"));
    let budget: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("budget.json")).unwrap()).unwrap();
    assert!(budget["wall_seconds"].as_f64().unwrap() > 0.0);
    assert_eq!(budget["budget"]["seeds"].as_array().unwrap().len(), 2);
    // The crusts go to the glTF validator run by tests/run.sh.
    if let Some(v) = std::env::var_os("VF_GLB_OUT") {
        let dst = PathBuf::from(v).join("study");
        std::fs::create_dir_all(&dst).unwrap();
        for e in std::fs::read_dir(out.join("meshes")).unwrap() {
            let p = e.unwrap().path();
            std::fs::copy(&p, dst.join(p.file_name().unwrap())).unwrap();
        }
    }
}

#[test]
fn study_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    for bad in [&["--mlp-sizes", "0x3"][..], &["--mlp-sizes", "64"], &["--only", "mlp"], &["--sites", "1"]] {
        let o = Command::new(env!("CARGO_BIN_EXE_voronoi-fit"))
            .args(["study", "sphere", "--quick", "--quiet", "--out"])
            .arg(dir.path().join("s"))
            .args(bad)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2), "{bad:?}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(!dir.path().join("s").join("results.csv").exists());
    }
}

#[test]
fn a_partial_study_runs_only_what_was_asked() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s");
    let o = Command::new(env!("CARGO_BIN_EXE_voronoi-fit"))
        .args(["study", "sphere", "--quick", "--quiet", "--only", "deepsdf", "--mlp-sizes", "8x2", "--seeds", "3"])
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 1, "{csv}");
    assert!(rows[0].starts_with("deepsdf,113,"), "{}", rows[0]);
}
