//! Dense f64 reference of the soft-Voronoi kernel: every site, no truncation, no index.
//! O(K) per point; used by the tests to check the sparse kernel and by nothing else.

use crate::kernel::{distance, Kernel};

/// V(x) and ∂V/∂p_k for every site k (K×3), by the log-sum-exp formula over all sites.
pub fn value_and_grad(kernel: &Kernel, sites: &[[f64; 3]], labels: &[bool], x: [f64; 3]) -> (f64, Vec<[f64; 3]>) {
    let d: Vec<f64> = sites.iter().map(|&p| distance(x, p)).collect();
    let d_min = d.iter().copied().fold(f64::INFINITY, f64::min);
    let e: Vec<f64> = d.iter().map(|&dk| (-kernel.beta * (dk - d_min)).exp()).collect();
    let z: f64 = e.iter().sum();
    let v: f64 = e.iter().zip(labels).filter(|(_, &l)| l).map(|(w, _)| w).sum::<f64>() / z;
    let grad = (0..sites.len())
        .map(|k| {
            let lam = if labels[k] { 1.0 } else { 0.0 };
            if d[k] == 0.0 {
                return [0.0; 3];
            }
            let f = -kernel.beta * (e[k] / z) * (lam - v) / d[k];
            let p = sites[k];
            [f * (p[0] - x[0]), f * (p[1] - x[1]), f * (p[2] - x[2])]
        })
        .collect();
    (v, grad)
}

/// Mean reconstruction loss (1/N) Σ |O_i − V(x_i)| and its gradient (K×3), densely.
pub fn reconstruction(
    kernel: &Kernel,
    sites: &[[f64; 3]],
    labels: &[bool],
    points: &[[f64; 3]],
    occupancy: &[bool],
) -> (f64, Vec<[f64; 3]>) {
    let n = points.len() as f64;
    let mut loss = 0.0;
    let mut grad = vec![[0.0; 3]; sites.len()];
    for (&x, &o) in points.iter().zip(occupancy) {
        let (v, g) = value_and_grad(kernel, sites, labels, x);
        loss += if o { 1.0 - v } else { v };
        let s = if o { -1.0 } else { 1.0 } / n;
        for (acc, gk) in grad.iter_mut().zip(&g) {
            for c in 0..3 {
                acc[c] += s * gk[c];
            }
        }
    }
    (loss / n, grad)
}
