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
//! site). A k-d tree over the sites ([`KnnTree`]) finds, in one traversal, the sites within
//! that radius of the nearest, so a query costs O(log K + m) for m candidates instead of
//! the dense O(K). A training sample drawn again carries the site that was nearest last
//! time (a hint): its distance bounds the search from the start, so the tree is searched
//! much less. The candidates, and so V and its gradient, do not depend on the hint.
//!
//! At d_k = 0 the distance is not differentiable; its gradient is taken as 0 there (a
//! subgradient).

use std::sync::OnceLock;

use kiddo::immutable::float::kdtree::ImmutableKdTree;
use kiddo::SquaredEuclidean;

use crate::grid::KnnGrid;
use crate::knn::KnnTree;

/// No hint: the sample has not been seen, or its last nearest site is unknown.
pub const NO_HINT: u32 = u32::MAX;

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

/// The sites' k-d trees, in `D` dimensions: 3 for meshes, 2 for the MNIST autoencoder.
/// Everything in this module is generic over `D`, so the planar experiment runs the same
/// kernel as the main job.
///
/// The candidate query runs on this crate's [`KnnTree`]: it fuses the nearest query and
/// the radius query into one traversal and writes into a caller-owned buffer; kiddo's
/// radius query allocates a vector per call and needs a nearest query first, and the two
/// were most of a training step. The plain nearest query (hard labels of many points)
/// runs on kiddo's `ImmutableKdTree` (bucket size 32, SIMD leaf scans), built the first
/// time it is asked for.
///
/// With a cell width ([`SiteIndex::with_cell`], 3D only) the candidate query is first
/// tried on a uniform grid ([`KnnGrid::window`]): near the surface, where the sites are
/// dense and evenly spread, the block of cells around a sample holds its candidates, and
/// scanning a few contiguous runs beats descending the tree (the training's queries were
/// most of its time). Where the grid cannot tell (a sample far from every site), the tree
/// answers, built the first time it is needed. The answer is the same either way.
pub struct SiteIndex<const D: usize = 3> {
    knn: OnceLock<KnnTree<D>>,
    kiddo: OnceLock<ImmutableKdTree<f64, u32, D, 32>>,
    grid: Option<KnnGrid>,
    points: Vec<[f64; D]>,
}

impl<const D: usize> SiteIndex<D> {
    /// Builds the index over `sites` (finite coordinates; at least one site).
    pub fn new(sites: &[[f64; D]]) -> Self {
        let knn = OnceLock::new();
        let _ = knn.set(KnnTree::new(sites));
        SiteIndex { knn, kiddo: OnceLock::new(), grid: None, points: sites.to_vec() }
    }

    /// [`SiteIndex::new`] with a grid of cells about `cell` wide in front of the tree
    /// (see the type's documentation; in 3D only, elsewhere the same as `new`). The cell
    /// width sets only the speed.
    pub fn with_cell(sites: &[[f64; D]], cell: f64) -> Self {
        if D != 3 || !(cell.is_finite() && cell > 0.0) {
            return Self::new(sites);
        }
        let sites3: Vec<[f64; 3]> = sites.iter().map(|&p| to3(p)).collect();
        SiteIndex {
            knn: OnceLock::new(),
            kiddo: OnceLock::new(),
            grid: Some(KnnGrid::new(&sites3, cell)),
            points: sites.to_vec(),
        }
    }

    fn tree(&self) -> &KnnTree<D> {
        self.knn.get_or_init(|| KnnTree::new(&self.points))
    }

    /// Number of indexed sites.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the index is empty.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Index of a nearest site to `x` and its distance (recomputed exactly in f64 from
    /// `sites`).
    pub fn nearest(&self, sites: &[[f64; D]], x: [f64; D]) -> (u32, f64) {
        let tree = self.kiddo.get_or_init(|| ImmutableKdTree::new_from_slice(&self.points));
        let nn = tree.nearest_one::<SquaredEuclidean>(&x);
        (nn.item, distance(x, sites[nn.item as usize]))
    }

    /// Fills `out` with (site, distance) for every site within `d_min + window` of `x`,
    /// sorted by site index, and returns d_min. Distances are computed in f64 by
    /// [`distance`], so the result does not depend on the tree.
    pub fn candidates(&self, sites: &[[f64; D]], x: [f64; D], window: f64, out: &mut Vec<(u32, f64)>) -> f64 {
        let mut hint = NO_HINT;
        self.candidates_hinted(sites, x, window, &mut hint, out)
    }

    /// [`SiteIndex::candidates`] warm-started from `hint`, a site that was near `x`
    /// before (or [`NO_HINT`]); `hint` is set to the nearest site (the lowest index among
    /// equally near ones) for the next time. The candidates do not depend on the hint.
    pub fn candidates_hinted(
        &self,
        sites: &[[f64; D]],
        x: [f64; D],
        window: f64,
        hint: &mut u32,
        out: &mut Vec<(u32, f64)>,
    ) -> f64 {
        let start = match sites.get(*hint as usize) {
            Some(&p) => distance(x, p),
            _ => f64::INFINITY,
        };
        let on_grid = self.grid.as_ref().and_then(|g| g.window(to3(x), window, start, out));
        let d_min = match on_grid {
            Some(d) => d,
            None => self.tree().window(x, window, start, out),
        };
        out.sort_unstable_by_key(|c| c.0);
        if let Some(c) = out.iter().find(|c| c.1 == d_min) {
            *hint = c.0;
        }
        d_min
    }
}

/// The first three coordinates of a `D`-dimensional point (zeros beyond `D`): the grid's
/// point for [`SiteIndex::with_cell`], which builds a grid only when `D` is 3.
#[inline]
fn to3<const D: usize>(p: [f64; D]) -> [f64; 3] {
    let mut q = [0.0; 3];
    let n = D.min(3);
    q[..n].copy_from_slice(&p[..n]);
    q
}

/// Euclidean distance in `D` dimensions: the square root of [`crate::knn::d2`], so the
/// kernel's distances and the tree's agree bit for bit.
#[inline]
pub fn distance<const D: usize>(a: [f64; D], b: [f64; D]) -> f64 {
    crate::knn::d2(a, b).sqrt()
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
    grad: impl FnMut(u32, [f64; D]),
) -> f64 {
    let mut hint = NO_HINT;
    value_and_grad_hinted(kernel, index, sites, labels, x, &mut hint, s, grad)
}

/// [`value_and_grad`] warm-started from a hint (see [`SiteIndex::candidates_hinted`]);
/// the result does not depend on it.
#[allow(clippy::too_many_arguments)]
pub fn value_and_grad_hinted<const D: usize>(
    kernel: &Kernel,
    index: &SiteIndex<D>,
    sites: &[[f64; D]],
    labels: &[bool],
    x: [f64; D],
    hint: &mut u32,
    s: &mut Scratch,
    mut grad: impl FnMut(u32, [f64; D]),
) -> f64 {
    let d_min = index.candidates_hinted(sites, x, kernel.window(), hint, &mut s.candidates);
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
