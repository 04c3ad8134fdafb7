//! Thin parts: where a part is thinner than the mirrored pairs would be wide, the pairs
//! become columns (inside at the middle, outside at its mirror images across both faces),
//! so a thin plate's faces come out flat at initialisation, whatever the spacing.

use fit::{FitConfig, NoProgress};
use mesh_io::TriMesh;

/// An axis-aligned box [0, a] × [0, b] × [0, c], outward-facing.
fn cuboid(a: f64, b: f64, c: f64) -> TriMesh {
    let positions =
        (0..8).map(|i| [a * (i & 1) as f64, b * ((i >> 1) & 1) as f64, c * ((i >> 2) & 1) as f64]).collect();
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|q: &[u32; 4]| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
    TriMesh { positions, triangles }
}

#[test]
fn a_thin_plate_starts_with_flat_faces() {
    let t = 0.02;
    let plate = cuboid(1.0, 1.0, t);
    let mut c = FitConfig::new("plate", 2048);
    c.train.steps = 0;
    c.carve = None;
    c.polish = None;
    c.sampling.samples = 100_000;
    c.eval.samples = 50_000;
    let out = fit::fit(&plate, &c, &mut NoProgress).unwrap();
    assert_eq!(out.report.solid.rule, fit::SolidRule::Winding);
    assert!(out.report.crust.is_closed && out.report.crust.num_components == 1, "{:?}", out.report.crust);
    // Away from the rim, every crust vertex lies on one of the two faces.
    let mut inner = 0;
    for p in &out.crust.positions {
        if (0.2..0.8).contains(&p[0]) && (0.2..0.8).contains(&p[1]) {
            inner += 1;
            let off = p[2].abs().min((p[2] - t).abs());
            assert!(off < 0.05 * t, "crust vertex {p:?} is {off} off the plate's faces (thickness {t})");
        }
    }
    assert!(inner > 100, "{inner} crust vertices in the plate's middle");
    // Untrained; the rim (the plate's narrow sides) is where the rest of the error is.
    assert!(out.report.quality.misclassification < 0.03, "{}", out.report.quality.misclassification);
}
