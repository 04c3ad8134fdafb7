//! The flood solid on a dataset-style soup: a seat whose faces are doubled with opposite
//! orientations (its winding number is 0 everywhere), legs that are boxes open at both
//! ends (closed flat by the planar hole filling), and a single-sided backrest panel. The auto rule takes the flood solid, which keeps
//! every part on the input's surface; the winding-number solid, forced, loses the seat and
//! the panel (the test's control).

mod common;

use fit::{FitConfig, NoProgress, SolidRule};
use mesh_io::shapes::cuboid;
use mesh_io::TriMesh;
use occupancy::{MeshOracle, Workspace};

fn append(into: &mut TriMesh, part: &TriMesh) {
    let n = into.positions.len() as u32;
    into.positions.extend(&part.positions);
    into.triangles.extend(part.triangles.iter().map(|t| t.map(|v| v + n)));
}

/// The soup (1 × 1 × 1.2) and, per part, points on it: the seat, each leg, the panel.
fn chair() -> (TriMesh, Vec<(&'static str, [f64; 3])>) {
    let mut soup = TriMesh { positions: vec![], triangles: vec![] };
    let seat = cuboid([0.0, 0.0, 0.4], [1.0, 1.0, 0.5]);
    let mut flipped = seat.clone();
    flipped.triangles.iter_mut().for_each(|t| t.swap(1, 2));
    append(&mut soup, &seat);
    append(&mut soup, &flipped);
    let mut probes = vec![("seat top", [0.5, 0.5, 0.5]), ("seat side", [0.0, 0.5, 0.45])];
    for (i, (x, y)) in [(0.0, 0.0), (0.9, 0.0), (0.0, 0.9), (0.9, 0.9)].into_iter().enumerate() {
        let mut leg = cuboid([x, y, 0.0], [x + 0.1, y + 0.1, 0.4]);
        // Open at both ends: no triangle lying in z = 0 or z = 0.4.
        leg.triangles.retain(|t| {
            let z = t.map(|v| leg.positions[v as usize][2]);
            !(z[0] == z[1] && z[1] == z[2])
        });
        append(&mut soup, &leg);
        probes.push(
            [
                ("leg 0", [x, y + 0.05, 0.2]),
                ("leg 1", [x, y + 0.05, 0.2]),
                ("leg 2", [x, y + 0.05, 0.2]),
                ("leg 3", [x, y + 0.05, 0.2]),
            ][i],
        );
    }
    let panel = TriMesh {
        positions: vec![[0.0, 0.95, 0.5], [1.0, 0.95, 0.5], [1.0, 0.95, 1.2], [0.0, 0.95, 1.2]],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    append(&mut soup, &panel);
    probes.push(("panel", [0.5, 0.95, 0.85]));
    (soup, probes)
}

fn config(solid: SolidRule) -> FitConfig {
    let mut c = common::small("chair soup", 2048, 60, 200_000, 20_000);
    c.sampling.solid = solid;
    c
}

/// Distance from each probe to the crust, as a share of the soup's diagonal.
fn distances(crust: &TriMesh, probes: &[(&str, [f64; 3])]) -> Vec<f64> {
    let oracle = MeshOracle::from_mesh(crust, &occupancy::Config::default()).unwrap();
    let mut ws = Workspace::new();
    let diagonal = (1.0f64 + 1.0 + 1.44).sqrt();
    probes.iter().map(|(_, p)| oracle.closest_point(*p, &mut ws).squared_distance.sqrt() / diagonal).collect()
}

#[test]
fn the_flood_solid_keeps_every_part_of_a_soup() {
    let (soup, probes) = chair();
    let out = fit::fit(&soup, &config(SolidRule::Auto), &mut NoProgress).unwrap();
    let s = &out.report.solid;
    assert_eq!(s.rule, SolidRule::Flood, "{}", out.report.details());
    assert_eq!(s.chosen_by, "auto");
    let f = s.flood.as_ref().expect("the flood solid reports its grid");
    // The legs' open ends are planar holes (4 legs × 2 ends) and the panel's outline a
    // ninth loop, left open (a flat patch closes no volume). The legs' bottoms are closed
    // flat before the solid is built; a top lies in the plane of the seat's underside,
    // where the winding number is not that of a lid on the solid's boundary, and may stay
    // open (the flood fill closes it with the seat). The seat's doubled faces and the legs
    // bound the enclosed part; the panel is a sheet.
    let holes = s.holes_filled.as_ref().expect("an open input reports its hole filling");
    assert!(holes.loops_found == 9 && holes.open_shallow == 1 && holes.loops_filled >= 4, "{holes:?}");
    assert!(f.boundary_share > 0.6 && f.sheet_share > 0.05, "{f:?}");
    assert!(out.report.summary().contains("flood fill"), "{}", out.report.summary());
    // The sheets' band against the F-score's τ: at K = 2,048 it is wider, and the report
    // says about how many sites would bring it within τ (K scaled by (h/τ)²).
    let b = s.sheet_band.as_ref().expect("a flood solid with sheets reports its band");
    assert!(!b.within_tau && b.half_thickness_of_diagonal > b.tau_of_diagonal, "{b:?}");
    let k = b.sites_for_tau.unwrap() as f64;
    let expected = 2048.0 * (b.half_thickness_of_diagonal / b.tau_of_diagonal).powi(2);
    assert!((k - expected).abs() <= 1.0, "{b:?}");
    assert!(out.report.details().contains("would bring them within τ"), "{}", out.report.details());
    assert!(out.report.summary().lines().all(|l| l.chars().count() <= 100), "{}", out.report.summary());
    let c = &out.report.crust;
    assert!(c.is_closed && c.is_manifold, "{c:?}");
    // The solid guard ran on the flood solid, and where it added mirrors the crust stands
    // no farther outside the solid than before.
    let g = out.report.guard.as_ref().expect("carving is on, so is the guard");
    assert!(g.solid_beyond_before > 0.0 && g.solid_mirrors_dropped.is_none(), "{g:?}");
    assert!(g.solid_beyond_after <= g.solid_beyond_before, "{g:?}");
    let h = f.sheet_half_thickness_of_diagonal;
    let d = distances(&out.crust, &probes);
    for ((name, _), d) in probes.iter().zip(&d) {
        // On the boundary of an enclosed part the crust lies on the input; on a sheet, one
        // band's half-thickness off it — each up to the sites' resolution at K = 2,048.
        assert!(*d < h + 0.02, "{name}: {:.2}% of the diagonal from the crust (band ±{:.2}%)", 100.0 * d, 100.0 * h);
    }

    // The control: the winding number of doubled, opposite faces is 0, so the forced
    // winding-number solid has no seat and no panel.
    let winding = fit::fit(&soup, &config(SolidRule::Winding), &mut NoProgress);
    if let Ok(w) = winding {
        let d = distances(&w.crust, &probes);
        let lost: Vec<_> = probes.iter().zip(&d).filter(|(_, d)| **d >= h + 0.02).map(|((n, _), _)| *n).collect();
        assert!(lost.contains(&"panel") && lost.contains(&"seat top"), "the winding solid kept {lost:?} off");
    }
}

#[test]
fn a_closed_mesh_keeps_the_winding_solid_and_flood_can_be_forced() {
    let cube = cuboid([0.0; 3], [1.0; 3]);
    let out = fit::fit(&cube, &common::small("cube", 512, 20, 50_000, 20_000), &mut NoProgress).unwrap();
    assert_eq!(out.report.solid.rule, SolidRule::Winding);
    assert!(out.report.solid.flood.is_none());
    let mut c = common::small("cube", 512, 20, 50_000, 20_000);
    c.sampling.solid = SolidRule::Flood;
    let out = fit::fit(&cube, &c, &mut NoProgress).unwrap();
    assert_eq!(out.report.solid.rule, SolidRule::Flood);
    assert_eq!(out.report.solid.chosen_by, "--solid");
    let f = out.report.solid.flood.as_ref().unwrap();
    // A closed cube: all boundary, and the flood solid labels as the winding number does
    // (its enclosed cells stop a wall radius short of the faces).
    assert!(f.boundary_share > 0.97 && f.sheet_share < 0.01, "{f:?}");
    assert!(f.disagreement < 1e-3 && (0.0..0.03).contains(&(f.winding_share - f.enclosed_share)), "{f:?}");
    assert!(out.report.crust.is_closed);
}

#[test]
fn a_flood_grid_out_of_range_is_refused_before_any_work() {
    for n in [0, 15, 501, 100_000] {
        let o = fit::FitOptions { flood_cells: Some(n), ..Default::default() };
        let e = o.to_config("m").unwrap_err();
        assert!(e.is_input_fault() && e.to_string().contains("--flood-cells"), "{e}");
    }
    let o = fit::FitOptions { flood_cells: Some(64), ..Default::default() };
    assert_eq!(o.to_config("m").unwrap().sampling.flood_cells, 64);
}

/// A volume-filling soup like libigl's `cube_40k.obj`: a 6 × 6 × 6 grid of cubes, each with
/// its own 12 triangles (every inner face doubled), the grid's side at x = 1 left open.
/// Most of its surface lies inside the enclosed part, not on its boundary: auto takes the
/// flood solid for it all the same (`config::FLOOD_ENCLOSED_SHARE`).
#[test]
fn a_volume_filling_soup_takes_the_flood_solid() {
    let n = 6;
    let mut soup = TriMesh { positions: vec![], triangles: vec![] };
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let lo = [i, j, k].map(|c| c as f64 / n as f64);
                let mut cell = cuboid(lo, lo.map(|c| c + 1.0 / n as f64));
                cell.triangles.retain(|t| !t.iter().all(|&v| cell.positions[v as usize][0] == 1.0));
                append(&mut soup, &cell);
            }
        }
    }
    let mut c = common::small("grid of cubes", 512, 20, 50_000, 20_000);
    c.sampling.solid = SolidRule::Auto;
    let out = fit::fit(&soup, &c, &mut NoProgress).unwrap();
    let s = &out.report.solid;
    assert_eq!((s.rule, s.chosen_by), (SolidRule::Flood, "auto"), "{}", out.report.details());
    let f = s.flood.as_ref().unwrap();
    // The boundary alone is short of the rule's quarter; with the inner faces it is half.
    assert!(f.boundary_share < fit::config::FLOOD_BOUNDARY_SHARE, "{f:?}");
    assert!(f.boundary_share + f.interior_share >= fit::config::FLOOD_ENCLOSED_SHARE, "{f:?}");
    assert!(out.report.crust.is_closed && out.report.crust.is_manifold, "{:?}", out.report.crust);
    // The report's metrics tell the inner faces apart by the solid fitted (the raw soup's
    // winding number would take its exact fallback beside every open face): the same
    // share the flood solid left out of the training pool, on other samples.
    let fit::report::MetricsReport::Done(m) = &out.report.metrics else { panic!("metrics were asked for") };
    let b = &m.solid_boundary;
    assert!(b.interior_by.contains("flood solid"), "{b:?}");
    let left_out = f.interior_share + f.crevice_share;
    assert!(left_out > 0.3 && (b.interior_share - left_out).abs() < 0.03, "{b:?} against {f:?}");
}
