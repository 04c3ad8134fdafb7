//! Where the sites start ([`crate::Init`]) and the fixed outside sites on the faces of the
//! unit cube that bound every Voronoi cell.

use vf_common::rng::{ChunkRng, Stream};

use crate::config::Density;
use crate::data::TrainingData;
use crate::error::TrainError;
use crate::kernel::SiteIndex;
use crate::losses::Solid;

/// Distance of the boundary sites from the faces of the unit cube (they must lie
/// strictly inside it for the crust).
pub const BOUNDARY_INSET: f64 = 1e-3;

/// Projects sites into [1e-9, 1 − 1e-9]³; returns them, their labels and the number moved.
pub fn project_sites(sites: &[[f64; 3]], labels: &[bool]) -> (Vec<[f64; 3]>, Vec<bool>, usize) {
    const EPS: f64 = 1e-9;
    let mut moved = 0;
    let out = sites
        .iter()
        .map(|p| {
            let q = p.map(|x| x.clamp(EPS, 1.0 - EPS));
            moved += (q != *p) as usize;
            q
        })
        .collect();
    (out, labels.to_vec(), moved)
}

/// The paper's initialisation: K uniform points in the unit cube, alternately labelled
/// inside (even k) and outside (odd k).
pub fn paper_init(k: usize, seed: u64) -> (Vec<[f64; 3]>, Vec<bool>) {
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 0);
    let sites = (0..k).map(|_| [rng.uniform(), rng.uniform(), rng.uniform()]).collect();
    let labels = (0..k).map(|i| i % 2 == 0).collect();
    (sites, labels)
}

/// K distinct training samples chosen at random (partial Fisher–Yates), with their
/// ground-truth labels.
///
/// # Errors
/// [`TrainError::Data`] when the pool has fewer distinct points than K.
pub fn samples_init(k: usize, data: &TrainingData, seed: u64) -> Result<(Vec<[f64; 3]>, Vec<bool>), TrainError> {
    let n = data.points.len();
    if n < k {
        return Err(TrainError::Data(format!("{n} training samples cannot seed {k} sites; sample more points")));
    }
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 1);
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut sites = Vec::with_capacity(k);
    let mut labels = Vec::with_capacity(k);
    let mut seen = std::collections::HashSet::with_capacity(k);
    let mut i = 0;
    while sites.len() < k && i < n {
        let j = i + (rng.next_u64() % (n - i) as u64) as usize;
        order.swap(i, j);
        let s = order[i] as usize;
        i += 1;
        let p = data.points[s];
        if seen.insert(p.map(f64::to_bits)) {
            sites.push(p);
            labels.push(data.occupancy[s]);
        }
    }
    if sites.len() < k {
        return Err(TrainError::Data(format!("only {} distinct training samples for {k} sites", sites.len())));
    }
    Ok((sites, labels))
}

/// Pairs of sites straddling the surface: K/2 surface points p (drawn from
/// `data.surface`), each giving sites p ± h·n along its normal, h = `offset` × the mean
/// distance from a chosen surface point to the nearest other one (the pair spacing). Labels come from the solid, so flipped or missing normals only cost accuracy.
/// The Voronoi face between the two sites of a pair is close to the tangent plane at p.
///
/// # Errors
/// [`TrainError::Data`] when there are fewer than K/2 surface points.
pub fn surface_init(
    k: usize,
    data: &TrainingData,
    solid: &dyn Solid,
    offset: f64,
    seed: u64,
) -> Result<(Vec<[f64; 3]>, Vec<bool>), TrainError> {
    let pairs = k / 2;
    let n = data.surface.len();
    if n < pairs.max(2) || data.normals.len() != n {
        return Err(TrainError::Data(format!("{n} surface samples (with normals) cannot seed {pairs} site pairs")));
    }
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 2);
    let mut order: Vec<u32> = (0..n as u32).collect();
    for i in 0..pairs {
        let j = i + (rng.next_u64() % (n - i) as u64) as usize;
        order.swap(i, j);
    }
    let chosen: Vec<[f64; 3]> = order[..pairs].iter().map(|&i| data.surface[i as usize]).collect();
    // Mean nearest-neighbour distance among the chosen surface points.
    let index = SiteIndex::new(&chosen);
    let mut spacing = 0.0;
    let mut count = 0usize;
    let mut cands = Vec::new();
    for &p in &chosen {
        index.candidates(&chosen, p, 0.1, &mut cands);
        let d = cands.iter().map(|c| c.1).filter(|&d| d > 0.0).fold(f64::INFINITY, f64::min);
        if d.is_finite() {
            spacing += d;
            count += 1;
        }
    }
    let h = if count > 0 { offset * spacing / count as f64 } else { 1e-3 };
    let mut sites = Vec::with_capacity(2 * pairs + (k - 2 * pairs));
    for &i in &order[..pairs] {
        let (p, nrm) = (data.surface[i as usize], data.normals[i as usize]);
        // Each site is jittered by up to 0.3·h in every direction: exactly mirrored pairs
        // make neighbouring pairs (nearly) cospherical, and the nearly coincident Voronoi
        // vertices that follow cannot be told apart in f64 output.
        for sign in [1.0, -1.0] {
            let j = [0, 1, 2].map(|_| 0.3 * h * (2.0 * rng.uniform() - 1.0));
            sites.push([0, 1, 2].map(|c| p[c] + sign * h * nrm[c] + j[c]));
        }
    }
    if sites.len() < k {
        // Odd K: one more site from the training samples.
        sites.push(data.points[(rng.next_u64() % data.points.len() as u64) as usize]);
    }
    let labels = solid.locate(&sites).iter().map(|l| l.inside).collect();
    Ok((sites, labels))
}

/// About `count` outside sites on a regular m×m grid on each face of the unit cube, set
/// [`BOUNDARY_INSET`] inside it (m = ⌈√(count/6)⌉, so 6m² ≥ count; none when count = 0).
pub fn boundary_sites(count: usize) -> Vec<[f64; 3]> {
    let Some(m) = boundary_grid_size(count) else {
        return Vec::new();
    };
    let mut out = Vec::with_capacity(6 * m * m);
    for axis in 0..3 {
        for &face in &[BOUNDARY_INSET, 1.0 - BOUNDARY_INSET] {
            for i in 0..m {
                for j in 0..m {
                    let u = (i as f64 + 0.5) / m as f64;
                    let v = (j as f64 + 0.5) / m as f64;
                    let mut p = [0.0; 3];
                    p[axis] = face;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    out.push(p);
                }
            }
        }
    }
    out
}

/// Side m of the per-face grid for about `count` boundary sites (`None` for none).
pub fn boundary_grid_size(count: usize) -> Option<usize> {
    (count > 0).then(|| ((count as f64 / 6.0).sqrt().ceil() as usize).max(1))
}

/// What [`pairs_init`] returns: the sites, their labels and r0, the uniform spacing of the
/// pairs away from thin parts (unit-cube lengths).
pub type PairsInit = (Vec<[f64; 3]>, Vec<bool>, f64);

/// Well-spread mirrored pairs: about K/2 surface points chosen by greedy Poisson-disk
/// sampling (a minimum distance r found by bisection so the count is K/2; candidates are
/// the first 12·K of `data.surface`, already area-uniform and random), each giving the
/// sites p ± δ·n with δ = `offset` × r. Where both sites of a pair land on the same side of
/// the solid (a part thinner than 2δ, or a crease), δ is halved up to three times, so thin
/// parts keep one site on each side. Labels come from the solid.
///
/// Returns the sites, their labels and r0 (the uniform spacing of the pairs away from thin
/// parts, unit-cube lengths).
///
/// # Errors
/// [`TrainError::Data`] when there are fewer than K/2 surface points.
pub fn pairs_init(
    k: usize,
    data: &TrainingData,
    solid: &dyn Solid,
    offset: f64,
    density: Density,
    seed: u64,
) -> Result<PairsInit, TrainError> {
    pairs_init_refined(k, data, solid, offset, density, seed, &[])
}

/// [`pairs_init`] with pairs twice as dense where `refine` is true: `refine[i]` flags the
/// candidate `data.surface[i]` (the first min(12·K, #surface) are candidates; a shorter
/// slice leaves the rest unflagged). Used to grow K where a previous fit's error was
/// (`fit`'s accuracy target).
///
/// # Errors
/// As [`pairs_init`].
pub fn pairs_init_refined(
    k: usize,
    data: &TrainingData,
    solid: &dyn Solid,
    offset: f64,
    density: Density,
    seed: u64,
    refine: &[bool],
) -> Result<PairsInit, TrainError> {
    let pairs = k / 2;
    let n = data.surface.len();
    if n < pairs.max(2) || data.normals.len() != n {
        return Err(TrainError::Data(format!("{n} surface samples (with normals) cannot seed {pairs} site pairs")));
    }
    let m = n.min(12 * k.max(1));
    let candidates = &data.surface[..m];
    // A uniform spacing first, then a cap on each candidate's spacing where the part is
    // thinner (or the surface more folded) than the pairs would be wide there.
    let (_, r0) = poisson_subset(candidates, pairs);
    let (mut cap, thin) = match density {
        Density::Adaptive => feature_caps(candidates, &data.normals[..m], solid, r0, offset),
        Density::Uniform => (vec![f64::INFINITY; m], vec![false; m]),
    };
    for (c, _) in cap.iter_mut().zip(refine).filter(|(_, &r)| r) {
        *c = c.min(0.5 * r0);
    }
    let (chosen, spacing) = adaptive_subset(candidates, &cap, &thin, r0, pairs);
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 3);
    let mut delta: Vec<f64> = spacing.iter().map(|&h| offset * h).collect();
    let mut sites = vec![[0.0; 3]; 2 * chosen.len()];
    let place = |sites: &mut [[f64; 3]], delta: &[f64], which: &[usize]| {
        for &i in which {
            let (p, nrm) = (data.surface[chosen[i] as usize], data.normals[chosen[i] as usize]);
            sites[2 * i] = [0, 1, 2].map(|c| (p[c] + delta[i] * nrm[c]).clamp(1e-6, 1.0 - 1e-6));
            sites[2 * i + 1] = [0, 1, 2].map(|c| (p[c] - delta[i] * nrm[c]).clamp(1e-6, 1.0 - 1e-6));
        }
    };
    let all: Vec<usize> = (0..chosen.len()).collect();
    place(&mut sites, &delta, &all);
    let mut located = solid.locate(&sites);
    // Each site must sit on its own side with p as (nearly) its closest surface point: a
    // site that crossed a thin part, or came closer to another part of the surface than
    // to p (δ beyond the local feature size), has its pair's δ halved, up to five times.
    for _ in 0..5 {
        let ok = |j: usize| {
            let d = crate::kernel::distance(sites[j], located[j].closest);
            d >= 0.7 * delta[j / 2]
        };
        let bad: Vec<usize> = (0..chosen.len())
            .filter(|&i| located[2 * i].inside == located[2 * i + 1].inside || !ok(2 * i) || !ok(2 * i + 1))
            .collect();
        if bad.is_empty() {
            break;
        }
        bad.iter().for_each(|&i| delta[i] *= 0.5);
        place(&mut sites, &delta, &bad);
        let moved: Vec<[f64; 3]> = bad.iter().flat_map(|&i| [sites[2 * i], sites[2 * i + 1]]).collect();
        for (j, l) in solid.locate(&moved).into_iter().enumerate() {
            located[2 * bad[j / 2] + j % 2] = l;
        }
    }
    let labels: Vec<bool> = located.iter().map(|l| l.inside).collect();
    let mut kept_sites = Vec::with_capacity(k);
    let mut kept_labels = Vec::with_capacity(k);
    let columns = thin_columns(data, &chosen, &delta, &labels, solid, r0, offset, k);
    for column in columns.values().flatten() {
        kept_sites.extend_from_slice(column);
        kept_labels.extend(solid.inside(column));
    }
    // A pair whose sites still share a side (a crease, a hole, a part thinner than δ/8)
    // would put a site of one label among the other's, which grows a spike of crust: keep
    // one of its sites only.
    for i in 0..chosen.len() {
        if columns.contains_key(&i) {
            continue;
        }
        let both = labels[2 * i] != labels[2 * i + 1];
        for j in [2 * i, 2 * i + 1].into_iter().take(if both { 2 } else { 1 }) {
            kept_sites.push(sites[j]);
            kept_labels.push(labels[j]);
        }
    }
    let (mut sites, mut labels) = (kept_sites, kept_labels);
    sites.truncate(k);
    labels.truncate(k);
    while sites.len() < k {
        // Odd K, too few well-spread points or dropped sites: training samples fill up,
        // with their ground truth.
        let i = (rng.next_u64() % data.points.len() as u64) as usize;
        sites.push(data.points[i]);
        labels.push(data.occupancy[i]);
    }
    Ok((sites, labels, r0))
}

/// Columns across thin parts: where a pair's spacing or δ had to shrink (the part is
/// thinner than the pair was wide), the part's thickness w along the inward normal at p is
/// found (doubling, then bisection, of the solid's inside test) and the pair is replaced by
/// a column: inside at p + (w/2)·u (the middle), outside at its mirror images across both
/// faces, p − (w/2)·u and p + (3w/2)·u. Each face is then exactly the bisector of the middle
/// site and its mirror, and as every column carries both, a flat plate comes out flat
/// whatever the spacing (mirrored pairs from its two faces do not line up, and crumple it).
/// A column costs 3 sites against a pair's 2, so about two thirds of the thin pairs become
/// columns (a well-spread subset of them) and the rest are dropped, keeping K.
/// Returns pair index → its column, or `None` for a dropped pair.
#[allow(clippy::too_many_arguments)]
fn thin_columns(
    data: &TrainingData,
    chosen: &[u32],
    delta: &[f64],
    labels: &[bool],
    solid: &dyn Solid,
    r0: f64,
    offset: f64,
    k: usize,
) -> std::collections::BTreeMap<usize, Option<[[f64; 3]; 3]>> {
    let thin: Vec<usize> =
        (0..chosen.len()).filter(|&i| labels[2 * i] != labels[2 * i + 1] && delta[i] < 0.99 * offset * r0).collect();
    // Inward unit normal and the known inside depth of each thin pair.
    let frame: Vec<([f64; 3], [f64; 3])> = thin
        .iter()
        .map(|&i| {
            let (p, n) = (data.surface[chosen[i] as usize], data.normals[chosen[i] as usize]);
            let u = if labels[2 * i] { n } else { n.map(|x| -x) };
            (p, u)
        })
        .collect();
    let at = |j: usize, t: f64| [0, 1, 2].map(|c| (frame[j].0[c] + t * frame[j].1[c]).clamp(1e-6, 1.0 - 1e-6));
    let mut lo: Vec<f64> = thin.iter().map(|&i| delta[i]).collect();
    let mut hi: Vec<f64> = lo.iter().map(|&d| 2.0 * d).collect();
    let mut open: Vec<usize> = (0..thin.len()).collect();
    let mut bracketed = vec![false; thin.len()];
    for _ in 0..6 {
        if open.is_empty() {
            break;
        }
        let probes: Vec<[f64; 3]> = open.iter().map(|&j| at(j, hi[j])).collect();
        let inside = solid.inside(&probes);
        let mut still = Vec::new();
        for (&j, &ins) in open.iter().zip(&inside) {
            if ins {
                lo[j] = hi[j];
                hi[j] *= 2.0;
                still.push(j);
            } else {
                bracketed[j] = true;
            }
        }
        open = still;
    }
    let mut which: Vec<usize> = (0..thin.len()).filter(|&j| bracketed[j]).collect();
    for _ in 0..10 {
        let probes: Vec<[f64; 3]> = which.iter().map(|&j| at(j, 0.5 * (lo[j] + hi[j]))).collect();
        for (&j, ins) in which.iter().zip(solid.inside(&probes)) {
            let mid = 0.5 * (lo[j] + hi[j]);
            if ins {
                lo[j] = mid;
            } else {
                hi[j] = mid;
            }
        }
    }
    // Only parts thinner than the pair was meant to be wide become columns.
    which.retain(|&j| 0.5 * (lo[j] + hi[j]) < 2.0 * offset * r0);
    let budget = k.saturating_sub(2 * (chosen.len() - which.len())) / 3;
    // The columns kept are a well-spread subset of the thin pairs' feet (Poisson-disk, the
    // widest spacing that leaves `budget`), not the first ones in the pairs' order: that
    // order puts the pairs rescued onto the thinnest parts last, so it dropped them all
    // when the budget ran short (a slatted chair at K = 2,048: 108 pairs on its slats, 0
    // kept, and the slats were lost).
    let kept: std::collections::HashSet<u32> = if which.len() > budget {
        let feet: Vec<[f64; 3]> = which.iter().map(|&j| frame[j].0).collect();
        poisson_subset(&feet, budget).0.into_iter().collect()
    } else {
        (0..which.len() as u32).collect()
    };
    which
        .into_iter()
        .enumerate()
        .map(|(n, j)| {
            let w = 0.5 * (lo[j] + hi[j]);
            (thin[j], kept.contains(&(n as u32)).then(|| [at(j, 0.5 * w), at(j, -0.5 * w), at(j, 1.5 * w)]))
        })
        .collect()
}

/// Greedy Poisson-disk subset of `points` (in order) with `target` points: r is bisected
/// (on a log scale, 20 rounds) for the largest r giving at least `target` points, and the
/// first `target` accepted points are returned with r.
pub fn poisson_subset(points: &[[f64; 3]], target: usize) -> (Vec<u32>, f64) {
    let (mut lo, mut hi) = (1e-6f64, 1.0f64);
    let mut best = (0..target.min(points.len()) as u32).collect::<Vec<_>>();
    let mut best_r = 0.0;
    for _ in 0..20 {
        let r = (lo * hi).sqrt();
        let got = greedy_disk(points, r);
        if got.len() >= target {
            lo = r;
            best = got;
            best_r = r;
        } else {
            hi = r;
        }
    }
    best.truncate(target);
    (best, best_r)
}

/// Points of `points`, in order, kept when no kept point lies within `r` (a uniform grid
/// of cells of side ≥ r over the unit cube, 27 neighbouring cells checked).
pub fn greedy_disk(points: &[[f64; 3]], r: f64) -> Vec<u32> {
    greedy_disk_around(&[], points, r)
}

/// [`greedy_disk`] with `seeds` kept before any of `points` (only indices of `points` are
/// returned).
pub fn greedy_disk_around(seeds: &[[f64; 3]], points: &[[f64; 3]], r: f64) -> Vec<u32> {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for p in seeds.iter().chain(points) {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    if lo[0] > hi[0] {
        return Vec::new();
    }
    let mut grid = DiskGrid::within(r, lo, hi);
    seeds.iter().for_each(|&p| grid.insert(p));
    let mut kept = Vec::new();
    for (i, &p) in points.iter().enumerate() {
        if !grid.any_within(p) {
            grid.insert(p);
            kept.push(i as u32);
        }
    }
    kept
}

/// Points in the unit cube bucketed in a uniform grid of cells of side ≥ r, so every point
/// within r of a query lies in one of the 27 cells around it.
struct DiskGrid {
    /// Cells along each axis, over [lo, lo + extent].
    m: [usize; 3],
    lo: [f64; 3],
    extent: [f64; 3],
    r2: f64,
    head: Vec<u32>,
    next: Vec<u32>,
    placed: Vec<[f64; 3]>,
}

impl DiskGrid {
    fn new(r: f64) -> Self {
        DiskGrid::within(r, [0.0; 3], [1.0; 3])
    }

    /// A grid over the box [lo, hi] only (points outside fall in its border cells): a thin
    /// shell's rim or a flat sheet fills a sliver of the unit cube, and a grid of the whole
    /// cube at a small r cost 67 MB to clear per pass (most of a shell's layout time).
    fn within(r: f64, lo: [f64; 3], hi: [f64; 3]) -> Self {
        let extent = [0, 1, 2].map(|i| (hi[i] - lo[i]).max(0.0));
        let m = extent.map(|e| ((e / r).floor() as usize).clamp(1, 256));
        let cells = m[0] * m[1] * m[2];
        DiskGrid { m, lo, extent, r2: r * r, head: vec![u32::MAX; cells], next: Vec::new(), placed: Vec::new() }
    }

    fn cell(&self, p: [f64; 3]) -> [isize; 3] {
        [0, 1, 2].map(|i| {
            let t = if self.extent[i] > 0.0 { (p[i] - self.lo[i]) / self.extent[i] } else { 0.0 };
            ((t * self.m[i] as f64) as isize).clamp(0, self.m[i] as isize - 1)
        })
    }

    fn slot(&self, c: [isize; 3]) -> usize {
        (c[0] as usize * self.m[1] + c[1] as usize) * self.m[2] + c[2] as usize
    }

    fn insert(&mut self, p: [f64; 3]) {
        let h = self.slot(self.cell(p));
        self.next.push(self.head[h]);
        self.head[h] = self.placed.len() as u32;
        self.placed.push(p);
    }

    /// Whether a placed point lies strictly within r of `p`.
    fn any_within(&self, p: [f64; 3]) -> bool {
        self.count_within(p, 1) > 0
    }

    /// How many placed points lie strictly within r of `p`, counting up to `limit`.
    fn count_within(&self, p: [f64; 3], limit: usize) -> usize {
        let mut count = 0;
        let c = self.cell(p);
        for dx in -1..=1isize {
            for dy in -1..=1isize {
                for dz in -1..=1isize {
                    let q = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if (0..3).any(|i| q[i] < 0 || q[i] >= self.m[i] as isize) {
                        continue;
                    }
                    let mut j = self.head[self.slot(q)];
                    while j != u32::MAX {
                        let o = self.placed[j as usize];
                        let d2 = (o[0] - p[0]).powi(2) + (o[1] - p[1]).powi(2) + (o[2] - p[2]).powi(2);
                        if d2 < self.r2 {
                            count += 1;
                            if count >= limit {
                                return count;
                            }
                        }
                        j = self.next[j as usize];
                    }
                }
            }
        }
        count
    }
}

/// For each surface point p (normal n), the largest spacing h in r0, r0/2, …, r0/16 whose
/// pair p ± offset·h·n has one site on each side of the solid and p (nearly) closest to
/// both: infinity where r0 itself passes (no cap), else that h. Thin parts and tight folds
/// get proportionally more, closer pairs, so they do not grow spikes. Also whether each
/// point is on a part thinner than the r0 pair is wide (both its sites outside).
fn feature_caps(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    solid: &dyn Solid,
    r0: f64,
    offset: f64,
) -> (Vec<f64>, Vec<bool>) {
    let mut cap = vec![f64::INFINITY; points.len()];
    let mut thin = vec![false; points.len()];
    let mut open: Vec<usize> = (0..points.len()).collect();
    let mut h = r0;
    for level in 0..5 {
        if open.is_empty() {
            break;
        }
        let delta = offset * h;
        let probes: Vec<[f64; 3]> = open
            .iter()
            .flat_map(|&i| {
                let (p, n) = (points[i], normals[i]);
                [1.0, -1.0].map(|s| [0, 1, 2].map(|c| p[c] + s * delta * n[c]))
            })
            .collect();
        let located = solid.locate(&probes);
        let mut still = Vec::new();
        for (j, &i) in open.iter().enumerate() {
            let (a, b) = (&located[2 * j], &located[2 * j + 1]);
            let good = a.inside != b.inside
                && crate::kernel::distance(probes[2 * j], a.closest) >= 0.7 * delta
                && crate::kernel::distance(probes[2 * j + 1], b.closest) >= 0.7 * delta;
            if level == 0 {
                // Both sites outside: the part is thinner than 2δ across p.
                thin[i] = !a.inside && !b.inside;
            }
            if good {
                if level > 0 {
                    cap[i] = h;
                }
            } else {
                still.push(i);
            }
        }
        open = still;
        h *= 0.5;
    }
    for i in open {
        cap[i] = 2.0 * h;
    }
    (cap, thin)
}

/// About `target` well-spread points of `points` with their spacing: where `cap` is finite
/// (thin parts, folds, sharp creases) a Poisson-disk subset at that spacing, one pass per
/// cap level; elsewhere a Poisson-disk subset at the uniform spacing that makes up the
/// rest of the count. Capped regions take at most half the budget unless the rest has too
/// few candidates (a thin plate is all capped region).
///
/// The levels are taken widest first until the allowance runs out, so a thin part (the
/// smallest caps) may get nothing, and a thin part without sites is lost (at K = 2,048 a
/// box's creases took the whole allowance and its 1%-thick fin started, and ended, without
/// a site). So then points on parts thinner than the pairs (`thin`, and at least half of
/// the candidates within `r0`) farther than the uniform spacing `r0` from every point taken
/// get a greedy pass at `r0`, and so do the other capped points within 2·r0 of those (the
/// part's rim), before the rest of the surface. Where every thin part already has points,
/// nothing changes.
fn adaptive_subset(points: &[[f64; 3]], cap: &[f64], thin: &[bool], r0: f64, target: usize) -> (Vec<u32>, Vec<f64>) {
    let mut levels: Vec<f64> = cap.iter().copied().filter(|c| c.is_finite()).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup();
    // Thin regions take at most half the budget, unless the rest of the surface has too few
    // candidates to fill the other half (a thin plate is all thin region).
    let free: Vec<u32> = (0..points.len() as u32).filter(|&i| cap[i as usize].is_infinite()).collect();
    let keep = (target / 2).max(target.saturating_sub(free.len()));
    let mut chosen = Vec::new();
    let mut spacing = Vec::new();
    for &h in levels.iter().rev() {
        let ids: Vec<u32> = (0..points.len() as u32).filter(|&i| cap[i as usize] == h).collect();
        let pts: Vec<[f64; 3]> = ids.iter().map(|&i| points[i as usize]).collect();
        let got = greedy_disk(&pts, h);
        let room = keep - chosen.len();
        if got.len() <= room {
            for j in got {
                chosen.push(ids[j as usize]);
                spacing.push(h);
            }
        } else {
            // More than the allowance at this spacing: spread the allowance evenly over the
            // level instead (a wider Poisson-disk spacing), rather than cut a random subset.
            let (even, r) = poisson_subset(&pts, room);
            for j in even {
                chosen.push(ids[j as usize]);
                spacing.push(r.max(h));
            }
            break;
        }
    }
    // Thin parts left without points get them at the uniform spacing (they become columns,
    // which hold at any spacing), then the other capped points within 2·r0 of those (the
    // part's rim and edges: without pairs there, its inside cells run on past the rim).
    // Only where thin points are at least half of the candidates within r0: a part, not a
    // crease or a hole's rim where the pair happened to cross the solid (pairs rescued
    // there, with δ far below their spacing, grew spikes on featuretype).
    let thin_ids: Vec<u32> = {
        let (mut all, mut thin_grid) = (DiskGrid::new(r0), DiskGrid::new(r0));
        for (i, &p) in points.iter().enumerate() {
            all.insert(p);
            if thin[i] && cap[i].is_finite() {
                thin_grid.insert(p);
            }
        }
        (0..points.len() as u32)
            .filter(|&i| thin[i as usize] && cap[i as usize].is_finite())
            .filter(|&i| {
                let p = points[i as usize];
                2 * thin_grid.count_within(p, usize::MAX) >= all.count_within(p, usize::MAX)
            })
            .collect()
    };
    let mut taken: Vec<[f64; 3]> = chosen.iter().map(|&i| points[i as usize]).collect();
    let pts: Vec<[f64; 3]> = thin_ids.iter().map(|&i| points[i as usize]).collect();
    let rescued: Vec<[f64; 3]> = greedy_disk_around(&taken, &pts, r0)
        .into_iter()
        .map(|j| {
            chosen.push(thin_ids[j as usize]);
            spacing.push(r0);
            pts[j as usize]
        })
        .collect();
    if !rescued.is_empty() {
        let mut near = DiskGrid::new(2.0 * r0);
        rescued.iter().for_each(|&p| near.insert(p));
        let rim: Vec<u32> = (0..points.len() as u32)
            .filter(|&i| !thin[i as usize] && cap[i as usize].is_finite() && near.any_within(points[i as usize]))
            .collect();
        taken.extend_from_slice(&rescued);
        let pts: Vec<[f64; 3]> = rim.iter().map(|&i| points[i as usize]).collect();
        for j in greedy_disk_around(&taken, &pts, r0) {
            chosen.push(rim[j as usize]);
            spacing.push(r0);
        }
    }
    let pts: Vec<[f64; 3]> = free.iter().map(|&i| points[i as usize]).collect();
    let rest = target.saturating_sub(chosen.len());
    if rest > 0 && !pts.is_empty() {
        let (base, r) = poisson_subset(&pts, rest);
        for j in base {
            chosen.push(free[j as usize]);
            spacing.push(r);
        }
    }
    (chosen, spacing)
}
