//! Faces inside the solid (closed bodies that overlap, as CAD exports and scans of
//! assemblies often are) are not on the crust: their surface samples are left out of the
//! initialisation, the surface term and the polish, and the report says how much of the
//! surface that was.

mod common;

use fit::{FitConfig, NoProgress};
use mesh_io::shapes::cuboid;
use mesh_io::TriMesh;

fn concat(a: &TriMesh, b: &TriMesh) -> TriMesh {
    let n = a.positions.len() as u32;
    TriMesh {
        positions: a.positions.iter().chain(&b.positions).copied().collect(),
        triangles: a.triangles.iter().copied().chain(b.triangles.iter().map(|t| t.map(|v| v + n))).collect(),
    }
}

const SAMPLES: usize = 50_000;

fn small(name: &str) -> FitConfig {
    common::small(name, 512, 20, SAMPLES, 20_000)
}

#[test]
fn faces_inside_overlapping_bodies_are_left_out() {
    // A unit cube and a bar through its +x face: inside the union lie the cube's face
    // x = 1 where the bar crosses it (0.25), the bar's end x = 0.5 (0.25) and the bar's
    // four sides over 0.5 ≤ x ≤ 1 (4 × 0.25): 1.5 of the 8.5 of area.
    let union = concat(&cuboid([0.0; 3], [1.0; 3]), &cuboid([0.5, 0.25, 0.25], [1.5, 0.75, 0.75]));
    let out = fit::fit(&union, &small("union"), &mut NoProgress).unwrap();
    let s = &out.report.solid;
    let share = s.interior_surface_share.expect("the winding solid reports the share");
    assert!((share - 1.5 / 8.5).abs() < 0.01, "interior share {share}, expected {}", 1.5 / 8.5);
    let dropped = s.interior_surface_samples_dropped as f64;
    assert!((dropped / SAMPLES as f64 - share).abs() < 1e-9, "{dropped} samples dropped for a share of {share}");
    assert!(out.report.details().contains("not on the solid's boundary"), "{}", out.report.details());
    assert!(out.report.crust.is_closed && out.report.crust.num_components == 1, "{:?}", out.report.crust);

    // One cube alone: every sample is on the boundary, nothing is dropped, nothing is said.
    let cube = fit::fit(&cuboid([0.0; 3], [1.0; 3]), &small("cube"), &mut NoProgress).unwrap();
    assert_eq!(cube.report.solid.interior_surface_share, Some(0.0));
    assert_eq!(cube.report.solid.interior_surface_samples_dropped, 0);
    assert!(!cube.report.details().contains("not on the solid's boundary"));

    // A thin pin through the face: 0.06 of 6.14 (1%) inside, below the 5% at which the
    // pool is filtered: reported, nothing dropped.
    let pin = concat(&cuboid([0.0; 3], [1.0; 3]), &cuboid([0.9, 0.45, 0.45], [1.2, 0.55, 0.55]));
    let out = fit::fit(&pin, &small("pin"), &mut NoProgress).unwrap();
    let share = out.report.solid.interior_surface_share.unwrap();
    assert!((share - 0.06 / 6.14).abs() < 0.004, "interior share {share}, expected {}", 0.06 / 6.14);
    assert_eq!(out.report.solid.interior_surface_samples_dropped, 0);
}
