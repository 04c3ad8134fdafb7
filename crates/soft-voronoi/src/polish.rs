//! The surface polish: after training, the sites are moved so that the Voronoi faces pass
//! through the surface samples, with VoroMesh's loss (Maruani, Klokov, Ovsjanikov, Alliez,
//! Desbrun, "VoroMesh: Learning Watertight Surface Meshes with Voronoi Diagrams", ICCV
//! 2023, §4.1).
//!
//! For a surface sample x with nearest site p_i, VoroLoss is the squared distance from x to
//! the boundary of p_i's cell, taken as the smallest squared distance to the bisector planes
//! of p_i and its next-nearest sites p_j (10 of them, as in the paper's code):
//!
//! ```text
//! e = p_j − p_i,  u = e/|e|,  r = x − (p_i + p_j)/2,  d_j = r·u,   loss = mean_x min_j d_j²
//! ```
//!
//! The loss does not look at labels: it only pulls faces of the diagram onto the surface,
//! and the fit labels the sites by the solid afterwards (`fit`'s relabelling). The seed's
//! soft-Voronoi training ([`crate::Trainer`]) still runs first; the polish starts from its
//! result. Why it is there: the soft-Voronoi losses measure occupancy, whose gradient lives
//! within ~1/β of the crust, so they place the crust but hardly orient its faces; the
//! bisector distance is a direct, dense signal on every face near the surface. Measured on
//! the quality benchmark it raises normal consistency and lowers Chamfer on every mesh
//! (docs/quality.md).
//!
//! The neighbours are found exactly on a uniform grid ([`crate::grid::KnnGrid`], with
//! [`crate::knn::KnnTree`] behind it) and held fixed for the gradient, as in the paper;
//! the gradient is analytic (checked against finite differences in the tests). The run is
//! reproducible bit for bit on any thread count: batches come from their own random stream
//! per step, ties between equally near sites are broken by index, and the per-chunk
//! gradients are summed in chunk order.

use crate::grid::KnnGrid;
use crate::kernel::NO_HINT;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use vf_common::rng::{ChunkRng, Stream};
use vf_common::AdamParams;

use crate::error::TrainError;

/// A surface sample's bisector with one neighbour: (signed distance, the neighbour's
/// index, unit direction from the nearest site to it, the sample's offset from their
/// midpoint, their distance).
type Bisector = (f64, usize, [f64; 3], [f64; 3], f64);

/// Samples per parallel chunk (fixed, so the sums do not depend on the thread count).
const CHUNK: usize = 1024;

/// Above this many trainable sites the polish runs 600 steps instead of VoroMesh's 400.
///
/// Each step pulls 20,000 surface samples, so over 400 steps a site is pulled by about
/// 3,900 samples at K = 2,048 but 980 at 8,192: the larger K, the further from converged
/// the polish stops. Measured on the 16 meshes of `benches/quality.py` (2026-12-04, H %
/// Hausdorff, Chamfer, normal consistency; the open sheet, a thin shell, is not polished):
/// - K = 8,192, 400 → 600 steps: Chamfer and normal consistency better on all 15, the
///   Hausdorff distance on 10 (featuretype 0.71 → 0.50%, thin plate 0.47 → 0.25%), worse
///   on the Menger sponge (2.47 → 2.89%; over seeds 0–2 2.67 → 2.80% on average),
///   snowden, npm_teapot and box_fin; 800 steps went further on some and back on others;
/// - K = 32,768 (spot, featuretype, dragon, bunny_scan): Chamfer and normal consistency
///   better on all 4, Hausdorff better on spot and featuretype (0.196 → 0.166%, 0.278 →
///   0.215%), worse on the dragon (2.869 → 2.895%);
/// - K = 2,048: Chamfer better on 14, but the Hausdorff distance worse on 9 (the Menger
///   sponge 6.31 → 7.70%), so small K keeps 400.
pub const POLISH_STEPS_ABOVE: usize = 4096;

/// Steps whose VoroLoss is averaged into [`PolishReport::loss_tail`] (one batch's loss is
/// noisy; 20 batches are 400,000 samples at the default batch).
pub const TAIL_STEPS: usize = 20;

/// Settings of the polish.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PolishConfig {
    /// Adam steps (0 = no polish).
    pub steps: usize,
    /// Initial learning rate in unit-cube lengths; halved after 20%, 37.5%, 50% and 62.5%
    /// of the steps (the paper code's milestones 80, 150, 200, 250 of 400).
    pub lr: f64,
    /// Surface samples per step, drawn with replacement from the data's surface points.
    pub batch: usize,
    /// Next-nearest sites whose bisectors are considered (the paper's 10).
    pub neighbours: usize,
    /// Adam's constants.
    pub adam: AdamParams,
    /// Seed of the batches.
    pub seed: u64,
    /// The label-aware alignment term over the first steps ([`Alignment`]); `None` (the
    /// default: it trades Hausdorff distance on CAD parts and thin parts for normals on
    /// smooth shapes, docs/main-job.md, *Polish*): VoroLoss alone, as VoroMesh.
    #[serde(default)]
    pub alignment: Option<Alignment>,
}

/// The polish's second term, which sees the sites' labels: for a surface sample x with
/// normal n, a = its nearest inside site and b = its nearest outside site,
///
/// ```text
/// distance_weight · d² + normal_weight · ℓ² · (1 − (u·n)²),   u = (b − a)/|b − a|
/// ```
///
/// with d the distance from x to the bisector of a and b (the crust's face between them),
/// and ℓ = 20 · lr, about the pairs' spacing (the learning rate scales with it). It is the
/// training's surface term ([`crate::losses::surface_hinted`]) run inside the polish.
///
/// Why: VoroLoss takes the nearest bisector of x's nearest site and any of its neighbours,
/// labels unseen. Where the sites of two neighbouring pairs do not line up (an outside site a
/// little to the side of its inside partner), the crust between them is a narrow face
/// between one pair's inside site and the other's outside site, tilted by about
/// atan(spacing / 2δ) ≈ 27° at δ = the spacing, and VoroLoss does not see it: the pair's own
/// bisector passes through x. On libigl's sphere.obj at K = 8,192 such faces were 1.6% of the
/// crust's area and 85% of what its normal consistency lacked of 1 (5.8% and 65% on
/// libigl's bunny). The normal term turns each pair's axis along the surface normal, which
/// lines the pairs up, and the faces shrink to slivers. Only the first `share` of the steps
/// carry it: the pairs stay lined up under VoroLoss alone (it is blind to them either way),
/// and the last steps place the faces without being pulled at by the normals.
///
/// A sample whose a→b direction is more than acos(`min_cos`) from its normal pays no normal
/// term: by a sharp edge or a thin part the nearest sites belong to another face, and
/// turning them there rounds the edge (libigl's bunny's flat base: Hausdorff 0.26 → 0.46%
/// without the gate, 0.33% with it at 40°).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Alignment {
    /// Weight of the squared distance to the nearest inside–outside bisector (> 0).
    pub distance_weight: f64,
    /// Weight of 1 − (u·n)², in units of ℓ² (ℓ = 20 · lr).
    pub normal_weight: f64,
    /// Share of the steps, from the first, that carry the term.
    pub share: f64,
    /// Least |u·n| at which a sample pays the normal term.
    pub min_cos: f64,
}

impl Default for Alignment {
    /// Measured on libigl's sphere, 3holes and bunny and on featuretype (K = 8,192); the
    /// docs/main-job.md, *Polish*, says what it buys.
    fn default() -> Self {
        Alignment { distance_weight: 1.0, normal_weight: 0.3, share: 0.5, min_cos: 40f64.to_radians().cos() }
    }
}

impl PolishConfig {
    /// The default for `num_sites` trainable sites: 400 steps of 20,000 samples up to K =
    /// 4,096 and 600 above ([`POLISH_STEPS_ABOVE`]), 10 neighbours, lr 1e-3 at K = 8,192
    /// scaled with the surface spacing √(8192/K).
    ///
    /// The rate was measured on spot and featuretype from the trained default: 1e-3 gave
    /// spot Chamfer 0.0093% and normal consistency 0.988 against 0.0121% / 0.987 at the
    /// paper's 2.5e-3 (its 5e-3 in [−1, 1]³) and 0.0179% / 0.986 at 5e-3.
    pub fn default_for(num_sites: usize, seed: u64) -> Self {
        PolishConfig {
            steps: if num_sites > POLISH_STEPS_ABOVE { 600 } else { 400 },
            lr: 1e-3 * (8192.0 / num_sites.max(1) as f64).sqrt(),
            batch: 20_000,
            neighbours: 10,
            adam: AdamParams::default(),
            seed,
            alignment: None,
        }
    }

    /// The learning rate of 0-based step `t`.
    pub fn lr_at(&self, t: usize) -> f64 {
        let f = t as f64 / self.steps.max(1) as f64;
        let halvings = [0.2, 0.375, 0.5, 0.625].iter().filter(|&&m| f >= m).count();
        self.lr * 0.5f64.powi(halvings as i32)
    }

    /// Checks the settings; the message names the bad one.
    ///
    /// # Errors
    /// [`TrainError::Config`].
    pub fn validate(&self) -> Result<(), TrainError> {
        let bad = |m: String| Err(TrainError::Config(m));
        if !(self.lr.is_finite() && self.lr > 0.0) {
            return bad(format!("polish learning rate {} must be finite and positive", self.lr));
        }
        if self.steps > 0 && self.batch == 0 {
            return bad("polish batch must be at least 1".into());
        }
        if self.neighbours == 0 {
            return bad("polish neighbours must be at least 1".into());
        }
        if let Some(a) = &self.alignment {
            let ok = |x: f64| x.is_finite() && x >= 0.0;
            if !(ok(a.distance_weight)
                && a.distance_weight > 0.0
                && ok(a.normal_weight)
                && ok(a.share)
                && a.share <= 1.0
                && ok(a.min_cos)
                && a.min_cos <= 1.0)
            {
                return bad(format!("polish alignment {a:?}: the distance weight must be finite and > 0, the normal weight finite and ≥ 0, share and min_cos in [0, 1]"));
            }
        }
        self.adam.validate().map_err(TrainError::Config)
    }
}

/// What the polish did (the report's `polish` block).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PolishReport {
    /// Steps run.
    pub steps: usize,
    /// Initial learning rate.
    pub lr: f64,
    /// Surface samples per step.
    pub batch: usize,
    /// VoroLoss (unit-cube lengths squared) of the first and the last batch.
    pub loss_first: f64,
    /// See `loss_first`.
    pub loss_last: f64,
    /// Mean VoroLoss of the last [`TAIL_STEPS`] steps (fewer when fewer ran), the
    /// alignment term left out: where the polish ended, less noisy than `loss_last`.
    #[serde(default)]
    pub loss_tail: f64,
    /// Root mean square and largest distance a site moved, unit-cube lengths.
    pub move_rms: f64,
    /// See `move_rms`.
    pub move_max: f64,
    /// Whether the alignment term ran ([`Alignment`]).
    #[serde(default)]
    pub aligned: bool,
    /// Set by the fit when the aligned polish's crust could not be written in the output's
    /// precision and the polish ran again without the term: the error it gave.
    #[serde(default)]
    pub alignment_dropped: Option<String>,
}

/// VoroLoss of `points` against `sites` (all of them take part) and its gradient, added
/// into `grad` for the first `grad.len()` sites (the trainable ones); returns the mean over
/// the points. `neighbours` next-nearest sites are looked at (fewer when there are fewer).
pub fn voroloss(sites: &[[f64; 3]], points: &[[f64; 3]], neighbours: usize, grad: &mut [[f64; 3]]) -> f64 {
    let cell = crate::grid::cell_for(sites, points, (neighbours + 1).min(sites.len()));
    voroloss_on_grid(sites, points, neighbours, cell, None, grad).0
}

/// A surface sample's nearest inside and outside site, when both are among its nearest
/// sites the polish looked up (`true`), as [`crate::losses::LabelledIndex::nearest_pair`]
/// would find them.
type Pair = ([u32; 2], bool);

/// [`voroloss`] with the neighbours found on a [`KnnGrid`] of cells `cell` wide (the polish
/// picks the width once, [`crate::grid::cell_for`]); the result does not depend on it.
/// With `labels` (one per site), the second value holds every point's [`Pair`] for the
/// alignment term.
fn voroloss_on_grid(
    sites: &[[f64; 3]],
    points: &[[f64; 3]],
    neighbours: usize,
    cell: f64,
    labels: Option<&[bool]>,
    grad: &mut [[f64; 3]],
) -> (f64, Vec<Pair>) {
    if sites.len() < 2 || points.is_empty() {
        return (0.0, vec![([NO_HINT; 2], false); if labels.is_some() { points.len() } else { 0 }]);
    }
    let parts = sample_parts(sites, points, neighbours, cell, labels);
    let trainable = grad.len();
    let n = points.len() as f64;
    let mut loss = 0.0;
    for chunk in parts.chunks(CHUNK) {
        let mut l = 0.0;
        for part in chunk {
            let Some((d, [i, j], [ji, jj])) = part.bisector else { continue };
            l += d * d;
            for (k, jac) in [(i, ji), (j, jj)] {
                if (k as usize) < trainable {
                    for c in 0..3 {
                        grad[k as usize][c] += 2.0 * d * jac[c] / n;
                    }
                }
            }
        }
        loss += l;
    }
    let pairs = if labels.is_some() { parts.iter().map(|p| p.pair).collect() } else { Vec::new() };
    (loss / n, pairs)
}

/// Every point's [`Sample`] against `sites` (at least two), in the points' order, the
/// neighbours found on a [`KnnGrid`] of cells `cell` wide.
fn sample_parts(
    sites: &[[f64; 3]],
    points: &[[f64; 3]],
    neighbours: usize,
    cell: f64,
    labels: Option<&[bool]>,
) -> Vec<Sample> {
    let grid = KnnGrid::new(sites, cell);
    let want = (neighbours + 1).min(sites.len());
    // The samples are looked up in the order of their cells, so that consecutive lookups
    // read the same cells (a random order missed the cache on most runs of points; 1.6×
    // faster measured on the multibody polish). Each sample's part is put back in place and
    // everything is summed in the samples' own order, as before the sorting.
    let mut order: Vec<u64> = points.iter().enumerate().map(|(i, &x)| (grid.cell_key(x) << 32) | i as u64).collect();
    order.par_sort_unstable();
    let found: Vec<Vec<(u32, Sample)>> = order
        .par_chunks(CHUNK)
        .map(|keys| {
            let mut near: Vec<(f64, u32)> = Vec::with_capacity(want + 1);
            let mut buf = Vec::new();
            keys.iter()
                .map(|&key| {
                    let at = key as u32;
                    (at, sample_part(&grid, sites, points[at as usize], want, labels, &mut near, &mut buf))
                })
                .collect()
        })
        .collect();
    let mut parts = vec![Sample::default(); points.len()];
    for (at, part) in found.into_iter().flatten() {
        parts[at as usize] = part;
    }
    parts
}

/// One surface sample's part of VoroLoss: its signed distance d to the nearest bisector, the
/// two sites (nearest, neighbour) and the gradients of d with respect to them (`None`: every
/// neighbour coincides with the nearest site), and its [`Pair`].
#[derive(Clone, Copy)]
struct Sample {
    bisector: Option<(f64, [u32; 2], [[f64; 3]; 2])>,
    pair: Pair,
}

impl Default for Sample {
    fn default() -> Self {
        Sample { bisector: None, pair: ([NO_HINT; 2], false) }
    }
}

/// [`Sample`] of `x`: its `want` nearest sites on `grid` (into `near`), the nearest
/// bisector among them, and the pair when `labels` are given.
fn sample_part(
    grid: &KnnGrid,
    sites: &[[f64; 3]],
    x: [f64; 3],
    want: usize,
    labels: Option<&[bool]>,
    near: &mut Vec<(f64, u32)>,
    buf: &mut Vec<u128>,
) -> Sample {
    // Exact f64 distances, ties by index: the result does not depend on the grid.
    grid.k_nearest_with(x, want, near, buf);
    let mut part = Sample::default();
    if let Some(labels) = labels {
        // The first inside and the first outside site in (distance, index) order are the
        // nearest of each side, when both sides are among these.
        let first = |side: bool| near.iter().find(|c| labels[c.1 as usize] == side).map(|c| c.1);
        if let (Some(a), Some(b)) = (first(true), first(false)) {
            part.pair = ([a, b], true);
        }
    }
    let i = near[0].1 as usize;
    let pi = sites[i];
    // (signed distance to the bisector, j, unit edge direction, offset from the edge's
    // midpoint, edge length) of the nearest bisector so far.
    let mut best: Option<Bisector> = None;
    for &(_, j) in &near[1..] {
        let pj = sites[j as usize];
        let e = [pj[0] - pi[0], pj[1] - pi[1], pj[2] - pi[2]];
        let len = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
        if len == 0.0 {
            continue;
        }
        let u = e.map(|c| c / len);
        let r = [0, 1, 2].map(|c| x[c] - 0.5 * (pi[c] + pj[c]));
        let d = r[0] * u[0] + r[1] * u[1] + r[2] * u[2];
        if best.as_ref().is_none_or(|b| d * d < b.0 * b.0) {
            best = Some((d, j as usize, u, r, len));
        }
    }
    if let Some((d, j, u, r, len)) = best {
        // ∂d/∂p_j = −u/2 + t, ∂d/∂p_i = −u/2 − t, with t = (r − d u)/|e| (the turn of u);
        // the loss takes 2d times these.
        let t = [0, 1, 2].map(|c| (r[c] - d * u[c]) / len);
        let ji = [0, 1, 2].map(|c| -0.5 * u[c] - t[c]);
        let jj = [0, 1, 2].map(|c| -0.5 * u[c] + t[c]);
        part.bisector = Some((d, [i as u32, j as u32], [ji, jj]));
    }
    part
}

/// Polishes the first `trainable` of `sites` in place (the rest, the fixed boundary sites,
/// take part but do not move) against `surface` points, keeping them in [ε, 1 − ε]³ with
/// ε = 1e-9 as the crust needs. `aligned` gives every site's label and every surface
/// point's unit normal for `config.alignment`'s term; `None` (or no `alignment`) runs
/// VoroLoss alone. `on_step(step, steps, loss)` is called after every step and
/// returns `false` to stop early (the sites are then as after that step).
///
/// # Errors
/// Invalid settings; [`TrainError::Diverged`] on a non-finite loss or site.
pub fn polish(
    sites: &mut [[f64; 3]],
    trainable: usize,
    surface: &[[f64; 3]],
    aligned: Option<(&[bool], &[[f64; 3]])>,
    config: &PolishConfig,
    mut on_step: impl FnMut(usize, usize, f64) -> bool,
) -> Result<PolishReport, TrainError> {
    config.validate()?;
    let trainable = trainable.min(sites.len());
    let start: Vec<[f64; 3]> = sites[..trainable].to_vec();
    let mut report = PolishReport {
        steps: 0,
        lr: config.lr,
        batch: config.batch,
        loss_first: f64::NAN,
        loss_last: f64::NAN,
        loss_tail: f64::NAN,
        move_rms: 0.0,
        move_max: 0.0,
        aligned: false,
        alignment_dropped: None,
    };
    if surface.is_empty() || trainable == 0 || sites.len() < 2 {
        return Ok(report);
    }
    let (mut m, mut v) = (vec![[0.0; 3]; trainable], vec![[0.0; 3]; trainable]);
    let mut grad = vec![[0.0; 3]; trainable];
    let mut batch = Vec::with_capacity(config.batch);
    let mut batch_normals = Vec::with_capacity(config.batch);
    let alignment = match (aligned, &config.alignment) {
        (Some((labels, normals)), Some(a)) if labels.len() == sites.len() && normals.len() == surface.len() => {
            Some((labels, normals, a))
        }
        _ => None,
    };
    report.aligned = alignment.is_some();
    // The grid's cell width, from the sites as trained (they move by about a hundredth of
    // the cube in the whole polish, so it stays about right; it sets only the speed).
    let cell = crate::grid::cell_for(sites, surface, (config.neighbours + 1).min(sites.len()));
    const EPS: f64 = 1e-9;
    let mut tail = [0.0; TAIL_STEPS];
    for t in 0..config.steps {
        let mut rng = ChunkRng::for_chunk(config.seed, Stream::PolishBatch, t as u64);
        batch.clear();
        batch_normals.clear();
        for _ in 0..config.batch {
            let i = (rng.next_u64() % surface.len() as u64) as usize;
            batch.push(surface[i]);
            if let Some((_, normals, _)) = alignment {
                batch_normals.push(normals[i]);
            }
        }
        grad.iter_mut().for_each(|g| *g = [0.0; 3]);
        let active = alignment.filter(|(_, _, a)| (t as f64) < a.share * config.steps as f64);
        let (mut loss, mut pairs) =
            voroloss_on_grid(sites, &batch, config.neighbours, cell, active.map(|(l, _, _)| l), &mut grad);
        tail[t % TAIL_STEPS] = loss;
        if let Some((labels, _, a)) = active {
            // The term is d² + (normal / distance) · (1 − (u·n)²), times distance. The
            // nearest inside and outside sites come from VoroLoss's lookup where it saw
            // both; the others are searched in an index of the sites by label.
            let index = std::sync::OnceLock::new();
            let ell = 20.0 * config.lr;
            let ratio = a.normal_weight * ell * ell / a.distance_weight;
            loss += crate::losses::surface_paired(
                &index,
                labels,
                sites,
                &batch,
                &batch_normals,
                &mut pairs,
                ratio,
                a.min_cos,
                a.distance_weight,
                &mut grad,
            );
        }
        if !loss.is_finite() || !grad.iter().flatten().all(|g| g.is_finite()) {
            return Err(TrainError::Diverged { step: t, what: format!("polish loss {loss}") });
        }
        config.adam.at::<f64>(t as u64 + 1, config.lr_at(t)).apply(
            sites[..trainable].as_flattened_mut(),
            grad.as_flattened(),
            m.as_flattened_mut(),
            v.as_flattened_mut(),
        );
        for p in &mut sites[..trainable] {
            for x in p.iter_mut() {
                *x = x.clamp(EPS, 1.0 - EPS);
            }
        }
        if t == 0 {
            report.loss_first = loss;
        }
        report.loss_last = loss;
        report.steps = t + 1;
        if !on_step(t + 1, config.steps, loss) {
            break;
        }
    }
    // Summed in a fixed order (the ring's), so it depends on nothing but the losses.
    let ran = report.steps.min(TAIL_STEPS);
    if ran > 0 {
        report.loss_tail = tail[..ran].iter().sum::<f64>() / ran as f64;
    }
    let moves: Vec<f64> = sites[..trainable].iter().zip(&start).map(|(a, b)| crate::kernel::distance(*a, *b)).collect();
    report.move_rms = (moves.iter().map(|d| d * d).sum::<f64>() / moves.len() as f64).sqrt();
    report.move_max = moves.iter().copied().fold(0.0, f64::max);
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(state: &mut u64) -> f64 {
        *state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*state >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The gradient against central differences, with the neighbour sets held fixed (as the
    /// gradient is) by keeping the steps far below the gaps between distances.
    #[test]
    fn the_default_runs_longer_at_large_k() {
        assert_eq!(PolishConfig::default_for(2048, 0).steps, 400);
        assert_eq!(PolishConfig::default_for(POLISH_STEPS_ABOVE, 0).steps, 400);
        assert_eq!(PolishConfig::default_for(POLISH_STEPS_ABOVE + 1, 0).steps, 600);
        assert_eq!(PolishConfig::default_for(32768, 0).steps, 600);
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let mut s = 7u64;
        let sites: Vec<[f64; 3]> = (0..40).map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)]).collect();
        let points: Vec<[f64; 3]> = (0..300).map(|_| [lcg(&mut s), lcg(&mut s), lcg(&mut s)]).collect();
        let trainable = 30;
        let mut grad = vec![[0.0; 3]; trainable];
        voroloss(&sites, &points, 10, &mut grad);
        let h = 1e-7;
        let mut worst: f64 = 0.0;
        for k in 0..trainable {
            for c in 0..3 {
                let mut plus = sites.clone();
                plus[k][c] += h;
                let mut minus = sites.clone();
                minus[k][c] -= h;
                let mut g = vec![[0.0; 3]; trainable];
                let fd = (voroloss(&plus, &points, 10, &mut g) - voroloss(&minus, &points, 10, &mut g)) / (2.0 * h);
                worst = worst.max((fd - grad[k][c]).abs());
            }
        }
        assert!(worst < 1e-6, "largest gradient error {worst:e}");
    }

    /// Two sites mirrored across a plane: a sample on the plane has loss 0; off it, d².
    #[test]
    fn loss_is_the_squared_distance_to_the_bisector() {
        let sites = [[0.5, 0.5, 0.4], [0.5, 0.5, 0.6]];
        let mut g = vec![[0.0; 3]; 2];
        assert_eq!(voroloss(&sites, &[[0.3, 0.7, 0.5]], 10, &mut g), 0.0);
        let l = voroloss(&sites, &[[0.3, 0.7, 0.53]], 10, &mut g);
        assert!((l - 0.03f64.powi(2)).abs() < 1e-15, "{l}");
    }

    /// A pair whose bisector is off the samples' plane moves onto it; the fixed site does not
    /// move; the run is the same on one thread and on many.
    #[test]
    fn polish_moves_the_bisector_onto_the_surface() {
        let mut s = 3u64;
        let surface: Vec<[f64; 3]> =
            (0..2000).map(|_| [0.3 + 0.4 * lcg(&mut s), 0.3 + 0.4 * lcg(&mut s), 0.5]).collect();
        let start = vec![[0.5, 0.5, 0.45], [0.5, 0.5, 0.75], [0.02, 0.02, 0.02]];
        let config = PolishConfig { steps: 300, lr: 2e-3, batch: 256, ..PolishConfig::default_for(2, 1) };
        let run = |threads: usize| {
            let mut sites = start.clone();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let r = pool.install(|| polish(&mut sites, 2, &surface, None, &config, |_, _, _| true)).unwrap();
            (sites, r)
        };
        let (sites, report) = run(1);
        let mid = 0.5 * (sites[0][2] + sites[1][2]);
        assert!((mid - 0.5).abs() < 5e-3, "bisector at z = {mid}, sites {sites:?}");
        assert!(report.loss_last < 0.05 * report.loss_first, "{report:?}");
        assert_eq!(sites[2], start[2]);
        assert_eq!(run(2).0, sites);
    }

    /// `loss_tail` is the mean of the last [`TAIL_STEPS`] losses the polish reported (all of
    /// them when it ran fewer steps).
    #[test]
    fn the_tail_loss_is_the_mean_of_the_last_steps() {
        let mut s = 5u64;
        let surface: Vec<[f64; 3]> =
            (0..500).map(|_| [0.3 + 0.4 * lcg(&mut s), 0.3 + 0.4 * lcg(&mut s), 0.5]).collect();
        for steps in [7, TAIL_STEPS, 53] {
            let mut sites = vec![[0.5, 0.5, 0.45], [0.5, 0.5, 0.75], [0.4, 0.6, 0.7]];
            let config = PolishConfig { steps, lr: 2e-3, batch: 64, ..PolishConfig::default_for(3, 2) };
            let mut losses = Vec::new();
            let r = polish(&mut sites, 3, &surface, None, &config, |_, _, l| {
                losses.push(l);
                true
            })
            .unwrap();
            let last = &losses[losses.len().saturating_sub(TAIL_STEPS)..];
            let mean = last.iter().sum::<f64>() / last.len() as f64;
            assert!((r.loss_tail - mean).abs() <= 1e-12 * mean.abs(), "{steps} steps: {} against {mean}", r.loss_tail);
            assert_eq!(r.loss_last, *losses.last().unwrap());
        }
    }

    /// The gate: a sample whose nearest inside→outside direction is farther than
    /// acos(min_cos) from its normal pays only the distance term.
    #[test]
    fn samples_beyond_the_gate_pay_no_normal_term() {
        use crate::losses::{surface_hinted, LabelledIndex};
        // Inside at the origin's side, outside 60° off the normal (0, 0, 1).
        let sites =
            [[0.5, 0.5, 0.45], [0.5 + 0.1 * 60f64.to_radians().sin(), 0.5, 0.45 + 0.1 * 60f64.to_radians().cos()]];
        let labels = [true, false];
        let (x, n) = ([[0.52, 0.5, 0.47]], [[0.0, 0.0, 1.0]]);
        let index = LabelledIndex::new(&sites, &labels);
        let loss = |normal: f64, min_cos: f64| {
            let mut g = [[0.0; 3]; 2];
            let mut hints = [[crate::kernel::NO_HINT; 2]];
            surface_hinted(&index, &sites, &x, &n, &mut hints, normal, min_cos, 1.0, &mut g)
        };
        let distance_only = loss(0.0, 0.0);
        // cos 60° = 0.5: the term is 1 − 0.25 below the gate at 0.4, nothing above it at 0.6.
        assert!((loss(1.0, 0.4) - distance_only - 0.75).abs() < 1e-12);
        assert_eq!(loss(1.0, 0.6), distance_only);
    }

    #[test]
    fn schedule_and_validation() {
        // The halvings at the same fractions of the run whatever its length (the paper
        // code's steps 80, 150, 200 and 250 of 400).
        let c = PolishConfig::default_for(2048, 0);
        assert_eq!((c.steps, c.lr_at(0)), (400, 2e-3));
        assert_eq!(c.lr_at(79), 2e-3);
        assert_eq!(c.lr_at(80), 1e-3);
        assert_eq!(c.lr_at(399), 2e-3 / 16.0);
        let c = PolishConfig::default_for(8192, 0);
        assert_eq!((c.steps, c.lr_at(0)), (600, 1e-3));
        assert_eq!(c.lr_at(119), 1e-3);
        assert_eq!(c.lr_at(120), 5e-4);
        assert_eq!(c.lr_at(225), 2.5e-4);
        assert_eq!(c.lr_at(599), 1e-3 / 16.0);
        assert!(PolishConfig { lr: f64::NAN, ..c.clone() }.validate().is_err());
        assert!(PolishConfig { batch: 0, ..c.clone() }.validate().is_err());
        assert!(PolishConfig { neighbours: 0, ..c }.validate().is_err());
    }
}
