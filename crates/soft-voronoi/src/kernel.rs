//! The soft-Voronoi occupancy of VoronoiNet and its gradient with respect to the sites,
//! evaluated sparsely.
//!
//! For a point x and sites p_k with labels λ_k ∈ {0, 1}:
//!
//! ```text
//! d_k  = ‖x − p_k‖₂
//! w_k  = exp(−β (d_k − d_min)) / Σ_j exp(−β (d_j − d_min))      (softmax of −β d, shifted)
//! V(x) = Σ_k λ_k w_k
//! ∂V/∂p_k = w_k (λ_k − V) · (−β) · (p_k − x) / d_k
//! ```
//!
//! Shifting by d_min is the log-sum-exp trick: every exponent is ≤ 0 and the nearest site's
//! is exactly 0, so the denominator is ≥ 1 and nothing overflows or divides by zero for
//! any β. Sites farther than d_min + τ/β carry a weight below e^−τ relative to the nearest
//! one; they are left out, which changes V by at most (K−1)·e^−τ (τ = 30: 9.4e−14 per
//! site). A k-d tree over the sites (kiddo, rebuilt when the sites move) finds the nearest
//! site and then the sites within that radius, so a query costs O(log K + m) for m
//! candidates instead of the dense O(K).
//!
//! At d_k = 0 the distance is not differentiable; its gradient is taken as 0 there (a
//! subgradient).

use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

/// Default truncation τ: sites with weight below e^−τ of the nearest are ignored.
pub const DEFAULT_TAU: f64 = 30.0;

/// Temperature β and truncation τ of the soft-argmin.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Kernel {
    /// Inverse temperature β (> 0), in 1/unit-cube length. The paper uses 10,000.
    pub beta: f64,
    /// Truncation τ (> 0): candidate sites lie within τ/β of the nearest.
    pub tau: f64,
}

impl Kernel {
    /// The kernel with temperature `beta` and the default τ.
    pub fn new(beta: f64) -> Self {
        Kernel { beta, tau: DEFAULT_TAU }
    }

    /// Candidate window τ/β added to the nearest distance.
    pub fn window(&self) -> f64 {
        self.tau / self.beta
    }
}

/// A k-d tree over site positions (kiddo `ImmutableKdTree`, bucket size 32), in `D`
/// dimensions: 3 for meshes, 2 for the MNIST autoencoder. Everything in this module is
/// generic over `D`, so the planar experiment runs the same kernel as the main job.
pub struct SiteIndex<const D: usize = 3> {
    tree: ImmutableKdTree<f64, u32, D, 32>,
    num_sites: usize,
}

impl<const D: usize> SiteIndex<D> {
    /// Builds the tree over `sites` (finite coordinates; at least one site).
    pub fn new(sites: &[[f64; D]]) -> Self {
        SiteIndex { tree: ImmutableKdTree::new_from_slice(sites), num_sites: sites.len() }
    }

    /// Number of indexed sites.
    pub fn len(&self) -> usize {
        self.num_sites
    }

    /// Whether the index is empty.
    pub fn is_empty(&self) -> bool {
        self.num_sites == 0
    }

    /// Index of a nearest site to `x` and its distance (recomputed exactly in f64 from
    /// `sites`).
    pub fn nearest(&self, sites: &[[f64; D]], x: [f64; D]) -> (u32, f64) {
        let nn = self.tree.nearest_one::<SquaredEuclidean>(&x);
        (nn.item, distance(x, sites[nn.item as usize]))
    }

    /// Fills `out` with (site, distance) for every site within `d_min + window` of `x`,
    /// sorted by site index, and returns d_min. The distances are recomputed in f64 from
    /// `sites` so the result does not depend on the tree's internal arithmetic.
    pub fn candidates(&self, sites: &[[f64; D]], x: [f64; D], window: f64, out: &mut Vec<(u32, f64)>) -> f64 {
        out.clear();
        let (_, d_near) = self.nearest(sites, x);
        let radius = d_near + window;
        if radius < 1e150 {
            // A hair larger than the radius so that rounding in the tree's squared
            // distances never drops a site at the edge; the exact cut is applied below.
            let r2 = radius * radius * (1.0 + 1e-12) + f64::MIN_POSITIVE;
            for n in self.tree.within_unsorted::<SquaredEuclidean>(&x, r2) {
                out.push((n.item, distance(x, sites[n.item as usize])));
            }
        } else {
            out.extend(sites.iter().enumerate().map(|(k, &p)| (k as u32, distance(x, p))));
        }
        out.sort_unstable_by_key(|c| c.0);
        let d_min = out.iter().map(|c| c.1).fold(f64::INFINITY, f64::min).min(d_near);
        out.retain(|c| c.1 <= d_min + window);
        d_min
    }
}

/// Euclidean distance in `D` dimensions.
#[inline]
pub fn distance<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    let mut s = 0.0;
    for c in 0..D {
        let d = a[c] - b[c];
        s += d * d;
    }
    s.sqrt()
}

/// Scratch space for one thread's queries.
#[derive(Default)]
pub struct Scratch {
    candidates: Vec<(u32, f64)>,
    weights: Vec<f64>,
}

/// Soft occupancy V(x) from candidate (site, distance) pairs and their minimum distance,
/// with the normaliser z = Σ w (the unnormalised weights are left in `w`).
fn value_from_candidates(
    kernel: &Kernel,
    labels: &[bool],
    cands: &[(u32, f64)],
    d_min: f64,
    w: &mut Vec<f64>,
) -> (f64, f64) {
    w.clear();
    let mut z = 0.0;
    let mut num = 0.0;
    for &(k, d) in cands {
        let e = (-kernel.beta * (d - d_min)).exp();
        w.push(e);
        z += e;
        if labels[k as usize] {
            num += e;
        }
    }
    // z ≥ 1: the nearest site contributes exp(0).
    (num / z, z)
}

/// V(x) for one point.
pub fn value<const D: usize>(
    kernel: &Kernel,
    index: &SiteIndex<D>,
    sites: &[[f64; D]],
    labels: &[bool],
    x: [f64; D],
    s: &mut Scratch,
) -> f64 {
    let d_min = index.candidates(sites, x, kernel.window(), &mut s.candidates);
    value_from_candidates(kernel, labels, &s.candidates, d_min, &mut s.weights).0
}

/// V(x) and ∂V/∂p_k for the candidate sites k (every other site has a gradient below
/// β·e^−τ). Calls `grad(k, ∂V/∂p_k)` for each candidate, in site order, and returns V.
pub fn value_and_grad<const D: usize>(
    kernel: &Kernel,
    index: &SiteIndex<D>,
    sites: &[[f64; D]],
    labels: &[bool],
    x: [f64; D],
    s: &mut Scratch,
    mut grad: impl FnMut(u32, [f64; D]),
) -> f64 {
    let d_min = index.candidates(sites, x, kernel.window(), &mut s.candidates);
    let (v, z) = value_from_candidates(kernel, labels, &s.candidates, d_min, &mut s.weights);
    if s.candidates.len() < 2 {
        return v;
    }
    for (&(k, d), &e) in s.candidates.iter().zip(&s.weights) {
        let lam = if labels[k as usize] { 1.0 } else { 0.0 };
        let coef = (e / z) * (lam - v);
        if coef == 0.0 || d == 0.0 {
            continue;
        }
        let p = sites[k as usize];
        let f = -kernel.beta * coef / d;
        grad(k, std::array::from_fn(|c| f * (p[c] - x[c])));
    }
    v
}

/// Hard Voronoi occupancy: the label of a nearest site.
pub fn hard_label<const D: usize>(index: &SiteIndex<D>, sites: &[[f64; D]], labels: &[bool], x: [f64; D]) -> bool {
    labels[index.nearest(sites, x).0 as usize]
}
