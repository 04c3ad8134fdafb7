//! `voronoi-fit study sphere --quick`: the files are produced, the values finite, every
//! Voronoi crust watertight, the plot a real SVG and PNG.

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
    let mut methods = std::collections::BTreeSet::new();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        methods.insert(f[0].to_string());
        let num = |c: &str| f[col(c)].parse::<f64>().unwrap();
        let (lo, hi, chamfer) = (num("hausdorff_lo"), num("hausdorff_hi"), num("chamfer"));
        assert!(lo.is_finite() && hi.is_finite() && chamfer.is_finite(), "{line}");
        assert!(0.0 <= lo && lo <= hi && hi - lo <= 1e-5, "{line}: interval");
        assert!(chamfer <= hi + 1e-12, "{line}: the Chamfer distance cannot exceed the Hausdorff distance");
        assert!(num("params") > 0.0 && num("train_seconds") >= 0.0 && num("steps") > 0.0);
        if f[0] == "voronoi" {
            assert_eq!(f[col("watertight")], "true", "{line}: every crust is watertight");
        }
    }
    assert_eq!(methods.into_iter().collect::<Vec<_>>(), ["deepsdf", "occnet", "voronoi"]);
    let svg = std::fs::read_to_string(out.join("hausdorff_vs_params.svg")).unwrap();
    assert!(svg.starts_with("<?xml") || svg.starts_with("<svg"));
    assert!(svg.contains("Voronoi") && svg.contains("OccNet") && svg.contains("DeepSDF"));
    let png = std::fs::read(out.join("hausdorff_vs_params.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let table = std::fs::read_to_string(out.join("table.md")).unwrap();
    assert!(table.contains("| voronoi |") && table.contains("Parameters needed"));
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
