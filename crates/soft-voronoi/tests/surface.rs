//! The surface term's analytic gradient against central finite differences, with and
//! without the normal alignment, and its zero on an exactly mirrored pair.

use soft_voronoi::losses::{surface, LabelledIndex};
use vf_common::rng::{ChunkRng, Stream};

fn loss(sites: &[[f64; 3]], labels: &[bool], pts: &[[f64; 3]], nrm: &[[f64; 3]], wn: f64) -> f64 {
    let mut g = vec![[0.0; 3]; sites.len()];
    surface(&LabelledIndex::new(sites, labels), sites, pts, nrm, wn, 1.0, &mut g)
}

#[test]
fn gradient_matches_finite_differences() {
    let mut rng = ChunkRng::for_chunk(3, Stream::Test, 40);
    let sites: Vec<[f64; 3]> = (0..40).map(|_| [rng.uniform(), rng.uniform(), rng.uniform()]).collect();
    let labels: Vec<bool> = (0..40).map(|i| i % 2 == 0).collect();
    let pts: Vec<[f64; 3]> = (0..300).map(|_| [rng.uniform(), rng.uniform(), rng.uniform()]).collect();
    let nrm: Vec<[f64; 3]> = (0..300)
        .map(|_| {
            let d = [rng.normal(), rng.normal(), rng.normal()];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            d.map(|x| x / l)
        })
        .collect();
    for wn in [0.0, 0.3] {
        let mut grad = vec![[0.0; 3]; sites.len()];
        surface(&LabelledIndex::new(&sites, &labels), &sites, &pts, &nrm, wn, 1.0, &mut grad);
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for k in 0..sites.len() {
            for c in 0..3 {
                let mut a = sites.clone();
                let mut b = sites.clone();
                a[k][c] += h;
                b[k][c] -= h;
                // Small steps keep every sample's nearest pair (checked by the tolerance).
                let fd = (loss(&a, &labels, &pts, &nrm, wn) - loss(&b, &labels, &pts, &nrm, wn)) / (2.0 * h);
                worst = worst.max((fd - grad[k][c]).abs() / (1e-6 + fd.abs().max(grad[k][c].abs())));
            }
        }
        assert!(worst < 1e-4, "normal weight {wn}: worst relative error {worst:e}");
    }
}

#[test]
fn a_mirrored_pair_with_its_point_on_the_bisector_costs_nothing() {
    let sites = [[0.5, 0.5, 0.4], [0.5, 0.5, 0.6]];
    let labels = [true, false];
    let mut grad = vec![[0.0; 3]; 2];
    let l = surface(
        &LabelledIndex::new(&sites, &labels),
        &sites,
        &[[0.52, 0.49, 0.5]],
        &[[0.0, 0.0, 1.0]],
        1.0,
        1.0,
        &mut grad,
    );
    assert!(l.abs() < 1e-15 && grad.iter().flatten().all(|g| g.abs() < 1e-12), "{l} {grad:?}");
    // Off the bisector by 0.01: d² = 1e-4.
    let l = surface(
        &LabelledIndex::new(&sites, &labels),
        &sites,
        &[[0.5, 0.5, 0.51]],
        &[[0.0, 0.0, 1.0]],
        0.0,
        1.0,
        &mut grad,
    );
    assert!((l - 1e-4).abs() < 1e-15, "{l}");
}
