//! The sparse soft-Voronoi kernel against the dense f64 reference, finite differences and
//! extreme inputs.

use soft_voronoi::kernel::{self, Kernel, Scratch, SiteIndex};
use soft_voronoi::{dense, losses};
use vf_common::rng::{ChunkRng, Stream};

const BETAS: [f64; 6] = [10.0, 100.0, 1_000.0, 10_000.0, 30_000.0, 100_000.0];

/// Random sites, labels, and query points of which half sit near a bisector of two sites
/// (where the soft-argmin is not saturated and the gradient is large).
fn config(k: usize, n: usize, beta: f64, seed: u64) -> (Vec<[f64; 3]>, Vec<bool>, Vec<[f64; 3]>) {
    let mut rng = ChunkRng::for_chunk(seed, Stream::Test, 7);
    let sites: Vec<[f64; 3]> = (0..k).map(|_| [rng.uniform(), rng.uniform(), rng.uniform()]).collect();
    let labels: Vec<bool> = (0..k).map(|_| rng.next_u64().is_multiple_of(2)).collect();
    let index = SiteIndex::new(&sites);
    let mut points = Vec::new();
    while points.len() < n {
        let x = [rng.uniform(), rng.uniform(), rng.uniform()];
        if points.len() % 2 == 0 {
            points.push(x);
            continue;
        }
        // Move x onto the bisector of its two nearest sites, then off it by a few 1/β.
        let (a, _) = index.nearest(&sites, x);
        let b = (0..k)
            .filter(|&j| j != a as usize)
            .min_by(|&i, &j| kernel_distance(x, sites[i]).total_cmp(&kernel_distance(x, sites[j])));
        let Some(b) = b else {
            points.push(x);
            continue;
        };
        let (pa, pb) = (sites[a as usize], sites[b]);
        let mid = [0, 1, 2].map(|c| 0.5 * (pa[c] + pb[c]));
        let off = (rng.uniform() - 0.5) * 6.0 / beta;
        let dir = [0, 1, 2].map(|c| pb[c] - pa[c]);
        let len = kernel_distance(pa, pb).max(1e-300);
        points.push([0, 1, 2].map(|c| mid[c] + off * dir[c] / len));
    }
    (sites, labels, points)
}

fn kernel_distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn sparse_value_and_gradient_equal_dense_reference() {
    let mut checked_nontrivial = 0;
    for (bi, &beta) in BETAS.iter().enumerate() {
        for (ki, &k) in [2usize, 7, 64, 500].iter().enumerate() {
            let (sites, labels, points) = config(k, 60, beta, (bi * 10 + ki) as u64);
            let kern = Kernel::new(beta);
            let index = SiteIndex::new(&sites);
            let mut s = Scratch::default();
            for &x in &points {
                let mut sparse = vec![[0.0; 3]; k];
                let v =
                    kernel::value_and_grad(&kern, &index, &sites, &labels, x, &mut s, |j, g| sparse[j as usize] = g);
                let (vd, gd) = dense::value_and_grad(&kern, &sites, &labels, x);
                assert!(v.is_finite() && (v - vd).abs() <= 1e-9, "beta {beta} k {k}: V {v} vs dense {vd}");
                let scale = gd.iter().flatten().fold(1.0f64, |m, g| m.max(g.abs()));
                for j in 0..k {
                    for c in 0..3 {
                        let err = (sparse[j][c] - gd[j][c]).abs();
                        assert!(err <= 1e-9 * scale, "beta {beta} k {k} site {j}: {} vs {}", sparse[j][c], gd[j][c]);
                    }
                }
                if v > 1e-6 && v < 1.0 - 1e-6 {
                    checked_nontrivial += 1;
                }
            }
        }
    }
    // The bisector points make sure the comparison covers unsaturated softmaxes.
    assert!(checked_nontrivial > 200, "only {checked_nontrivial} unsaturated queries");
}

#[test]
fn analytic_gradient_equals_finite_differences() {
    let mut compared = 0;
    for &beta in &BETAS {
        let (sites, labels, points) = config(40, 30, beta, 99);
        let kern = Kernel::new(beta);
        let h = 1e-4 / beta;
        for &x in points.iter().skip(1).step_by(2) {
            let (v0, g) = dense::value_and_grad(&kern, &sites, &labels, x);
            if !(1e-4..=1.0 - 1e-4).contains(&v0) {
                continue;
            }
            for j in 0..sites.len() {
                for c in 0..3 {
                    let mut plus = sites.clone();
                    plus[j][c] += h;
                    let mut minus = sites.clone();
                    minus[j][c] -= h;
                    let fd = (dense::value_and_grad(&kern, &plus, &labels, x).0
                        - dense::value_and_grad(&kern, &minus, &labels, x).0)
                        / (2.0 * h);
                    let tol = 1e-5 * beta.max(1.0) * 0.25 + 1e-6 * g[j][c].abs();
                    assert!((fd - g[j][c]).abs() <= tol, "beta {beta} site {j}.{c}: fd {fd} vs {}", g[j][c]);
                    compared += (g[j][c].abs() > 1e-3) as usize;
                }
            }
        }
    }
    assert!(compared > 100, "only {compared} non-zero gradient entries compared");
}

#[test]
fn batch_loss_and_gradient_equal_dense_reference() {
    for &beta in &BETAS {
        let (sites, labels, points) = config(300, 400, beta, 5);
        let occ: Vec<bool> = points.iter().map(|p| p[0] + p[1] > 1.0).collect();
        let kern = Kernel::new(beta);
        let index = SiteIndex::new(&sites);
        let mut grad = vec![[0.0; 3]; sites.len()];
        let loss = losses::reconstruction(&kern, &index, &sites, &labels, &points, &occ, 1.0, &mut grad);
        let (ld, gd) = dense::reconstruction(&kern, &sites, &labels, &points, &occ);
        assert!((loss - ld).abs() <= 1e-9, "beta {beta}: loss {loss} vs {ld}");
        let scale = gd.iter().flatten().fold(1.0f64, |m, g| m.max(g.abs()));
        for (a, b) in grad.iter().flatten().zip(gd.iter().flatten()) {
            assert!((a - b).abs() <= 1e-9 * scale, "beta {beta}: {a} vs {b}");
        }
    }
}

#[test]
fn extreme_inputs_stay_finite() {
    let sites = vec![[0.5, 0.5, 0.5], [0.5, 0.5, 0.5], [0.5 + 1e-15, 0.5, 0.5], [0.1, 0.9, 0.3], [1e-300, 0.0, 0.0]];
    let labels = vec![true, false, true, false, true];
    let index = SiteIndex::new(&sites);
    let mut s = Scratch::default();
    for beta in [1e-6, 1.0, 1e4, 1e8, 1e15, 1e300] {
        let kern = Kernel::new(beta);
        for x in [[0.5, 0.5, 0.5], [0.5 + 5e-16, 0.5, 0.5], [0.0; 3], [1e6, -1e6, 3.0], [0.3, 0.7, 0.5]] {
            let mut gs = Vec::new();
            let v = kernel::value_and_grad(&kern, &index, &sites, &labels, x, &mut s, |j, g| gs.push((j, g)));
            assert!((0.0..=1.0).contains(&v), "beta {beta} x {x:?}: V = {v}");
            assert!(gs.iter().all(|(_, g)| g.iter().all(|c| c.is_finite())), "beta {beta} x {x:?}: {gs:?}");
            let (vd, gd) = dense::value_and_grad(&kern, &sites, &labels, x);
            assert!(vd.is_finite() && gd.iter().flatten().all(|g| g.is_finite()));
        }
    }
}

#[test]
fn hard_label_is_nearest_site_label() {
    let (sites, labels, points) = config(1000, 2000, 1e4, 3);
    let index = SiteIndex::new(&sites);
    for &x in &points {
        let best = (0..sites.len())
            .min_by(|&i, &j| kernel_distance(x, sites[i]).total_cmp(&kernel_distance(x, sites[j])))
            .unwrap();
        let d_best = kernel_distance(x, sites[best]);
        let (k, d) = index.nearest(&sites, x);
        assert_eq!(d, d_best);
        assert!(kernel::hard_label(&index, &sites, &labels, x) == labels[best] || k as usize != best);
    }
}
