//! `voronoi-fit mnist`: the quick run end to end (train, eval, tsne, interpolate), a rerun
//! that resumes from the finished checkpoints, and bad data refused with exit 2 and no
//! output.

use std::path::{Path, PathBuf};

mod common;
use common::{bin, root};

fn shared_mnist() -> PathBuf {
    std::env::var_os("VF_SHARED_MNIST").map(PathBuf::from).unwrap_or_else(|| root().join("../shared/mnist"))
}

fn png_size(p: &Path) -> (u32, u32) {
    let bytes = std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "{}", p.display());
    (u32::from_be_bytes(bytes[16..20].try_into().unwrap()), u32::from_be_bytes(bytes[20..24].try_into().unwrap()))
}

#[test]
fn the_quick_run_makes_every_output_and_a_rerun_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mnist");
    let run = |extra: &[&str]| {
        let o = bin()
            .args(["mnist", "run", "--quick", "--quiet", "--data"])
            .arg(shared_mnist())
            .arg("--out")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}\n{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).to_string()
    };
    let summary = run(&[]);
    assert!(summary.contains("mnist run (quick)") && summary.contains("Voronoi 128"), "{summary}");
    for f in [
        "table.md",
        "results.json",
        "results.csv",
        "run.json",
        "curves.svg",
        "tsne_voronoi.svg",
        "tsne_voronoi.npz",
        "interpolation.svg",
        "reconstructions.svg",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    for f in ["curves.png", "tsne_voronoi.png", "interpolation.png", "reconstructions.png"] {
        let (w, h) = png_size(&out.join(f));
        assert!(w >= 400 && h >= 300, "{f}: {w}×{h}");
    }
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("results.json")).unwrap()).unwrap();
    let rows = results.as_array().unwrap();
    assert_eq!(rows.len(), 4);
    for r in rows {
        assert_eq!(r["images"], 1000);
        let m = r["mismatched_pixels"]["mean"].as_f64().unwrap();
        // Far from the full run after 64 steps: the small OccNets still draw an empty
        // digit (~97 mismatched pixels, the mean ink area), but nothing is worse than that
        // by much, and nothing near a full square (784).
        assert!(m > 0.0 && m < 150.0, "{r}");
    }
    let voronoi = rows.iter().find(|r| r["label"] == "Voronoi 128").unwrap();
    assert_eq!(voronoi["decoder_params"], 2_379_008);
    // The Voronoi decoder and the widest OccNet already draw shapes where the digits are.
    assert!(voronoi["iou"]["mean"].as_f64().unwrap() > 0.15, "{voronoi}");
    let wide = rows.iter().find(|r| r["label"] == "OccNet 16k").unwrap();
    assert!(wide["iou"]["mean"].as_f64().unwrap() > 0.1, "{wide}");
    let table = std::fs::read_to_string(out.join("table.md")).unwrap();
    assert!(table.contains("58.0 / 17.0 / 58.3"), "the seed's numbers beside ours: {table}");
    // The interpolation figure draws a crust (polylines) and cells (polygons).
    let svg = std::fs::read_to_string(out.join("interpolation.svg")).unwrap();
    assert!(svg.matches("<polygon").count() > 100 && svg.contains("stroke=\"#c01a1a\""));
    // A rerun finds every checkpoint finished: no training, the same table.
    let before = std::fs::read(out.join("voronoi/checkpoint.npz")).unwrap();
    run(&[]);
    assert_eq!(std::fs::read(out.join("voronoi/checkpoint.npz")).unwrap(), before);
    assert_eq!(std::fs::read_to_string(out.join("table.md")).unwrap(), table);
    // Other settings on the same folder are refused, naming the way out.
    let o = bin()
        .args(["mnist", "train", "--quick", "--quiet", "--epochs", "3", "--methods", "voronoi", "--data"])
        .arg(shared_mnist())
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--restart"));
}

#[test]
fn bad_data_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir_all(&data).unwrap();
    // A training set whose label file is short by one.
    let mut im = vec![0, 0, 8, 3];
    for d in [3u32, 28, 28] {
        im.extend_from_slice(&d.to_be_bytes());
    }
    im.extend(vec![0u8; 3 * 784]);
    std::fs::write(data.join("train-images-idx3-ubyte"), &im).unwrap();
    let mut lb = vec![0, 0, 8, 1];
    lb.extend_from_slice(&2u32.to_be_bytes());
    lb.extend([1, 2]);
    std::fs::write(data.join("train-labels-idx1-ubyte"), &lb).unwrap();
    let out = dir.path().join("out");
    let o = bin()
        .args(["mnist", "train", "--quick", "--quiet", "--data"])
        .arg(&data)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("3 images but 2 labels") && err.contains("train-labels-idx1-ubyte"), "{err}");
    assert!(!out.exists());
    // No data at all.
    let o = bin().args(["mnist", "eval", "--quiet", "--out"]).arg(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--data"));
    // A folder without the files.
    let o =
        bin().args(["mnist", "train", "--quiet", "--data"]).arg(dir.path()).arg("--out").arg(&out).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no training set found"));
    assert!(!out.exists());
}
