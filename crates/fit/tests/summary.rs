//! The summary after a fit fits on a screen: at most `SUMMARY_LINES` short lines (what was
//! fitted, the solid, quality in four numbers, validity, the files and the time), the
//! rest in `details()`.

mod common;

use fit::report::SUMMARY_LINES;
use fit::{FitReport, NoProgress, SolidRule};
use mesh_io::shapes::cuboid;
use mesh_io::TriMesh;

/// Longest summary line, in characters.
const WIDTH: usize = 100;

fn check(report: &FitReport) {
    let summary = report.summary();
    let lines: Vec<&str> = summary.lines().collect();
    assert!(!lines.is_empty() && lines.len() <= SUMMARY_LINES, "{} lines:\n{summary}", lines.len());
    for l in &lines {
        assert!(l.chars().count() <= WIDTH, "a line of {} characters:\n{summary}", l.chars().count());
    }
    assert!(lines[0].starts_with(&report.input.path), "{summary}");
    assert!(lines[0].contains(&format!("{} sites", report.settings.train.num_sites)), "{summary}");
    let details = report.details();
    assert!(details.len() > summary.len(), "details:\n{details}\nsummary:\n{summary}");
    assert!(details.contains("misclassified"), "{details}");
}

#[test]
fn a_closed_fit_summary_has_five_short_lines() {
    let out = fit::fit(&cuboid([0.0; 3], [1.0; 3]), &common::small("cube", 512, 20, 50_000, 20_000), &mut NoProgress)
        .unwrap();
    check(&out.report);
    let summary = out.report.summary();
    assert_eq!(summary.lines().count(), SUMMARY_LINES, "{summary}");
    for word in ["winding-number", "Hausdorff", "Chamfer", "F-score", "normal consistency", "closed", "manifold"] {
        assert!(summary.contains(word), "{word}: {summary}");
    }
    assert!(!summary.contains("NOT"), "{summary}");
}

#[test]
fn a_sheet_open_mesh_and_unmeasured_fit_keep_it_short() {
    // A flat sheet: a thin shell, said on the solid's line.
    let sheet = TriMesh {
        positions: vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    let out = fit::fit(&sheet, &common::small("sheet", 1024, 80, 60_000, 40_000), &mut NoProgress).unwrap();
    assert_eq!(out.report.solid.rule, SolidRule::Shell);
    check(&out.report);
    assert!(out.report.summary().contains("thin shell"), "{}", out.report.summary());

    // A bowl (a sphere with a hole): the winding solid with a cap.
    let bowl = common::bowl(3);
    let mut c = common::small("a/rather/long/path/to/the/bowl.obj", 1024, 20, 60_000, 20_000);
    c.skip_metrics = true;
    let out = fit::fit(&bowl, &c, &mut NoProgress).unwrap();
    check(&out.report);
    assert!(out.report.summary().contains("capped"), "{}", out.report.summary());
}
