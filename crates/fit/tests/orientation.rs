//! Triangles flipped against the rest of their body are turned back before the solid is
//! built: the winding number of an inconsistently oriented box is not 1 inside it, and
//! the fit would reproduce the wrong solid (a wedge out of one face on the benchmark's
//! multibody, Hausdorff 12.7% of the diagonal).

mod common;

use fit::{FitConfig, NoProgress};
use mesh_io::shapes::cuboid;
use mesh_io::TriMesh;

fn small(name: &str) -> FitConfig {
    common::small(name, 512, 20, 50_000, 20_000)
}

#[test]
fn a_box_with_flipped_triangles_is_fitted_as_the_box() {
    let good = cuboid([0.0; 3], [1.0, 0.6, 0.4]);
    // Half of one face's triangles and one of another's reversed.
    let bad = TriMesh {
        positions: good.positions.clone(),
        triangles: good
            .triangles
            .iter()
            .enumerate()
            .map(|(i, t)| if [0, 5, 6].contains(&i) { [t[0], t[2], t[1]] } else { *t })
            .collect(),
    };
    assert!(!mesh_io::TopologyReport::of(&bad).is_orientation_consistent);
    // The bad box's own winding number is ±1/3-ish over much of the box: its labels
    // disagree with the box's on a large share of the training pool.
    let oracle = occupancy::MeshOracle::from_mesh(&bad, &occupancy::Config::default()).unwrap();
    let probes: Vec<[f64; 3]> = (0..1000).map(|i| [0.1 + 0.0008 * i as f64, 0.3, 0.2]).collect();
    assert!(oracle.inside(&probes).unwrap().iter().any(|&b| !b), "the flipped box must read partly outside");

    let fixed = fit::fit(&bad, &small("flipped"), &mut NoProgress).unwrap();
    let r = &fixed.report.input.reoriented;
    assert_eq!((r.flipped_triangles, r.pieces_changed, r.non_orientable_pieces), (3, 1, 0), "{r:?}");
    assert!(fixed.report.details().contains("turned around"), "{}", fixed.report.details());
    // The same fit as of the consistent box: the solid and the samples are the same.
    let want = fit::fit(&good, &small("good"), &mut NoProgress).unwrap();
    assert_eq!(fixed.sites, want.sites);
    assert_eq!(want.report.input.reoriented, mesh_io::Reorientation::default());
    assert!(!want.report.details().contains("turned around"));
    assert!(want.report.quality.misclassification < 0.02, "{}", want.report.quality.misclassification);
}
