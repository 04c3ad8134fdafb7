//! Site insertion where the crust strays (`fit::carve`): a gap in the outside sites over a
//! sphere's pole lets the inside cells poke out as a spike; pairs inserted at the spike's
//! feet cut it back, and the crust stays valid. On the whole job it is opt-in (`--carve`).

use fit::carve::{carve, CarveOptions};
use mesh_io::shapes::icosphere;
use mesh_io::{TriMesh, UnitCubeTransform};
use occupancy::MeshOracle;
use soft_voronoi::{MeshSolid, Solid};

/// Mirrored pairs c + (r ± δ)·n at `n` Fibonacci directions, without the outside sites
/// whose direction has z above `gap` (the spike's gap), plus the fixed boundary sites.
fn pairs_with_a_gap(center: [f64; 3], r: f64, n: usize, gap: f64) -> (Vec<[f64; 3]>, Vec<bool>) {
    let delta = 0.5 * r * (4.0 * std::f64::consts::PI / n as f64).sqrt();
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let (mut sites, mut labels) = (Vec::new(), Vec::new());
    for i in 0..n {
        let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let (s, a) = ((1.0 - z * z).sqrt(), golden * i as f64);
        let d = [s * a.cos(), s * a.sin(), z];
        for (rr, inside) in [(r - delta, true), (r + delta, false)] {
            if !inside && z > gap {
                continue;
            }
            sites.push([0, 1, 2].map(|c| center[c] + rr * d[c]));
            labels.push(inside);
        }
    }
    for b in soft_voronoi::init::boundary_sites(96) {
        sites.push(b);
        labels.push(false);
    }
    (sites, labels)
}

fn farthest(sites: &[[f64; 3]], labels: &[bool], oracle: &MeshOracle) -> f64 {
    let crust = crust::Crust::extract(sites, labels, &crust::CrustConfig::default()).unwrap();
    oracle.closest_points(&crust.mesh.positions).unwrap().iter().map(|c| c.squared_distance.sqrt()).fold(0.0, f64::max)
}

#[test]
fn pairs_at_the_feet_cut_a_spike_back() {
    let sphere = icosphere(5);
    let t = UnitCubeTransform::of_mesh(&sphere, 0.05).unwrap();
    let unit: TriMesh = t.mesh_to_unit(&sphere);
    let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default()).unwrap();
    let solid = MeshSolid { oracle: &oracle };
    let r = 0.45;
    let (mut sites, mut labels) = pairs_with_a_gap([0.5; 3], r, 2000, 0.995);
    let before = farthest(&sites, &labels, &oracle);
    assert!(before > 0.02, "the gap makes a spike: {before}");
    let tolerance = 0.004;
    let n0 = sites.len();
    let options = CarveOptions { tolerance, rounds: 4, max_new: 400, mirrors: true, peels: false, gate: None };
    let (start_sites, start_labels) = (sites.clone(), labels.clone());
    let report = carve(&mut sites, &mut labels, &oracle, &unit, &solid, &options).unwrap();
    // The gate: an uncarved crust short of the bar (here, of an unreachable normal
    // consistency) stops carving before its first round; one that reaches it carves as
    // without a gate.
    assert!(!report.gated);
    let first = report.first_surface;
    assert!(first.chamfer_l1 > 0.0 && first.normal_consistency > 0.9 && first.normal_consistency < 1.0, "{first:?}");
    for (bar, gated) in [
        (fit::carve::SurfaceBar { normal_consistency: first.normal_consistency + 1e-6, ..first }, true),
        (fit::carve::SurfaceBar { chamfer_l1: first.chamfer_l1 * 0.999, ..first }, true),
        (first, false),
    ] {
        let (mut s, mut l) = (start_sites.clone(), start_labels.clone());
        let r = carve(&mut s, &mut l, &oracle, &unit, &solid, &CarveOptions { gate: Some(bar), ..options }).unwrap();
        assert_eq!(r.gated, gated, "{bar:?}");
        if gated {
            assert!(r.inserted_per_round.is_empty() && s.len() == n0, "{r:?}");
        } else {
            assert_eq!((s, l), (sites.clone(), labels.clone()));
        }
    }
    // Started from the crust of the same sites extracted already (the fit's box guard
    // hands over its last one), carving does the same; a crust of other sites is not used.
    let extracted = crust::Crust::extract(&start_sites, &start_labels, &crust::CrustConfig::default()).unwrap();
    let fewer = crust::Crust::extract(&start_sites[1..], &start_labels[1..], &crust::CrustConfig::default()).unwrap();
    for given in [extracted, fewer] {
        let (mut s, mut l) = (start_sites.clone(), start_labels.clone());
        let start = fit::carve::Start { crust: Some(given), first_surface: &|_| None };
        let r = fit::carve::carve_with(&mut s, &mut l, &oracle, &unit, &solid, &options, start).unwrap();
        assert_eq!((s, l), (sites.clone(), labels.clone()));
        assert_eq!(r.farthest_per_round, report.farthest_per_round);
        assert_eq!(r.first_surface, report.first_surface);
    }
    let inserted: usize = report.inserted_per_round.iter().sum();
    assert_eq!(sites.len(), n0 + inserted);
    assert!(inserted > 0, "{report:?}");
    // The first round's pairs stand at the spike's feet, not at input samples.
    assert_eq!(report.inserted_at_input_per_round.len(), report.inserted_per_round.len());
    assert_eq!(report.inserted_at_input_per_round[0], 0, "{report:?}");
    assert!((report.farthest_before - before).abs() < 1e-12);
    assert!(report.farthest_after < 0.5 * before, "{report:?}");
    assert!((farthest(&sites, &labels, &oracle) - report.farthest_after).abs() < 1e-12);
    // The pairs are labelled by the solid (on a smooth sphere: one inside, one outside).
    let new_labels = &labels[n0..];
    assert_eq!(solid.inside(&sites[n0..]), new_labels);
    // The first round's pairs (its first sites, before any mirror images and peel sites at
    // the crust's vertices) straddle the surface.
    // Peel sites were not asked for.
    assert!(report.inserted_as_peels_per_round.iter().all(|&p| p == 0), "{report:?}");
    let first_pairs =
        report.inserted_per_round[0] - report.inserted_as_mirrors_per_round[0] - report.inserted_as_peels_per_round[0];
    assert!(first_pairs > 0 && first_pairs.is_multiple_of(2), "{report:?}");
    assert!(new_labels[..first_pairs].chunks(2).all(|p| p[0] != p[1]), "{new_labels:?}");
    assert!(report.farthest_after <= report.farthest_before);
    // One farthest distance per extraction on each side; the kept state's two-sided one
    // (the Hausdorff distance) is within 1% of the least and no larger than before carving;
    // no more than PATIENCE rounds ran after the last one that beat the best.
    let per = &report.farthest_per_round;
    let input = &report.input_farthest_per_round;
    assert_eq!(per.len(), input.len());
    assert_eq!(per[0], report.farthest_before);
    assert_eq!(per.len(), report.inserted_per_round.len() + report.undone_rounds + 1, "{report:?}");
    let kept = report.inserted_per_round.len();
    assert_eq!(per[kept], report.farthest_after);
    let fscore = &report.fscore_per_round;
    assert_eq!(fscore.len(), per.len());
    assert!(fscore[kept] >= fscore[0] - 0.002, "{report:?}");
    let two_sided: Vec<f64> = per.iter().zip(input).map(|(a, b)| a.max(*b)).collect();
    let least =
        (0..per.len()).filter(|&i| fscore[i] >= fscore[0] - 0.002).map(|i| two_sided[i]).fold(f64::INFINITY, f64::min);
    assert!(two_sided[kept] <= least * 1.01 && two_sided[kept] <= two_sided[0], "{report:?}");
    // Carving cuts the spike and leaves no dent: the input's side is not farther than before.
    assert!(input[kept] <= input[0] * 1.01 + 1e-4, "{report:?}");
    let last_best = (0..per.len()).filter(|&i| two_sided[..i].iter().all(|&x| two_sided[i] < x)).max().unwrap();
    assert!(per.len() - 1 - last_best <= fit::carve::PATIENCE, "{report:?}");
}

/// A pair at a foot near a convex edge: the site that would sit by the other face (nearer
/// the input than half the offset) is left out, the other kept; a foot in the middle of a
/// face, or on the edge with the pair along the bisecting direction, keeps both.
#[test]
fn sites_that_would_stand_by_another_face_are_left_out() {
    let unit = mesh_io::shapes::cuboid([0.3; 3], [0.7; 3]);
    let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default()).unwrap();
    let t = 0.004;
    let pair = |c: [f64; 3], n: [f64; 3]| [1.0, -1.0].map(|s| [0, 1, 2].map(|i| c[i] + s * t * n[i])).to_vec();
    // On the top face, 0.3 t from the edge x = 0.7, the pair along the face's normal: the
    // inside site would be 0.3 t from the side face x = 0.7 (featuretype's counterbore).
    let near_edge = pair([0.7 - 0.3 * t, 0.5, 0.7], [0.0, 0.0, 1.0]);
    assert_eq!(fit::carve::clear_of_the_input(&oracle, near_edge.clone(), t).unwrap(), vec![near_edge[0]]);
    let middle = pair([0.5, 0.5, 0.7], [0.0, 0.0, 1.0]);
    assert_eq!(fit::carve::clear_of_the_input(&oracle, middle.clone(), t).unwrap(), middle);
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let on_edge = pair([0.7, 0.5, 0.7], [h, 0.0, h]);
    assert_eq!(fit::carve::clear_of_the_input(&oracle, on_edge.clone(), t).unwrap(), on_edge);
}

#[test]
fn the_guard_cuts_a_spike_at_the_bounding_box() {
    // The same gap: the spike runs up out of the sphere's bounding box to the unit cube's
    // boundary sites. Mirrors of the inside sites across the box's top end it there, and
    // the crust below the top is what it was (the guard never changes the box's inside).
    let sphere = icosphere(5);
    let t = UnitCubeTransform::of_mesh(&sphere, 0.05).unwrap();
    let unit: TriMesh = t.mesh_to_unit(&sphere);
    let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default()).unwrap();
    let (mut sites, mut labels) = pairs_with_a_gap([0.5; 3], 0.45, 2000, 0.995);
    let (lo, hi) = unit.bounding_box();
    let top = |s: &[[f64; 3]], l: &[bool]| {
        let c = crust::Crust::extract(s, l, &crust::CrustConfig::default()).unwrap();
        c.mesh.positions.iter().fold(0.0f64, |m, p| m.max(p[2]))
    };
    let before = top(&sites, &labels);
    assert!(before > hi[2] + 0.02, "the spike leaves the box: {before} against {}", hi[2]);
    let n0 = sites.len();
    let r = fit::guard::guard(&mut sites, &mut labels, lo, hi, 0.004).unwrap();
    assert!(r.inserted_per_round.iter().sum::<usize>() > 0 && r.skipped_outside_cube == 0, "{r:?}");
    assert!(r.beyond_after <= 0.004 && r.beyond_before > 0.02, "{r:?}");
    assert!(top(&sites, &labels) <= hi[2] + 0.004);
    assert!(labels[n0..].iter().all(|&l| !l) && sites[n0..].iter().all(|p| p[2] > hi[2]));
    assert!(farthest(&sites, &labels, &oracle) < 0.5 * (before - hi[2]) + 0.004);
}

/// The other side: a small box beside the sphere that no site stands near. No crust vertex
/// is far from the input, but the box's samples are far from the crust; the pairs inserted
/// at them along the box's normals give it a solid of its own.
#[test]
fn pairs_at_input_far_from_the_crust_bring_a_lost_part_back() {
    let sphere = icosphere(5);
    let (c, r) = ([0.4, 0.5, 0.5], 0.25);
    let mut unit = TriMesh {
        positions: sphere.positions.iter().map(|p| [0, 1, 2].map(|k| c[k] + r * p[k])).collect(),
        triangles: sphere.triangles.clone(),
    };
    let small = mesh_io::shapes::cuboid([0.74, 0.46, 0.46], [0.82, 0.54, 0.54]);
    let n = unit.positions.len() as u32;
    unit.positions.extend(&small.positions);
    unit.triangles.extend(small.triangles.iter().map(|t| t.map(|v| v + n)));
    let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default()).unwrap();
    let solid = MeshSolid { oracle: &oracle };
    // The sphere's pairs (the icosphere's vertices lie on it), none at the box.
    let (mut sites, mut labels) = pairs_with_a_gap(c, r, 3000, 2.0);
    let before = crust::Crust::extract(&sites, &labels, &crust::CrustConfig::default()).unwrap();
    assert_eq!(mesh_io::topology::TopologyReport::of(&before.mesh).num_components, 1);
    let tolerance = 0.004;
    // The budget covers two rounds over the box: its first round's pairs (turned to bisect
    // the box's edges, not left out there) and their mirrors take 600 sites.
    let options = CarveOptions { tolerance, rounds: 4, max_new: 900, mirrors: true, peels: true, gate: None };
    let report = carve(&mut sites, &mut labels, &oracle, &unit, &solid, &options).unwrap();
    let input = &report.input_farthest_per_round;
    let kept = report.inserted_per_round.len();
    // Before: the box's far corner is 0.12 and more from the sphere's crust.
    assert!(input[0] > 0.1, "{report:?}");
    assert!(kept > 0, "{report:?}");
    assert!(input[kept] < 0.25 * input[0], "{report:?}");
    // The first round's pairs all stand at the box's samples (no crust vertex was far), and
    // the rest are their mirror images across the box's faces near them.
    assert_eq!(
        report.inserted_at_input_per_round[0] + report.inserted_as_mirrors_per_round[0],
        report.inserted_per_round[0],
        "{report:?}"
    );
    // The box's crust stays within a few tolerances of it (its edges are cut by pairs
    // 2·tolerance apart), the F-score rises, and the box is a second body.
    assert!(report.farthest_after < 3.0 * tolerance, "{report:?}");
    let f = &report.fscore_per_round;
    assert!(f[kept] > f[0], "{report:?}");
    let after = crust::Crust::extract(&sites, &labels, &crust::CrustConfig::default()).unwrap();
    assert_eq!(mesh_io::topology::TopologyReport::of(&after.mesh).num_components, 2);
    assert!(after.mesh.positions.iter().any(|p| p[0] > 0.78), "the box's side at x = 0.82 has crust");
}
