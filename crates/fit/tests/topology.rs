//! The report's topology check: the crust's genus against the input's, where the input's is
//! the solid's (a clean closed input fitted as its winding solid), and the summary's word
//! where they differ.

mod common;

use fit::NoProgress;
use mesh_io::shapes::{cuboid, torus};
use mesh_io::TriMesh;

/// Two disjoint meshes as one.
fn both(a: &TriMesh, b: &TriMesh) -> TriMesh {
    let n = a.positions.len() as u32;
    let mut m = a.clone();
    m.positions.extend_from_slice(&b.positions);
    m.triangles.extend(b.triangles.iter().map(|t| t.map(|v| v + n)));
    m
}

/// A torus with a wide hole keeps its handle: the check is made and says so.
#[test]
fn a_wide_torus_keeps_its_handle() {
    let out = fit::fit(&torus(1.0, 0.35, 48, 24), &common::small("torus", 1024, 20, 60_000, 20_000), &mut NoProgress)
        .unwrap();
    let r = &out.report;
    assert_eq!(r.input.genus, Some(1));
    let t = r.topology.as_ref().expect("a clean closed input is checked");
    assert_eq!((t.input_genus, t.crust_genus, t.handles_closed, t.handles_added), (1, 1, 0, 0), "{t:?}");
    assert!(t.kept());
    assert!(!r.summary().contains("input genus"), "{}", r.summary());
    assert!(!r.details().contains("topology differs"), "{}", r.details());
}

/// A torus whose hole is far narrower than the sites' spacing at K = 256 loses its handle
/// (the hole is 0.1% of the torus's width across): the report counts the closed handle and the
/// summary and details say it.
#[test]
fn a_handle_narrower_than_the_sites_is_counted_as_closed() {
    // Beside it, a cube far away: two components, both kept.
    let m = both(&torus(1.0, 0.998, 64, 48), &cuboid([3.0, -0.5, -0.5], [4.0, 0.5, 0.5]));
    let out = fit::fit(&m, &common::small("narrow torus", 256, 20, 60_000, 20_000), &mut NoProgress).unwrap();
    let r = &out.report;
    assert_eq!(r.input.genus, Some(1));
    let t = r.topology.as_ref().expect("a clean closed input is checked");
    assert_eq!((t.input_genus, t.crust_genus, t.handles_closed), (1, 0, 1), "{t:?}");
    assert_eq!((t.input_components, t.crust_components), (2, 2), "{t:?}");
    assert!(!t.kept());
    let summary = r.summary();
    assert!(summary.lines().nth(1).unwrap().contains("input genus 1"), "{summary}");
    assert!(summary.lines().all(|l| l.chars().count() <= 100), "{summary}");
    assert!(r.details().contains("closed 1 of the input's 1 handles"), "{}", r.details());
}

/// Overlapping closed bodies: their genera do not add up to the solid's, so no check.
#[test]
fn overlapping_bodies_are_not_checked() {
    let m = both(&cuboid([0.0; 3], [1.0; 3]), &cuboid([0.5; 3], [1.5; 3]));
    let mut c = common::small("overlap", 512, 20, 50_000, 20_000);
    c.skip_metrics = true;
    let out = fit::fit(&m, &c, &mut NoProgress).unwrap();
    assert_eq!(out.report.input.genus, Some(0));
    assert!(out.report.topology.is_none(), "{:?}", out.report.topology);
}

/// `keep_topology` grows K until the handle is kept: a torus whose hole (1.5% of its width
/// across) closes at K = 256 keeps it at a larger K, and the trace says at which.
#[test]
fn keep_topology_grows_the_sites_until_the_handle_is_kept() {
    let m = torus(1.0, 0.985, 64, 48);
    let c = common::small("torus", 256, 20, 60_000, 20_000);
    let first = fit::fit(&m, &c, &mut NoProgress).unwrap();
    assert_eq!(first.report.topology.as_ref().map(|t| t.handles_closed), Some(1), "closed at K = 256");
    let goal = fit::AccuracyGoal { hausdorff_of_diagonal: None, keep_topology: true, max_sites: 4096 };
    let out = fit::fit_to_accuracy(&m, &c, &goal, &mut NoProgress).unwrap();
    let a = out.report.accuracy_target.as_ref().expect("the trace");
    assert!(a.met, "{:?}", a.trace);
    let last = a.trace.last().unwrap();
    assert!(last.sites > 256 && last.genus == Some(1) && last.handles_closed == Some(0), "{:?}", a.trace);
    assert!(a.trace[..a.trace.len() - 1].iter().all(|r| r.handles_closed == Some(1)), "{:?}", a.trace);
    assert_eq!((a.sites_used, out.report.crust.genus), (last.sites, Some(1)));
    assert!(out.report.details().contains("the input's topology met with"), "{}", out.report.details());
}
