//! Asking for an accuracy instead of a K: the fit doubles K, refining where the previous
//! crust missed, until the certified Hausdorff meets the goal or the budget is spent; the
//! report carries the K used and the error-against-K trace.

mod common;

use fit::{fit_to_accuracy, AccuracyGoal, FitConfig, NoProgress};
use mesh_io::shapes::icosphere;

/// The certified Hausdorff distance of `out`'s crust to `mesh`, upper end, share of the
/// diagonal.
fn hausdorff_of(out: &fit::FitOutput, mesh: &mesh_io::TriMesh) -> f64 {
    match &out.report.metrics {
        fit::report::MetricsReport::Done(m) => m.hausdorff.hi / mesh.diagonal(),
        other => panic!("{other:?}"),
    }
}

/// The trace's row with the least Hausdorff distance.
fn closest(trace: &[fit::grow::GrowthRow]) -> &fit::grow::GrowthRow {
    trace.iter().min_by(|x, y| x.hausdorff_hi_of_diagonal.total_cmp(&y.hausdorff_hi_of_diagonal)).unwrap()
}

fn small(k: usize) -> FitConfig {
    common::small("sphere", k, 60, 60_000, 20_000)
}

#[test]
fn grows_until_the_goal_is_met_and_reports_the_trace() {
    let sphere = icosphere(3);
    // A goal the first round misses (128 sites on a sphere: a few % of the diagonal).
    let first = fit::fit(&sphere, &small(128), &mut NoProgress).unwrap();
    let h0 = hausdorff_of(&first, &sphere);
    let goal = AccuracyGoal { hausdorff_of_diagonal: Some(0.5 * h0), keep_topology: false, max_sites: 2048 };
    let out = fit_to_accuracy(&sphere, &small(128), &goal, &mut NoProgress).unwrap();
    let a = out.report.accuracy_target.as_ref().expect("the trace");
    let sites: Vec<usize> = a.trace.iter().map(|r| r.sites).collect();
    assert!(sites.len() >= 2, "the first round cannot meet half its own error: {sites:?}");
    assert!(sites.windows(2).all(|w| w[1] == 2 * w[0]), "{sites:?}");
    assert!((a.trace[0].hausdorff_hi_of_diagonal - h0).abs() < 1e-12, "the same first fit (seeded)");
    assert!(
        a.trace[1..].iter().all(|r| r.refined_share > 0.0),
        "later rounds refine where the error was: {:?}",
        a.trace
    );
    let last = a.trace.last().unwrap();
    // The fit returned: the round that met the goal, else the closest one.
    let kept = if a.met { last } else { closest(&a.trace) };
    assert_eq!(a.sites_used, kept.sites);
    assert_eq!(out.report.settings.train.num_sites, kept.sites);
    assert_eq!(hausdorff_of(&out, &sphere), kept.hausdorff_hi_of_diagonal);
    assert_eq!(a.met, last.hausdorff_hi_of_diagonal <= goal.hausdorff_of_diagonal.unwrap());
    assert!(a.met || last.sites * 2 > goal.max_sites, "stopped early without meeting the goal");
    assert!(out.report.crust.is_closed && out.report.crust.is_manifold);
    assert!(out.report.details().contains("Accuracy target"));
    let json = serde_json::to_value(&out.report).unwrap();
    assert!(json["accuracy_target"]["trace"].as_array().unwrap().len() == a.trace.len());
}

#[test]
fn an_unreachable_goal_returns_the_closest_fit() {
    let sphere = icosphere(3);
    let goal = AccuracyGoal { hausdorff_of_diagonal: Some(1e-6), keep_topology: false, max_sites: 512 };
    let out = fit_to_accuracy(&sphere, &small(128), &goal, &mut NoProgress).unwrap();
    let a = out.report.accuracy_target.as_ref().expect("the trace");
    assert!(!a.met);
    assert_eq!(a.trace.iter().map(|r| r.sites).collect::<Vec<_>>(), vec![128, 256, 512]);
    let kept = closest(&a.trace);
    assert_eq!(a.sites_used, kept.sites);
    assert_eq!(out.report.settings.train.num_sites, kept.sites);
    assert_eq!(hausdorff_of(&out, &sphere), kept.hausdorff_hi_of_diagonal);
    assert!(out.report.details().contains("NOT met; the fit written is the closest one"));
}

#[test]
fn an_easy_goal_stops_at_the_first_round_and_bad_goals_are_refused() {
    let sphere = icosphere(2);
    let goal = AccuracyGoal { hausdorff_of_diagonal: Some(0.5), keep_topology: false, max_sites: 1024 };
    let out = fit_to_accuracy(&sphere, &small(128), &goal, &mut NoProgress).unwrap();
    let a = out.report.accuracy_target.unwrap();
    assert!(a.met && a.trace.len() == 1 && a.sites_used == 128);
    for goal in [
        AccuracyGoal { hausdorff_of_diagonal: Some(0.0), keep_topology: false, max_sites: 1024 },
        AccuracyGoal { hausdorff_of_diagonal: Some(f64::NAN), keep_topology: false, max_sites: 1024 },
        AccuracyGoal { hausdorff_of_diagonal: Some(0.01), keep_topology: false, max_sites: 64 },
        AccuracyGoal { hausdorff_of_diagonal: None, keep_topology: false, max_sites: 1024 },
    ] {
        assert!(fit_to_accuracy(&sphere, &small(128), &goal, &mut NoProgress).is_err_and(|e| e.is_input_fault()));
    }
}
