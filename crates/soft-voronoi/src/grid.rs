//! Exact nearest-site queries on a uniform grid: the polish's k nearest sites (20,000
//! surface samples a step, each asking for its 11 nearest), and training's two queries,
//! the soft-Voronoi kernel's candidate window ([`KnnGrid::window`]) and a surface sample's
//! nearest inside and outside site ([`KnnGrid::nearest_by_label`]). The latter two return
//! `None` where the cells around the sample cannot settle the answer, and the caller asks
//! its k-d trees.
//!
//! Why not only [`KnnTree`]: a tree query descends from the root and backtracks through a
//! dozen levels of branches for every sample, about 1.9 µs at K = 8,192, and the polish
//! spent most of its time there. Where the sites are about evenly spread near the surface,
//! the k nearest of a sample almost always lie in the 3 × 3 × 3 cells around it when a cell
//! is about as wide as the k-th nearest distance: nine contiguous runs of points, no
//! branches to mispredict. A query scans them, and then checks that no point outside the
//! block can be nearer than the k-th found (the block's walls are farther than it); when
//! that check fails (a sparse region, a sample far from every site) it asks the tree,
//! built once on the first such query.
//!
//! The answer is [`KnnTree::k_nearest`]'s, bit for bit: the same squared distances
//! ([`crate::knn::d2`]), the same order (distance, then index), and a point is left out
//! only when its computed distance is certainly above the k-th. So the polish's result does
//! not depend on the cell size, which only sets the speed. kiddo (the crate the project
//! uses elsewhere) has no such grid, and its k-nearest query was slower than the tree
//! (`knn.rs`).

use std::sync::OnceLock;

use crate::knn::{d2, KnnTree};

/// At most this many cells (a dense grid of `u32` run starts: 16 MB); a finer cell size
/// than this allows is coarsened.
const MAX_CELLS: usize = 1 << 22;

/// A uniform grid over a fixed set of 3D points, with a k-d tree for the queries the grid
/// cannot answer alone.
pub struct KnnGrid {
    lo: [f64; 3],
    cell: f64,
    inv: f64,
    dims: [usize; 3],
    /// Run start of every cell in `points` (cells in x-fastest order), and the end.
    starts: Vec<u32>,
    /// The points' coordinates in cell order, one array per axis (so that a run's
    /// distances are computed several at a time).
    coords: [Vec<f64>; 3],
    ids: Vec<u32>,
    source: Vec<[f64; 3]>,
    tree: OnceLock<KnnTree>,
}

impl KnnGrid {
    /// The grid over `points` (finite coordinates) with cells about `cell` wide (coarser
    /// when that would make more than [`MAX_CELLS`] cells); ids are the points' indices.
    pub fn new(points: &[[f64; 3]], cell: f64) -> Self {
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in points {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        if points.is_empty() {
            (lo, hi) = ([0.0; 3], [0.0; 3]);
        }
        let extent = (0..3).map(|c| hi[c] - lo[c]).fold(0.0, f64::max).max(1e-12);
        let mut cell = if cell.is_finite() && cell > 0.0 { cell.max(extent * 1e-6) } else { extent };
        let dims_for = |cell: f64| [0, 1, 2].map(|c| (((hi[c] - lo[c]) / cell).floor() as usize + 1).max(1));
        let mut dims = dims_for(cell);
        while dims.iter().product::<usize>() > MAX_CELLS {
            cell *= 1.25;
            dims = dims_for(cell);
        }
        let inv = 1.0 / cell;
        let mut grid = KnnGrid {
            lo,
            cell,
            inv,
            dims,
            starts: Vec::new(),
            coords: [Vec::new(), Vec::new(), Vec::new()],
            ids: Vec::new(),
            source: points.to_vec(),
            tree: OnceLock::new(),
        };
        // Counting sort of the points by cell.
        let n_cells = dims.iter().product::<usize>();
        let keys: Vec<u32> = points.iter().map(|&p| grid.cell_id(grid.cell_of(p)) as u32).collect();
        let mut starts = vec![0u32; n_cells + 1];
        for &k in &keys {
            starts[k as usize + 1] += 1;
        }
        for i in 0..n_cells {
            starts[i + 1] += starts[i];
        }
        let mut fill = starts.clone();
        let mut order = vec![0u32; points.len()];
        for (i, &k) in keys.iter().enumerate() {
            order[fill[k as usize] as usize] = i as u32;
            fill[k as usize] += 1;
        }
        grid.coords = [0, 1, 2].map(|c| order.iter().map(|&i| points[i as usize][c]).collect());
        grid.ids = order;
        grid.starts = starts;
        grid
    }

    /// Cell width.
    pub fn cell(&self) -> f64 {
        self.cell
    }

    /// A key of x's cell (queries sorted by it read the grid in order).
    pub fn cell_key(&self, x: [f64; 3]) -> u64 {
        self.cell_id(self.cell_of(x)) as u64
    }

    fn cell_of(&self, x: [f64; 3]) -> [usize; 3] {
        [0, 1, 2].map(|c| {
            let f = ((x[c] - self.lo[c]) * self.inv).floor();
            if f.is_nan() || f < 0.0 {
                0
            } else {
                (f as usize).min(self.dims[c] - 1)
            }
        })
    }

    fn cell_id(&self, c: [usize; 3]) -> usize {
        (c[2] * self.dims[1] + c[1]) * self.dims[0] + c[0]
    }

    /// The `k` nearest points of `x` (fewer when there are fewer points) into `out` as
    /// (squared distance, index), sorted by squared distance and then index: exactly
    /// [`KnnTree::k_nearest`]'s answer. `buf` is scratch space. Returns whether the grid
    /// answered alone (`false`: the tree did).
    ///
    /// The block of 3 × 3 × 3 cells around x's cell is scanned and only the points nearer
    /// than the block's nearest wall are kept (no point outside the block is that near).
    /// When at least `k` are kept, the k nearest of them are the answer; else the 5³ block
    /// is scanned the same way, and so on up to [`MAX_RING`] cells from x's; then the tree
    /// answers. The keeping is branch-free (a scanned point is written and the count moves
    /// on only when it is near enough), so scanning costs a few cycles a point.
    pub fn k_nearest_with(&self, x: [f64; 3], k: usize, out: &mut Vec<(f64, u32)>, buf: &mut Vec<u128>) -> bool {
        out.clear();
        if k == 0 || self.ids.is_empty() {
            return true;
        }
        let c = self.cell_of(x);
        for ring in 1..=MAX_RING {
            let Some((from, to, wall)) = self.block(x, c, ring) else { continue };
            let whole = wall.is_infinite();
            // Kept: squared distance strictly below this (every point when the block is
            // the whole grid).
            let keep = if whole { f64::INFINITY } else { wall * wall * (1.0 - 1e-12) };
            buf.clear();
            for z in from[2]..=to[2] {
                for y in from[1]..=to[1] {
                    self.gather(x, keep, [from[0], y, z], to[0], buf);
                }
            }
            if buf.len() >= k || whole {
                // The k smallest by (distance, index): a selection, then a sort of those
                // (inserting each kept point in turn mispredicted a branch per shift), on
                // the integer keys of `key`.
                if buf.len() > k {
                    buf.select_nth_unstable(k - 1);
                    buf.truncate(k);
                }
                buf.sort_unstable();
                out.extend(buf.iter().map(|&key| (f64::from_bits((key >> 32) as u64), key as u32)));
                return true;
            }
        }
        self.tree.get_or_init(|| KnnTree::new(&self.source)).k_nearest(x, k, out);
        false
    }

    /// The block of cells within `ring` of cell `c` (x's): its first and last cell and
    /// the distance from x to its nearest wall, less a margin far above the rounding of
    /// `cell_of` and of the distances (infinite when the block is the whole grid: a wall at
    /// the grid's edge has no point beyond it). Every point outside the block is farther
    /// from x than that. `None` when x is within the margin of a wall.
    fn block(&self, x: [f64; 3], c: [usize; 3], ring: usize) -> Option<([usize; 3], [usize; 3], f64)> {
        const SLACK: f64 = 1e-9;
        let from = c.map(|v| v.saturating_sub(ring));
        let to = [0, 1, 2].map(|a| (c[a] + ring).min(self.dims[a] - 1));
        let mut wall = f64::INFINITY;
        for a in 0..3 {
            if from[a] > 0 {
                wall = wall.min(x[a] - (self.lo[a] + from[a] as f64 * self.cell));
            }
            if to[a] + 1 < self.dims[a] {
                wall = wall.min(self.lo[a] + (to[a] + 1) as f64 * self.cell - x[a]);
            }
        }
        if wall.is_infinite() {
            return Some((from, to, wall));
        }
        let wall = wall - SLACK;
        (wall > 0.0).then_some((from, to, wall))
    }

    /// Calls `f(squared distance, index)` for every point in the cells `from` … `to`.
    #[inline]
    fn scan(&self, x: [f64; 3], from: [usize; 3], to: [usize; 3], mut f: impl FnMut(f64, u32)) {
        let [px, py, pz] = &self.coords;
        for z in from[2]..=to[2] {
            for y in from[1]..=to[1] {
                for i in self.run([from[0], y, z], to[0]) {
                    f(d2(x, [px[i], py[i], pz[i]]), self.ids[i]);
                }
            }
        }
    }

    /// The soft-Voronoi kernel's candidate query ([`KnnTree::window`], answered on the
    /// grid): every point within `d_min + window` of `x`, d_min the nearest point's
    /// distance, into `out` as (index, distance) in no set order, and d_min. Distances
    /// are `d2(x, p).sqrt()`, as the tree computes them, so the set and the distances are
    /// the tree's. `None` (with `out` unspecified) when the blocks up to [`MAX_RING`]
    /// cells around x cannot tell: d_min + window reaches beyond them. `start` is a
    /// distance known to be ≥ d_min (a site's that was near x before, or infinity: none
    /// known): a block whose walls are nearer than `start + window` is likely not to tell
    /// and is skipped, and when every block is, the grid gives up at once.
    pub fn window(&self, x: [f64; 3], window: f64, start: f64, out: &mut Vec<(u32, f64)>) -> Option<f64> {
        if self.ids.is_empty() {
            return None;
        }
        let c = self.cell_of(x);
        for ring in 1..=MAX_RING {
            let Some((from, to, wall)) = self.block(x, c, ring) else { continue };
            if start.is_finite() && start + window >= wall {
                continue;
            }
            out.clear();
            let mut best = f64::INFINITY;
            // The tree's prefilter: squared distances above the padded square of the
            // current radius are certainly outside it.
            let mut r2 = f64::INFINITY;
            self.scan(x, from, to, |q, id| {
                if q > r2 {
                    return;
                }
                let d = q.sqrt();
                if d <= best + window {
                    out.push((id, d));
                    if d < best {
                        best = d;
                        r2 = crate::knn::pad2(best + window);
                    }
                }
            });
            if best + window < wall {
                out.retain(|c| c.1 <= best + window);
                return Some(best);
            }
        }
        None
    }

    /// The nearest point labelled `true` and the nearest labelled `false` (`labels` has
    /// one entry per point), each as (squared distance, index) with ties by index, as
    /// [`KnnTree::nearest_within`] finds them on each side's own tree. `None` when the
    /// blocks up to [`MAX_RING`] cells around x cannot tell (a side's nearest point may
    /// lie beyond them, or a side has none there). `reach`: a squared distance within
    /// which both are known to lie (or infinity); blocks whose walls are nearer are skipped,
    /// as in [`KnnGrid::window`].
    pub fn nearest_by_label(&self, x: [f64; 3], labels: &[bool], reach: f64) -> Option<[(f64, u32); 2]> {
        if self.ids.is_empty() {
            return None;
        }
        let c = self.cell_of(x);
        for ring in 1..=MAX_RING {
            let Some((from, to, wall)) = self.block(x, c, ring) else { continue };
            if reach.is_finite() && reach >= wall * wall {
                continue;
            }
            let mut best = [(f64::INFINITY, u32::MAX); 2];
            self.scan(x, from, to, |q, id| {
                let b = &mut best[usize::from(labels[id as usize])];
                if q < b.0 || (q == b.0 && id < b.1) {
                    *b = (q, id);
                }
            });
            // Nearer than every point beyond the walls (as in `k_nearest_with`).
            let keep = if wall.is_infinite() { f64::INFINITY } else { wall * wall * (1.0 - 1e-12) };
            if best.iter().all(|b| b.1 != u32::MAX && b.0 < keep) {
                return Some([best[1], best[0]]);
            }
        }
        None
    }

    /// [`KnnGrid::k_nearest_with`] with its own scratch space.
    pub fn k_nearest(&self, x: [f64; 3], k: usize, out: &mut Vec<(f64, u32)>) -> bool {
        self.k_nearest_with(x, k, out, &mut Vec::new())
    }

    /// The points of cells `from` … (`to_x`, from's y and z), one contiguous run of the
    /// points in cell order.
    #[inline]
    fn run(&self, from: [usize; 3], to_x: usize) -> std::ops::Range<usize> {
        self.starts[self.cell_id(from)] as usize..self.starts[self.cell_id([to_x, from[1], from[2]]) + 1] as usize
    }

    /// Appends to `buf` the points of cells `from` … (`to_x`, from's y and z) (one
    /// contiguous run) whose squared distance to x is below `keep`, as [`d2`] computes it.
    #[inline]
    fn gather(&self, x: [f64; 3], keep: f64, from: [usize; 3], to_x: usize, buf: &mut Vec<u128>) {
        let r = self.run(from, to_x);
        let [px, py, pz] = &self.coords;
        let (px, py, pz, ids) = (&px[r.clone()], &py[r.clone()], &pz[r.clone()], &self.ids[r]);
        let mut n = buf.len();
        buf.resize(n + ids.len(), 0);
        let slots = &mut buf[..];
        for i in 0..ids.len() {
            let d = d2(x, [px[i], py[i], pz[i]]);
            // Written always, kept only when near: no branch to mispredict.
            slots[n] = key(d, ids[i]);
            n += usize::from(d < keep);
        }
        buf.truncate(n);
    }
}

/// A kept point as one integer that orders as (squared distance, index) does: the bits of a
/// non-negative f64 order as its value, so the selection and the sort compare integers
/// (faster than `total_cmp` and then the index, measured on the polish).
#[inline]
fn key(d: f64, id: u32) -> u128 {
    (u128::from(d.to_bits()) << 32) | u128::from(id)
}

/// Rings of cells a query scans before it asks the tree.
const MAX_RING: usize = 2;

/// A cell width for queries of the `k` nearest of `points` among `sites`: the 80th
/// percentile of the k-th nearest distance over at most 2,000 of the points, evenly
/// strided (deterministic). About one in five queries then falls back to the tree at
/// worst (a query's walls are at least a cell away).
pub fn cell_for(sites: &[[f64; 3]], points: &[[f64; 3]], k: usize) -> f64 {
    if sites.is_empty() || points.is_empty() || k == 0 {
        return f64::INFINITY;
    }
    let tree = KnnTree::new(sites);
    let stride = points.len().div_ceil(2000).max(1);
    let mut out = Vec::new();
    let mut d: Vec<f64> = points
        .iter()
        .step_by(stride)
        .filter_map(|&x| {
            tree.k_nearest(x, k, &mut out);
            out.last().map(|c| c.0.sqrt())
        })
        .collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() * 4 / 5).copied().unwrap_or(f64::INFINITY)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn coord() -> impl Strategy<Value = f64> {
        // Coarse values make many exact ties, duplicates and points on cell walls.
        prop_oneof![(0i32..8).prop_map(|v| v as f64 / 8.0), 0.0f64..1.0, -0.5f64..1.5]
    }

    proptest! {
        #[test]
        fn equals_the_tree(
            points in prop::collection::vec([coord(), coord(), coord()], 1..300),
            queries in prop::collection::vec([coord(), coord(), coord()], 1..20),
            k in 1usize..16,
            cell in prop_oneof![Just(0.125), 0.01f64..0.5],
        ) {
            let tree = KnnTree::new(&points);
            let grid = KnnGrid::new(&points, cell);
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for &x in &queries {
                tree.k_nearest(x, k, &mut a);
                grid.k_nearest(x, k, &mut b);
                prop_assert_eq!(&a, &b);
            }
        }
    }

    proptest! {
        /// The kernel's candidate query: whenever the grid answers, it is the tree's answer
        /// (the same nearest distance, the same sites at the same distances), whatever the
        /// start distance it was given.
        #[test]
        fn window_equals_the_tree(
            points in prop::collection::vec([coord(), coord(), coord()], 1..300),
            queries in prop::collection::vec([coord(), coord(), coord()], 1..20),
            window in prop_oneof![Just(0.0), 0.0f64..0.2],
            cell in prop_oneof![Just(0.125), 0.01f64..0.5],
            hint in 0usize..300,
        ) {
            let tree = KnnTree::new(&points);
            let grid = KnnGrid::new(&points, cell);
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for &x in &queries {
                let mut kn = Vec::new();
                tree.k_nearest(x, 1, &mut kn);
                let nearest = kn[0].0.sqrt();
                let start = d2(x, points[hint % points.len()]).sqrt();
                for start in [nearest, start, f64::INFINITY] {
                    let da = tree.window(x, window, start, &mut a);
                    if let Some(db) = grid.window(x, window, start, &mut b) {
                        a.sort_unstable_by_key(|c| c.0);
                        b.sort_unstable_by_key(|c| c.0);
                        prop_assert_eq!(da, db);
                        prop_assert_eq!(&a, &b);
                    }
                }
            }
        }

        /// The nearest site of each label: whenever the grid answers, it is what each side's
        /// own tree finds (ties by index).
        #[test]
        fn nearest_by_label_equals_the_trees(
            points in prop::collection::vec(([coord(), coord(), coord()], any::<bool>()), 1..300),
            queries in prop::collection::vec([coord(), coord(), coord()], 1..20),
            cell in prop_oneof![Just(0.125), 0.01f64..0.5],
        ) {
            let sites: Vec<[f64; 3]> = points.iter().map(|p| p.0).collect();
            let labels: Vec<bool> = points.iter().map(|p| p.1).collect();
            let side = |l: bool| -> (Vec<u32>, KnnTree) {
                let ids: Vec<u32> = (0..sites.len() as u32).filter(|&i| labels[i as usize] == l).collect();
                let tree = KnnTree::new(&ids.iter().map(|&i| sites[i as usize]).collect::<Vec<_>>());
                (ids, tree)
            };
            let (inside, outside) = (side(true), side(false));
            let grid = KnnGrid::new(&sites, cell);
            for &x in &queries {
                for reach in [f64::INFINITY, 0.01, 1e-6] {
                    if let Some([a, b]) = grid.nearest_by_label(x, &labels, reach) {
                        for ((ids, tree), got) in [(&inside, a), (&outside, b)] {
                            let (d, local) = tree.nearest_within(x, f64::INFINITY).unwrap();
                            prop_assert_eq!((d, ids[local as usize]), got);
                        }
                    }
                }
            }
        }
    }

    /// On evenly spread points with the cell from [`cell_for`], most queries never reach
    /// the tree (so the grid is doing the work, not the fallback).
    #[test]
    fn the_grid_answers_most_queries_alone() {
        let mut s = 1u64;
        let mut r = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let sites: Vec<[f64; 3]> = (0..4000).map(|_| [r(), r(), r()]).collect();
        let queries: Vec<[f64; 3]> = (0..4000).map(|_| [r(), r(), r()]).collect();
        let grid = KnnGrid::new(&sites, cell_for(&sites, &queries, 11));
        let tree = KnnTree::new(&sites);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        let mut alone = 0;
        for &x in &queries {
            alone += usize::from(grid.k_nearest(x, 11, &mut a));
            tree.k_nearest(x, 11, &mut b);
            assert_eq!(a, b);
        }
        assert!(alone > 3000, "the grid answered {alone} of 4000 alone");
        // The kernel's candidate query with a narrow window, started from the nearest
        // distance as a hint gives it: the grid answers most alone too.
        let mut out = Vec::new();
        let answered = queries
            .iter()
            .filter(|&&x| {
                tree.k_nearest(x, 1, &mut b);
                grid.window(x, 1e-3, b[0].0.sqrt(), &mut out).is_some()
            })
            .count();
        assert!(answered > 3000, "the grid answered {answered} of 4000 window queries");
    }
}
