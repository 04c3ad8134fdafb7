//! The training losses and their gradients with respect to the trainable sites.
//!
//! All gradients are accumulated in a fixed order (fixed-size chunks of samples or sites,
//! reduced in chunk order) so a step's result is bit-identical for any thread count.

use rayon::prelude::*;

use crate::grid::KnnGrid;
use crate::kernel::{self, Kernel, Scratch, SiteIndex, NO_HINT};
use crate::knn::{self, KnnTree};
use std::sync::OnceLock;

/// Samples per parallel chunk (fixed: the reduction order depends on it).
pub const CHUNK: usize = 1024;

/// One chunk's share of a loss: its summed loss and its sparse gradient contributions
/// (site index, gradient), reduced in chunk order by [`reduce`].
pub(crate) type ChunkPart<const D: usize> = (f64, Vec<(u32, [f64; D])>);

/// Reconstruction loss (1/N) Σ_i |O(x_i) − V(x_i)| over a batch, and its gradient added
/// (times `weight`) into `grad` for the first `grad.len()` sites (the trainable ones;
/// later sites — fixed boundary sites — get none).
///
/// - `sites`, `labels`: all K + B sites; `index` built over `sites`.
/// - `points`, `occupancy`: the batch (unit-cube frame) and its ground truth.
#[allow(clippy::too_many_arguments)]
pub fn reconstruction<const D: usize>(
    kernel: &Kernel,
    index: &SiteIndex<D>,
    sites: &[[f64; D]],
    labels: &[bool],
    points: &[[f64; D]],
    occupancy: &[bool],
    weight: f64,
    grad: &mut [[f64; D]],
) -> f64 {
    let mut hints = vec![kernel::NO_HINT; points.len()];
    reconstruction_hinted(kernel, index, sites, labels, points, occupancy, &mut hints, weight, grad)
}

/// [`reconstruction`] with one hint per point (a site near it, or
/// [`kernel::NO_HINT`]), updated to each point's nearest site; the result does not depend
/// on the hints (see [`SiteIndex::candidates_hinted`]).
#[allow(clippy::too_many_arguments)]
pub fn reconstruction_hinted<const D: usize>(
    kernel: &Kernel,
    index: &SiteIndex<D>,
    sites: &[[f64; D]],
    labels: &[bool],
    points: &[[f64; D]],
    occupancy: &[bool],
    hints: &mut [u32],
    weight: f64,
    grad: &mut [[f64; D]],
) -> f64 {
    let n = points.len().max(1) as f64;
    let trainable = grad.len() as u32;
    let parts: Vec<ChunkPart<D>> = points
        .par_chunks(CHUNK)
        .zip(occupancy.par_chunks(CHUNK))
        .zip(hints.par_chunks_mut(CHUNK))
        .map(|((xs, os), hs)| {
            let mut s = Scratch::default();
            let mut contributions = Vec::new();
            let mut loss = 0.0;
            for ((&x, &o), h) in xs.iter().zip(os).zip(hs) {
                let sign = if o { -1.0 } else { 1.0 };
                let v = kernel::value_and_grad_hinted(kernel, index, sites, labels, x, h, &mut s, |k, g| {
                    if k < trainable {
                        contributions.push((k, g.map(|gc| sign * gc)));
                    }
                });
                loss += if o { 1.0 - v } else { v };
            }
            (loss, contributions)
        })
        .collect();
    reduce(parts, weight / n, grad) / n
}

/// Per-chunk partial losses and gradient contributions, summed in chunk order (so the
/// result does not depend on the thread count); the contributions times `factor` are
/// added into `grad`. Returns the summed loss.
fn reduce<const D: usize>(parts: Vec<ChunkPart<D>>, factor: f64, grad: &mut [[f64; D]]) -> f64 {
    let mut loss = 0.0;
    for (l, contributions) in parts {
        loss += l;
        for (k, g) in contributions {
            let acc = &mut grad[k as usize];
            for c in 0..D {
                acc[c] += factor * g[c];
            }
        }
    }
    loss
}

/// Bounds loss Σ_k Σ_c max(−p_kc, 0) + max(p_kc − 1, 0) over the trainable sites (the
/// unit cube is the domain), with its gradient times `weight` added into `grad`.
pub fn bounds<const D: usize>(sites: &[[f64; D]], weight: f64, grad: &mut [[f64; D]]) -> f64 {
    let mut loss = 0.0;
    for (p, g) in sites.iter().zip(grad.iter_mut()) {
        for c in 0..D {
            if p[c] < 0.0 {
                loss -= p[c];
                g[c] -= weight;
            } else if p[c] > 1.0 {
                loss += p[c] - 1.0;
                g[c] += weight;
            }
        }
    }
    loss
}

/// Where a point lies relative to the target solid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Located<const D: usize = 3> {
    /// Whether the point is inside the solid.
    pub inside: bool,
    /// A closest point on the solid's surface.
    pub closest: [f64; D],
}

/// The target shape, as needed by the signed-distance regulariser: inside test and
/// closest surface point, in the unit-cube frame. Implemented for meshes
/// ([`crate::MeshSolid`]) and analytic shapes (the sphere study).
pub trait Solid: Sync {
    /// Locates every point (any thread count; the result must not depend on it).
    fn locate(&self, points: &[[f64; 3]]) -> Vec<Located>;

    /// Inside test only (solids with a cheaper test than [`Solid::locate`] override it).
    fn inside(&self, points: &[[f64; 3]]) -> Vec<bool> {
        self.locate(points).into_iter().map(|l| l.inside).collect()
    }
}

/// Signed-distance regulariser: (1/K) Σ_k dist(p_k, S_k) where S_k is the solid for an
/// inside site and its complement for an outside site (0 when the site is on its side),
/// with its gradient times `weight` added into `grad`. Sites are the trainable ones.
pub fn signed_distance(
    solid: &dyn Solid,
    sites: &[[f64; 3]],
    inside: &[bool],
    weight: f64,
    grad: &mut [[f64; 3]],
) -> f64 {
    signed_distance_cached(&solid.locate(sites), sites, inside, weight, grad)
}

/// [`signed_distance`] with the side and closest surface point of each site given
/// (`located`, computed at a recent position of the sites: training refreshes them every
/// `refresh_every` steps, during which a site moves at most a few learning rates). The
/// distance and its gradient use the current positions.
pub fn signed_distance_cached<const D: usize>(
    located: &[Located<D>],
    sites: &[[f64; D]],
    inside: &[bool],
    weight: f64,
    grad: &mut [[f64; D]],
) -> f64 {
    let k = sites.len().max(1) as f64;
    let mut loss = 0.0;
    for (((p, &lab), loc), g) in sites.iter().zip(inside).zip(located).zip(grad.iter_mut()) {
        if lab == loc.inside {
            continue;
        }
        let d = kernel::distance(*p, loc.closest);
        if d == 0.0 {
            continue;
        }
        loss += d;
        let f = weight / (k * d);
        for c in 0..D {
            g[c] += f * (p[c] - loc.closest[c]);
        }
    }
    loss / k
}

/// The Delaunay graph of all sites (trainable and boundary) in compressed rows, site
/// indices as given.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SiteGraph {
    /// #sites + 1 row offsets into `neighbors`.
    pub offsets: Vec<u32>,
    /// Neighbour site indices, sorted within each row.
    pub neighbors: Vec<u32>,
}

impl SiteGraph {
    /// The Delaunay graph of `sites` (exact, from delaunay3). Duplicate sites share one
    /// Delaunay vertex; each copy gets that vertex's neighbours.
    ///
    /// # Errors
    /// The triangulation's error (non-finite or all coplanar sites).
    pub fn delaunay(sites: &[[f64; 3]]) -> Result<Self, delaunay3::DelaunayError> {
        let dt = delaunay3::Delaunay3::new(sites)?;
        let nv = dt.num_vertices();
        let mut rows: Vec<Vec<u32>> = vec![Vec::new(); nv];
        for e in dt.edges() {
            let [a, b] = e.vertices;
            if a as usize >= nv || b as usize >= nv {
                continue;
            }
            rows[a as usize].push(b);
            rows[b as usize].push(a);
        }
        let mut offsets = Vec::with_capacity(sites.len() + 1);
        let mut neighbors = Vec::new();
        offsets.push(0u32);
        for i in 0..sites.len() {
            let v = dt.vertex_of_input(i);
            let mut row: Vec<u32> = rows[v as usize].iter().map(|&w| dt.input_of_vertex(w)).collect();
            row.sort_unstable();
            neighbors.extend(row);
            offsets.push(neighbors.len() as u32);
        }
        Ok(SiteGraph { offsets, neighbors })
    }

    /// The graph with the given undirected `edges` over `num_sites` sites (each edge once
    /// or twice, in any order; self-loops and repeats are dropped). The planar experiment
    /// builds it from an exact 2D Delaunay triangulation.
    pub fn from_edges(num_sites: usize, edges: impl IntoIterator<Item = (u32, u32)>) -> Self {
        let mut rows: Vec<Vec<u32>> = vec![Vec::new(); num_sites];
        for (a, b) in edges {
            if a != b && (a as usize) < num_sites && (b as usize) < num_sites {
                rows[a as usize].push(b);
                rows[b as usize].push(a);
            }
        }
        let mut offsets = Vec::with_capacity(num_sites + 1);
        let mut neighbors = Vec::new();
        offsets.push(0u32);
        for mut row in rows {
            row.sort_unstable();
            row.dedup();
            neighbors.extend(row);
            offsets.push(neighbors.len() as u32);
        }
        SiteGraph { offsets, neighbors }
    }

    /// Neighbours of site `i`.
    pub fn row(&self, i: usize) -> &[u32] {
        &self.neighbors[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Number of sites the graph covers.
    pub fn num_sites(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }
}

/// Centroidal regulariser (1/K) Σ_{i trainable} ‖(L p)_i‖² with the uniform graph
/// Laplacian (L p)_i = p_i − mean_{j ∈ N(i)} p_j of `graph`, and its gradient times
/// `weight` added into `grad` (trainable sites only).
pub fn centroidal<const D: usize>(graph: &SiteGraph, sites: &[[f64; D]], weight: f64, grad: &mut [[f64; D]]) -> f64 {
    let trainable = grad.len();
    let k = trainable.max(1) as f64;
    let mut loss = 0.0;
    for i in 0..trainable.min(graph.num_sites()) {
        let row = graph.row(i);
        if row.is_empty() {
            continue;
        }
        let inv = 1.0 / row.len() as f64;
        let mut r = sites[i];
        for &j in row {
            for c in 0..D {
                r[c] -= inv * sites[j as usize][c];
            }
        }
        loss += r.iter().map(|x| x * x).sum::<f64>();
        let f = 2.0 * weight / k;
        for c in 0..D {
            grad[i][c] += f * r[c];
        }
        for &j in row {
            if (j as usize) < trainable {
                for c in 0..D {
                    grad[j as usize][c] -= f * inv * r[c];
                }
            }
        }
    }
    loss / k
}

/// Sites split by label, each side in its own k-d tree, for [`surface`]. With a cell width
/// ([`LabelledIndex::with_cell`]) a uniform grid over all sites answers first
/// ([`KnnGrid::nearest_by_label`]: the block of cells around a sample near the surface
/// holds the nearest site of each side), and the trees, built the first time they are
/// needed, answer the rest. The answer is the same either way.
pub struct LabelledIndex {
    /// Global indices of the inside sites.
    pub inside: Vec<u32>,
    /// Global indices of the outside sites.
    pub outside: Vec<u32>,
    labels: Vec<bool>,
    /// Each side's sites, in the order of `inside` and `outside`.
    points: [Vec<[f64; 3]>; 2],
    inside_tree: OnceLock<KnnTree>,
    outside_tree: OnceLock<KnnTree>,
    grid: Option<KnnGrid>,
}

impl LabelledIndex {
    /// Indexes `sites` by `labels`.
    pub fn new(sites: &[[f64; 3]], labels: &[bool]) -> Self {
        let index = Self::with_cell(sites, labels, f64::NAN);
        rayon::join(|| index.tree(true), || index.tree(false));
        index
    }

    /// [`LabelledIndex::new`] with a grid of cells about `cell` wide in front of the trees
    /// (none when `cell` is not finite and positive); the cell width sets only the speed.
    pub fn with_cell(sites: &[[f64; 3]], labels: &[bool], cell: f64) -> Self {
        let (mut inside, mut outside) = (Vec::new(), Vec::new());
        for (i, &l) in labels.iter().enumerate() {
            if l {
                inside.push(i as u32)
            } else {
                outside.push(i as u32)
            }
        }
        let points = |ids: &[u32]| ids.iter().map(|&i| sites[i as usize]).collect::<Vec<_>>();
        let grid = (cell.is_finite() && cell > 0.0).then(|| KnnGrid::new(sites, cell));
        LabelledIndex {
            points: [points(&inside), points(&outside)],
            inside_tree: OnceLock::new(),
            outside_tree: OnceLock::new(),
            grid,
            inside,
            outside,
            labels: labels.to_vec(),
        }
    }

    /// The tree of the inside (`true`) or outside sites.
    fn tree(&self, inside: bool) -> &KnnTree {
        let (cell, points) =
            if inside { (&self.inside_tree, &self.points[0]) } else { (&self.outside_tree, &self.points[1]) };
        cell.get_or_init(|| KnnTree::new(points))
    }

    /// The nearest inside and the nearest outside site of `x` (global indices; ties by
    /// index), if both sides have sites.
    pub fn nearest_pair(&self, sites: &[[f64; 3]], x: [f64; 3]) -> Option<(u32, u32)> {
        self.nearest_pair_hinted(sites, x, &mut [NO_HINT; 2])
    }

    /// [`LabelledIndex::nearest_pair`] warm-started from `hints` (an inside and an outside
    /// site that were near `x` before, global indices, or [`NO_HINT`]), which are set to
    /// the answer; the answer does not depend on them. `sites` are the indexed ones.
    pub fn nearest_pair_hinted(&self, sites: &[[f64; 3]], x: [f64; 3], hints: &mut [u32; 2]) -> Option<(u32, u32)> {
        // A hint that carries its side's label bounds that side's nearest squared distance
        // (computed as the grid and the trees compute it): the grid skips the blocks that
        // cannot hold both, and each tree's search starts bounded.
        let bound = |hint: u32, label: bool| match self.labels.get(hint as usize) {
            Some(&l) if l == label => knn::d2(x, sites[hint as usize]),
            _ => f64::INFINITY,
        };
        let bounds = [bound(hints[0], true), bound(hints[1], false)];
        if let Some(grid) = &self.grid {
            if let Some([(_, a), (_, b)]) = grid.nearest_by_label(x, &self.labels, bounds[0].max(bounds[1])) {
                *hints = [a, b];
                return Some((a, b));
            }
        }
        let side =
            |tree: &KnnTree, ids: &[u32], bound2: f64| tree.nearest_within(x, bound2).map(|(_, l)| ids[l as usize]);
        let a = side(self.tree(true), &self.inside, bounds[0])?;
        hints[0] = a;
        let b = side(self.tree(false), &self.outside, bounds[1])?;
        hints[1] = b;
        Some((a, b))
    }
}

/// Surface term (1/M) Σ_x d(x)² over surface samples `points`: for each, a = its nearest
/// inside site and b = its nearest outside site, and d = (x − (a+b)/2)·(b − a)/|b − a| its
/// signed distance to their bisector plane, which carries the crust's face between them
/// when a and b are Voronoi neighbours (they are, for x close to the crust). It pulls the
/// crust onto the surface directly (the occupancy loss only sees it through β), like
/// VoroMesh's VoroLoss (Maruani et al. 2023) but between opposite labels only, the faces
/// that make the crust. The gradient times `weight` is added into `grad` for trainable
/// sites (index < `grad.len()`).
///
/// With `normal_weight` > 0 each sample also pays `normal_weight` · (1 − (u·n)²), u the
/// unit direction from a to b and n the surface normal at x (either orientation): the
/// face must not only pass through x but lie along the surface there.
pub fn surface(
    index: &LabelledIndex,
    sites: &[[f64; 3]],
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    normal_weight: f64,
    weight: f64,
    grad: &mut [[f64; 3]],
) -> f64 {
    let mut hints = vec![[NO_HINT; 2]; points.len()];
    surface_hinted(index, sites, points, normals, &mut hints, normal_weight, 0.0, weight, grad)
}

/// One surface sample's part of [`surface_hinted`]: x with unit normal `nx`, its nearest
/// inside site `ia` and nearest outside site `ib`; adds its loss into `loss` and the
/// trainable sites' gradients into `contributions`.
#[allow(clippy::too_many_arguments)]
#[inline]
fn surface_one(
    sites: &[[f64; 3]],
    x: [f64; 3],
    nx: [f64; 3],
    ia: u32,
    ib: u32,
    normal_weight: f64,
    min_cos: f64,
    trainable: u32,
    loss: &mut f64,
    contributions: &mut Vec<(u32, [f64; 3])>,
) {
    let (a, b) = (sites[ia as usize], sites[ib as usize]);
    let e = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
    if len == 0.0 {
        return;
    }
    let r = [0, 1, 2].map(|c| x[c] - 0.5 * (a[c] + b[c]));
    let d = (r[0] * e[0] + r[1] * e[1] + r[2] * e[2]) / len;
    *loss += d * d;
    // ∂d/∂a = (−e/2 − r)/|e| + d·u/|e|, ∂d/∂b = (−e/2 + r)/|e| − d·u/|e|, u = e/|e|.
    let f = 2.0 * d / len;
    let mut ga = [0, 1, 2].map(|c| f * (-0.5 * e[c] - r[c] + d * e[c] / len));
    let mut gb = [0, 1, 2].map(|c| f * (-0.5 * e[c] + r[c] - d * e[c] / len));
    let un = (e[0] * nx[0] + e[1] * nx[1] + e[2] * nx[2]) / len;
    if normal_weight > 0.0 && un.abs() >= min_cos {
        // 1 − (u·n)²; ∂(u·n)/∂e = (n − (u·n) u)/|e|, ∂e/∂b = I = −∂e/∂a.
        *loss += normal_weight * (1.0 - un * un);
        let g = -2.0 * normal_weight * un / len;
        for c in 0..3 {
            let de = g * (nx[c] - un * e[c] / len);
            gb[c] += de;
            ga[c] -= de;
        }
    }
    if ia < trainable {
        contributions.push((ia, ga));
    }
    if ib < trainable {
        contributions.push((ib, gb));
    }
}

/// [`surface_hinted`] where the caller already knows, for most samples, the nearest inside
/// and outside site: `pairs[i]` is that pair when its flag is set, else the pair is searched
/// in `index` (built from `labels` on the first such sample). Same result as
/// [`surface_hinted`], bit for bit: the polish finds the pairs among the 11 nearest sites it
/// looks up anyway.
#[allow(clippy::too_many_arguments)]
pub(crate) fn surface_paired(
    index: &std::sync::OnceLock<LabelledIndex>,
    labels: &[bool],
    sites: &[[f64; 3]],
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    pairs: &mut [([u32; 2], bool)],
    normal_weight: f64,
    min_cos: f64,
    weight: f64,
    grad: &mut [[f64; 3]],
) -> f64 {
    let pair = |&mut (p, known): &mut ([u32; 2], bool), x: [f64; 3]| {
        if known {
            Some((p[0], p[1]))
        } else {
            index.get_or_init(|| LabelledIndex::new(sites, labels)).nearest_pair(sites, x)
        }
    };
    surface_sum(sites, points, normals, pairs, pair, normal_weight, min_cos, weight, grad)
}

/// [`surface`] warm-started: `hints` holds, per point, an inside and an outside site that
/// were near it (or [`NO_HINT`]), and is set to the nearest pair; the result does not
/// depend on it.
#[allow(clippy::too_many_arguments)]
pub fn surface_hinted(
    index: &LabelledIndex,
    sites: &[[f64; 3]],
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    hints: &mut [[u32; 2]],
    normal_weight: f64,
    min_cos: f64,
    weight: f64,
    grad: &mut [[f64; 3]],
) -> f64 {
    let pair = |h: &mut [u32; 2], x: [f64; 3]| index.nearest_pair_hinted(sites, x, h);
    surface_sum(sites, points, normals, hints, pair, normal_weight, min_cos, weight, grad)
}

/// The surface term over `points`, each sample's nearest inside and outside site given by
/// `pair` from its own entry of `per_point` (a hint it may update, or a known pair); chunks
/// of [`CHUNK`] samples, summed in order.
#[allow(clippy::too_many_arguments)]
fn surface_sum<P: Send>(
    sites: &[[f64; 3]],
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    per_point: &mut [P],
    pair: impl Fn(&mut P, [f64; 3]) -> Option<(u32, u32)> + Sync,
    normal_weight: f64,
    min_cos: f64,
    weight: f64,
    grad: &mut [[f64; 3]],
) -> f64 {
    let m = points.len().max(1) as f64;
    let trainable = grad.len() as u32;
    let parts: Vec<ChunkPart<3>> = points
        .par_chunks(CHUNK)
        .zip(normals.par_chunks(CHUNK))
        .zip(per_point.par_chunks_mut(CHUNK))
        .map(|((xs, ns), ps)| {
            let mut contributions = Vec::with_capacity(2 * xs.len());
            let mut loss = 0.0;
            for ((&x, &nx), p) in xs.iter().zip(ns).zip(ps) {
                let Some((ia, ib)) = pair(p, x) else { continue };
                surface_one(sites, x, nx, ia, ib, normal_weight, min_cos, trainable, &mut loss, &mut contributions);
            }
            (loss, contributions)
        })
        .collect();
    reduce(parts, weight / m, grad) / m
}
