//! Site insertion where the crust strays: after training, at the foot c (closest input
//! point) of every crust vertex v far from the input, a mirrored pair c ± t·n (t the
//! tolerance; n = (v − c)/|v − c|: the triangle's normal where the foot is inside a
//! triangle, the spike's own direction at an edge or a corner) is inserted, labelled by
//! the solid, and the crust is extracted again, for a few rounds. A spike of crust (an
//! inside cell poking out between outside sites at an ear tip or a corner) stands over its
//! foot; the pair's bisector is the tangent plane at c, and the outside site is nearer to
//! the spike than the sites that made it, so the spike is cut back to the surface there.
//! The other side too: at an input sample c far from the crust (a tunnel the crust fills
//! in, a part it lost, a dent), the pair c ± t·n along the input's normal puts a site of
//! the right label on each side of the surface where the crust has none. Far means
//! farther than t and within [`WORST_SHARE`] of the worst, so each round works where the
//! Hausdorff distance is set. A pair by an edge is turned to bisect it ([`aim_at_edges`]);
//! each inserted site gets its mirror images across the other input faces near it, so that
//! its cell stops at them too (a thin wall's far face: [`mirror_closure`]); a site of a pair
//! that would still stand nearer the input than half its offset (at a corner) is left out
//! ([`MIN_CLEARANCE`]), and the state
//! kept is the one with the least two-sided Hausdorff distance, so that a dent cut by an
//! inserted outside site counts too. (A single site at the stray vertex itself was tried
//! first: its cell, bounded only by the sites of an empty sphere, can be larger than the
//! spike and made the farthest vertex farther.)

use crust::{Crust, CrustConfig};
use mesh_io::TriMesh;
use occupancy::{BvhPreset, MeshOracle};
use soft_voronoi::Solid;
use vf_common::vec3::{distance_squared, dot};

use crate::error::FitError;
pub use crate::report::{CarveReport, SurfaceBar};

/// How [`carve`] runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarveOptions {
    /// How far a crust vertex or an input sample may stray before a pair goes there, in
    /// the unit frame (the pairs' half-offset too).
    pub tolerance: f64,
    /// Rounds at most.
    pub rounds: usize,
    /// Sites inserted at most, over all rounds.
    pub max_new: usize,
    /// Whether the inserted sites get their mirror images ([`mirror_closure`]).
    pub mirrors: bool,
    /// Whether crust vertices far from the input get sites of their own ([`peel_sites`]).
    pub peels: bool,
    /// Stop before the first round (nothing inserted; [`CarveReport::gated`]) when the
    /// uncarved crust's Chamfer distance is larger or its normal consistency lower than
    /// these: the fit's second, aligned polish is measured against the plain one's this way
    /// before it pays for carving (`run.rs`).
    pub gate: Option<SurfaceBar>,
}

impl CarveOptions {
    /// The main job's: [`ROUNDS`] rounds and K/8 sites for `k` sites, with mirrors.
    pub fn for_sites(tolerance: f64, k: usize) -> Self {
        CarveOptions { tolerance, rounds: ROUNDS, max_new: k / 8, mirrors: true, peels: true, gate: None }
    }
}

/// Whether the main job's carving places [`peel_sites`]: for every solid but the winding
/// solid (`winding`) of a mesh without open edges (see [`peel_sites`] for why).
pub fn peels_for(winding: bool, mesh: &TriMesh) -> bool {
    !winding || !mesh_io::topology::boundary_edges(mesh).is_empty()
}

/// Rounds of the main job's carving ([`CarveOptions::for_sites`]).
pub const ROUNDS: usize = 8;

/// Inserts pairs of sites (appended to `sites` and `labels`) at the feet of the crust's
/// vertices far from `mesh` (the mesh behind `oracle`, same frame) and at the input samples
/// far from the crust (farther than the tolerance and than [`WORST_SHARE`] of the worst),
/// labelled by `solid`, for up to `options.rounds` rounds and at most `options.max_new`
/// sites in all (farthest first; feet closer than two tolerances to an earlier one are
/// skipped), then keeps the best of the states reached (see
/// [`CarveReport::undone_rounds`]).
///
/// # Errors
/// [`FitError::Crust`] when the crust before any insertion cannot be extracted (a round
/// whose insertions leave no extractable crust is taken back: see
/// [`CarveReport::round_not_extracted`]); [`FitError::Occupancy`] or
/// [`FitError::Metrics`] when a distance cannot be measured.
pub fn carve(
    sites: &mut Vec<[f64; 3]>,
    labels: &mut Vec<bool>,
    oracle: &MeshOracle,
    mesh: &TriMesh,
    solid: &dyn Solid,
    options: &CarveOptions,
) -> Result<CarveReport, FitError> {
    let start = Start { crust: None, first_surface: &|_| options.gate };
    carve_with(sites, labels, oracle, mesh, solid, options, start)
}

/// What [`carve_with`] starts from beyond the sites and the options.
pub struct Start<'a> {
    /// The crust of the sites and labels as given, when it was extracted already (the box
    /// guard's last): the first round measures it instead of extracting it again. A crust
    /// of another number of sites is not used.
    pub crust: Option<Crust>,
    /// The gate, once the uncarved crust is measured: called with that crust's
    /// [`SurfaceBar`], it returns the bar to stop under (`None`: no gate); `options.gate`
    /// is not used. The fit's two attempts running side by side pass the plain one's bar to
    /// the aligned one this way (`run.rs`).
    pub first_surface: &'a dyn Fn(SurfaceBar) -> Option<SurfaceBar>,
}

/// [`carve`], from [`Start`].
///
/// # Errors
/// As [`carve`].
pub fn carve_with(
    sites: &mut Vec<[f64; 3]>,
    labels: &mut Vec<bool>,
    oracle: &MeshOracle,
    mesh: &TriMesh,
    solid: &dyn Solid,
    options: &CarveOptions,
    start: Start,
) -> Result<CarveReport, FitError> {
    let Start { crust: mut extracted, first_surface } = start;
    extracted = extracted.filter(|c| c.stats.num_sites == sites.len());
    let CarveOptions { tolerance, rounds, max_new, mirrors, peels, gate: _ } = *options;
    let mut report = CarveReport { tolerance, ..Default::default() };
    let mut budget = max_new;
    let open_edges = mesh_io::topology::boundary_edges(mesh);
    // The state after each round's extraction. Rounds need not help one by one (cutting one
    // spike can expose the next), so all of them run and the best state ([`best_state`]) is
    // kept: carving never makes the crust's Hausdorff distance to the input larger.
    let mut states: Vec<State> = Vec::new();
    // The input side is certified to 0.01% of the diagonal: enough to compare states. The
    // input's distance structure is built once for all rounds.
    let certify = metrics::CertifiedOptions { rel_tolerance: 1e-4, ..Default::default() };
    let surface_options =
        metrics::SurfaceOptions { num_samples: F_SAMPLES, seed: 0, fscore_tau_rel: tolerance / mesh.diagonal() };
    let input = metrics::DistanceMesh::with_preset(mesh, "input", BvhPreset::VeryFast).map_err(measure_failure)?;
    let samples = unburied_samples(mesh, solid)?;
    let sample_index = (!samples.points.is_empty()).then(|| soft_voronoi::SiteIndex::new(&samples.points));
    // One function for all rounds (about 120 lines): each round's measurements, its
    // choice of strays and its insertions share the budget, the states and the report.
    for round in 0..=rounds {
        let crust = match extracted.take().map_or_else(|| Crust::extract(sites, labels, &CrustConfig::default()), Ok) {
            Ok(crust) => crust,
            // The sites with this round's insertions have no extractable crust (nearly
            // degenerate sites whose Voronoi vertices break it when rounded): take the
            // round back and stop at the state before it, which was extracted and checked.
            Err(source) if round > 0 => {
                let before = states.last().map_or(sites.len(), |s| s.sites);
                sites.truncate(before);
                labels.truncate(before);
                let kept_rounds = states.len() - 1;
                report.inserted_per_round.truncate(kept_rounds);
                report.inserted_at_input_per_round.truncate(kept_rounds);
                report.inserted_as_mirrors_per_round.truncate(kept_rounds);
                report.inserted_as_peels_per_round.truncate(kept_rounds);
                report.round_not_extracted = Some(source.to_string());
                break;
            }
            Err(source) => return Err(FitError::Crust { during: "crust while carving", source }),
        };
        let far = oracle.closest_points(&crust.mesh.positions).map_err(failure)?;
        let farthest = far.iter().map(|c| c.squared_distance.sqrt()).fold(0.0, f64::max);
        let excess: f64 = far.iter().map(|c| (c.squared_distance.sqrt() - tolerance).max(0.0)).sum();
        // The other side: the input's farthest point from the crust (a dent where an
        // inserted outside site's cell cut into the solid); then the rest of the surface:
        // the F-score at the tolerance, from samples on both.
        let crust_distance =
            metrics::DistanceMesh::with_preset(&crust.mesh, "crust", BvhPreset::VeryFast).map_err(measure_failure)?;
        let sample_distance = distances_to(&samples.points, &crust_distance);
        // Where part of the input is buried in its solid, the largest distance of the
        // samples of the rest; else certified.
        let missed = if samples.any_buried {
            sample_distance.iter().copied().fold(0.0, f64::max)
        } else {
            metrics::hausdorff::directed_certify_prepared(&input, &crust_distance, &certify)
                .map_err(measure_failure)?
                .hi
        };
        let surface =
            metrics::surface_metrics_of(&input, &crust_distance, &surface_options).map_err(measure_failure)?;
        let fscore = surface.fscore;
        if round == 0 {
            report.first_surface =
                SurfaceBar { chamfer_l1: surface.chamfer_l1, normal_consistency: surface.normal_consistency };
            if let Some(bar) = first_surface(report.first_surface) {
                // NaN compares false both ways: a NaN stops too.
                let reaches =
                    surface.chamfer_l1 <= bar.chamfer_l1 && surface.normal_consistency >= bar.normal_consistency;
                if !reaches {
                    report.gated = true;
                }
            }
        }
        states.push(State { sites: sites.len(), farthest, missed, excess, fscore });
        report.farthest_per_round.push(farthest);
        report.input_farthest_per_round.push(missed);
        report.fscore_per_round.push(fscore);
        // Rounds that keep failing to beat the best state so far are not worth more
        // extractions: after PATIENCE of them in a row, stop.
        let best_so_far = best_state(&states);
        let stale = states.len() - 1 - best_so_far >= PATIENCE;
        // Where the error is: the crust vertices far from the input (spikes, caps across
        // tunnels) and the input's samples far from the crust (dents, tunnels filled in,
        // parts lost), farther than the tolerance and within WORST_SHARE of the worst.
        let threshold = tolerance.max(WORST_SHARE * farthest.max(missed));
        let mut stray = strays(&far, &crust.mesh.positions, &sample_distance, &samples, mesh, threshold);
        if round == rounds || stray.is_empty() || budget < 2 || stale || report.gated {
            break;
        }
        // A round takes at most ROUND_SHARE of the budget left, so that the rounds after it
        // can cut what it exposes.
        let round_budget = ((ROUND_SHARE * budget as f64).ceil() as usize).clamp(2, budget);
        let (feet, mut new, from_input) = pairs_at(&mut stray, mesh, &open_edges, tolerance, round_budget);
        // A pair at an edge is turned to bisect it ([`aim_at_edges`]). A site still nearer
        // the input than half its offset stands by another part of the surface than its
        // foot's: at a corner, or across a thin part. Its cell, bounded on that side only by
        // the trained sites, pokes through that face as a new spike, so it is left out and
        // its partner alone cuts the spike (see [`MIN_CLEARANCE`]).
        aim_at_edges(oracle, mesh, &feet, &mut new, tolerance)?;
        let clear = clearance_mask(oracle, &new, tolerance)?;
        let at_input = from_input.iter().zip(&clear).filter(|(&a, &c)| a && c).count();
        let mut new: Vec<[f64; 3]> = new.into_iter().zip(&clear).filter(|(_, &c)| c).map(|(p, _)| p).collect();
        let pairs = new.len();
        if let Some(index) = sample_index.as_ref().filter(|_| mirrors) {
            mirror_closure(oracle, solid, &samples, index, &mut new, tolerance, round_budget)?;
        }
        let mirrors = new.len() - pairs;
        // Sites at the crust's vertices far from the input themselves ([`peel_sites`]).
        let before_peels = new.len();
        if peels {
            new.extend(peel_sites(&stray, mesh, &open_edges, tolerance, round_budget.saturating_sub(new.len())));
        }
        // Each site is labelled by the solid, whatever it gives: at a thin tip both sites of
        // a pair may land outside (or inside), and two outside sites there are exactly what
        // cuts a spike back. (Keeping only pairs that straddle the surface, as the initial
        // pairs do, left the bunny's ear-tip spikes untouched.) A round that does harm is
        // undone by the choice of the best state below.
        let peels = new.len() - before_peels;
        let kept = new.len();
        labels.extend(solid.inside(&new));
        sites.extend(new);
        if kept == 0 {
            break;
        }
        budget = budget.saturating_sub(kept);
        report.inserted_per_round.push(kept);
        report.inserted_at_input_per_round.push(at_input);
        report.inserted_as_mirrors_per_round.push(mirrors);
        report.inserted_as_peels_per_round.push(peels);
    }
    let best = best_state(&states);
    report.farthest_before = states[0].farthest;
    report.farthest_after = states[best].farthest;
    report.undone_rounds = report.inserted_per_round.len() - best;
    report.inserted_per_round.truncate(best);
    report.inserted_at_input_per_round.truncate(best);
    report.inserted_as_mirrors_per_round.truncate(best);
    report.inserted_as_peels_per_round.truncate(best);
    sites.truncate(states[best].sites);
    labels.truncate(states[best].sites);
    Ok(report)
}

/// A carving site is inserted only if the input is at least this share of the tolerance (its
/// offset from the foot) away from it. Measured on the quality benchmark at K = 8,192 by
/// replaying the carving on the same trained sites: with every pair inserted,
/// featuretype's first round put an inside site 0.0009 from the side face of a counterbore
/// (its foot on the top face, 0.3 t from the edge) and made a fin 0.057 long off that edge
/// (farthest crust vertex 1.68% → 5.5% of the diagonal), so every round was undone; with
/// the rule, the farthest vertex went 1.68% → 0.28% (4 sites), thin_plate 1.12% → 0.36%,
/// box_fin 1.50% → 0.73% and dragon 0.84% → 0.48%. Shares 0.35–0.9 all gave featuretype
/// 0.28%; 0.9 left dragon at 0.58%. 0.5 keeps the pair at a right-angled edge (its sites
/// along the bisecting direction are 0.71 t from both faces).
pub const MIN_CLEARANCE: f64 = 0.5;

/// The sites of `new` (same frame as `oracle`) that the input is at least
/// [`MIN_CLEARANCE`]·`tolerance` away from, in their order.
///
/// # Errors
/// [`FitError::Occupancy`] for a non-finite site.
pub fn clear_of_the_input(oracle: &MeshOracle, new: Vec<[f64; 3]>, tolerance: f64) -> Result<Vec<[f64; 3]>, FitError> {
    let clear = clearance_mask(oracle, &new, tolerance)?;
    Ok(new.into_iter().zip(&clear).filter(|(_, &c)| c).map(|(p, _)| p).collect())
}

/// For each of `new`: whether the input is at least [`MIN_CLEARANCE`]·`tolerance` away.
fn clearance_mask(oracle: &MeshOracle, new: &[[f64; 3]], tolerance: f64) -> Result<Vec<bool>, FitError> {
    let closest = oracle.closest_points(new).map_err(failure)?;
    let min2 = (MIN_CLEARANCE * tolerance).powi(2);
    Ok(closest.iter().map(|c| c.squared_distance >= min2).collect())
}

/// Turns each pair of `new` (`new[2i]`, `new[2i + 1]`: `feet[i]` ± t·n) whose site
/// stands within [`MIN_CLEARANCE`]·t of an input face other than its foot's (a face whose
/// normal n₂ is more than about 25° from n: the foot is by an edge) to bisect the edge,
/// along (n + n₂)/|n + n₂|, unless n₂ is nearly opposite n (a thin part, not an edge). At a
/// right-angled edge both sites then stand 0.71 t from both faces, where the clearance rule
/// would have dropped one of them and left the other alone: a lone outside site above a
/// CAD part's convex edge dug a dent 0.014 deep into featuretype (4.6 t), and a lone inside
/// site at a concave one poked through the thin wall behind it.
///
/// # Errors
/// [`FitError::Occupancy`] for a non-finite site.
fn aim_at_edges(
    oracle: &MeshOracle,
    mesh: &TriMesh,
    feet: &[[f64; 3]],
    new: &mut [[f64; 3]],
    tolerance: f64,
) -> Result<(), FitError> {
    let closest = oracle.closest_points(new).map_err(failure)?;
    let min2 = (MIN_CLEARANCE * tolerance).powi(2);
    for (k, &f) in feet.iter().enumerate() {
        let n = [0, 1, 2].map(|i| (new[2 * k][i] - f[i]) / tolerance);
        // The first site of the pair by another face, with the bisecting direction.
        let turned = closest[2 * k..2 * k + 2].iter().filter(|c| c.squared_distance < min2).find_map(|c| {
            let n2 = soft_voronoi::solid::unit_normal(mesh, c.triangle as usize);
            let b = [0, 1, 2].map(|i| n[i] + n2[i]);
            let len = dot(b, b).sqrt();
            (dot(n, n2) <= EDGE_COSINE && len >= 0.5).then(|| b.map(|x| x / len))
        });
        if let Some(b) = turned {
            for (j, sign) in [(2 * k, 1.0), (2 * k + 1, -1.0)] {
                new[j] = [0, 1, 2].map(|i| (f[i] + sign * tolerance * b[i]).clamp(1e-6, 1.0 - 1e-6));
            }
        }
    }
    Ok(())
}

/// Normals with a cosine above this are one face to [`aim_at_edges`] (about 25°).
const EDGE_COSINE: f64 = 0.9;

/// Mirror images of the inserted sites across the input faces near them, and of those in
/// turn, [`CLOSURE_DEPTH`] times: for each site s of `new` and each input face within
/// [`CLOSURE_REACH`]·t of it (the nearest sample of each group of samples whose normals
/// agree within [`FACE_COSINE`]; q, n), the site s − 2((s − q)·n)n of the other label
/// (the solid is asked; a mirror it labels otherwise, within 0.3 t of a site already there,
/// or nearer the input than [`MIN_CLEARANCE`]·t, like an inserted site, is not added; nor
/// one across a face whose plane passes that near s). Each such face is then the bisector
/// of s and its mirror near q, so the cell of s cannot cross it there. A pair's own partner is its mirror across its
/// foot's face; the others are what it lacks: a pair's inside site in a wall thinner than
/// the trained sites' spacing (featuretype's counterbores come within 1.8 t of the outer
/// face) poked out through the wall's far face as a spike 0.02 long (6 t), and a pair
/// turned to bisect an edge poked through both faces of the edge. Measured on featuretype
/// at K = 8,192, seeds 0 / 1 / 2: certified Hausdorff 0.498 / 0.84 / 0.58% of the
/// diagonal without the mirrors and the turning, 0.328 / 0.376 / 0.386% with both.
/// Appends to `new` until it holds `budget` sites.
fn mirror_closure(
    oracle: &MeshOracle,
    solid: &dyn Solid,
    samples: &InputSamples,
    index: &soft_voronoi::SiteIndex,
    new: &mut Vec<[f64; 3]>,
    tolerance: f64,
    budget: usize,
) -> Result<(), FitError> {
    let reach = CLOSURE_REACH * tolerance;
    let dup2 = (0.3 * tolerance).powi(2);
    let mut level: Vec<([f64; 3], bool)> = new.iter().copied().zip(solid.inside(new)).collect();
    let mut near = Vec::new();
    for _ in 0..CLOSURE_DEPTH {
        let mut candidates: Vec<([f64; 3], bool)> = Vec::new();
        for &(s, label) in &level {
            index.candidates(&samples.points, s, reach, &mut near);
            near.retain(|&(_, d)| d < reach);
            near.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
            let mut faces: Vec<[f64; 3]> = Vec::new();
            for &(i, _) in &near {
                let (q, n) = (samples.points[i as usize], samples.normals[i as usize]);
                if faces.iter().any(|m| dot(*m, n) > FACE_COSINE) {
                    continue;
                }
                faces.push(n);
                let h = dot([0, 1, 2].map(|k| s[k] - q[k]), n);
                if h.abs() < MIN_CLEARANCE * tolerance || h.abs() > reach {
                    continue;
                }
                candidates.push(([0, 1, 2].map(|k| (s[k] - 2.0 * h * n[k]).clamp(1e-6, 1.0 - 1e-6)), !label));
            }
        }
        let points: Vec<[f64; 3]> = candidates.iter().map(|c| c.0).collect();
        let clear = clearance_mask(oracle, &points, tolerance)?;
        let mut next: Vec<([f64; 3], bool)> = Vec::new();
        for ((c, inside), clear) in candidates.into_iter().zip(solid.inside(&points)).zip(clear) {
            if c.1 != inside
                || !clear
                || new.len() + next.len() >= budget
                || new.iter().chain(next.iter().map(|n| &n.0)).any(|x| distance_squared(*x, c.0) < dup2)
            {
                continue;
            }
            next.push(c);
        }
        if next.is_empty() {
            break;
        }
        new.extend(next.iter().map(|n| n.0));
        level = next;
    }
    Ok(())
}

/// The most of the budget left that one round of [`carve`] inserts. Measured on the Menger
/// sponge at K = 8,192, where every round has more strays than the budget: with the pairs
/// turned at edges and mirrored ([`aim_at_edges`], [`mirror_closure`]) and the mirrors not
/// yet held to the budget, the first round took 1,373 sites and left the next rounds
/// nothing: 2.61% of the diagonal against 1.99% before them; at half, eight rounds ran and
/// it came out at 1.90%.
pub const ROUND_SHARE: f64 = 0.5;

/// How far from an inserted site (in tolerances) [`mirror_closure`] looks for faces.
pub const CLOSURE_REACH: f64 = 3.0;

/// Rounds of mirroring in [`mirror_closure`] (a mirror of a mirror closes a thin wall's
/// far side).
pub const CLOSURE_DEPTH: usize = 3;

/// Sample normals with a cosine above this are one face to [`mirror_closure`] (about 18°).
const FACE_COSINE: f64 = 0.95;

/// Rounds in a row that do not beat the best state before [`carve`] stops early. Measured
/// on the 16 meshes of the quality benchmark at K = 8,192: where a round improved on the
/// best, it came at most two rounds after the previous improvement (thin_plate, box_fin,
/// dragon); on featuretype and the two teapots, where every round makes the farthest vertex
/// farther, three rounds run instead of eight.
pub const PATIENCE: usize = 3;

/// A round of [`carve`] inserts pairs only where the error is within this share of the
/// worst: at the crust vertices and input samples farther from the other surface than
/// max(tolerance, share × the two-sided farthest distance). Measured on the quality
/// benchmark (every crust vertex beyond the tolerance before, and the crust's side only):
/// the Menger sponge at K = 8,192, where hundreds of pairs a round along its unresolved
/// tunnels lowered the F-score past the slack so that every round was undone, went
/// 2.89 → 1.99% of the diagonal (with the input's side), and featuretype at K = 2,048
/// 6.51 → 1.46%; the README's *Carving where the error is* has the table.
pub const WORST_SHARE: f64 = 0.5;

/// A place where the crust strays: a crust vertex far from the input, or an input sample
/// far from the crust.
struct Stray {
    /// How far from the other surface.
    distance: f64,
    /// The input point the pair is centred on (the vertex's closest input point, or the
    /// sample itself).
    foot: [f64; 3],
    /// Unit direction of the pair.
    direction: [f64; 3],
    /// The input triangle the foot is on.
    triangle: u32,
    /// Whether the foot is an input sample far from the crust.
    at_input: bool,
}

/// Where the error is: the crust vertices at `positions` farther than `threshold` from the
/// input (`far`: their closest input points) and the input `samples` farther than it from
/// the crust (`sample_distance`), each with the foot and the direction of its pair.
fn strays(
    far: &[occupancy::ClosestPoint],
    positions: &[[f64; 3]],
    sample_distance: &[f64],
    samples: &InputSamples,
    mesh: &TriMesh,
    threshold: f64,
) -> Vec<Stray> {
    let mut stray: Vec<Stray> = far
        .iter()
        .zip(positions)
        .filter(|(c, _)| c.squared_distance.sqrt() > threshold)
        .map(|(c, &v)| {
            let d = c.squared_distance.sqrt();
            // The pair lies along the stray vertex's own direction from its foot.
            // Where the foot is inside a triangle that is the triangle's normal; at an
            // edge or a corner (a spike off a plate's rim, a CAD part's corner) it is
            // the direction the spike actually takes, which a neighbouring face's
            // normal is not.
            let direction = if d > 0.0 {
                [0, 1, 2].map(|i| (v[i] - c.point[i]) / d)
            } else {
                soft_voronoi::solid::unit_normal(mesh, c.triangle as usize)
            };
            Stray { distance: d, foot: c.point, direction, triangle: c.triangle, at_input: false }
        })
        .collect();
    // An input sample far from the crust is its own foot; its pair lies along the
    // input's normal there.
    stray.extend(sample_distance.iter().enumerate().filter(|(_, &d)| d > threshold).map(|(i, &d)| Stray {
        distance: d,
        foot: samples.points[i],
        direction: samples.normals[i],
        triangle: samples.triangles[i],
        at_input: true,
    }));
    stray
}

/// The pairs of one round, farthest stray first, at most `round_budget` sites: feet closer
/// than two tolerances to an earlier one, and feet on an open edge, are skipped. Returns
/// the feet, the pairs' sites and whether each came from an input sample.
fn pairs_at(
    stray: &mut [Stray],
    mesh: &TriMesh,
    open_edges: &[(u32, u32)],
    tolerance: f64,
    round_budget: usize,
) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<bool>) {
    stray.sort_by(|a, b| {
        b.distance.total_cmp(&a.distance).then(a.foot.map(f64::to_bits).cmp(&b.foot.map(f64::to_bits)))
    });
    let mut feet: Vec<[f64; 3]> = Vec::new();
    let mut new: Vec<[f64; 3]> = Vec::new();
    // Whether each of `new` came from an input sample's pair.
    let mut from_input: Vec<bool> = Vec::new();
    for st in stray.iter() {
        if new.len() + 2 > round_budget {
            break;
        }
        let c = st.foot;
        if feet.iter().any(|f| distance_squared(*f, c) < 4.0 * tolerance * tolerance) {
            continue;
        }
        // A crust vertex whose foot is on the rim of a hole in the input spans the hole
        // (the solid closes it); no site pair there can bring it nearer, and pairs along
        // its direction would lie in the hole's plane. Measured on the scanned bunny
        // (holes underneath): carving there lowered F-score 0.990 → 0.978.
        if on_open_edge(mesh, st.triangle as usize, c, open_edges, 1e-9) {
            continue;
        }
        feet.push(c);
        let n = st.direction;
        new.extend([1.0, -1.0].map(|s| [0, 1, 2].map(|i| (c[i] + s * tolerance * n[i]).clamp(1e-6, 1.0 - 1e-6))));
        from_input.extend([st.at_input; 2]);
    }
    (feet, new, from_input)
}

/// Crust vertices farther than [`PEEL_REACH`] tolerances from the input, farthest first,
/// none nearer an earlier one than half its distance, at most `budget`: sites there (the
/// solid labels them) take those places from the cells that reach them. A pair at the
/// foot cannot: where trained inside sites sit in a thin part with no outside site beyond
/// its edge (a soup's wing, a chair's open rail), their cells run on past the edge as fins
/// and plates a fifth of the diagonal long, whose feet are all on that edge. Measured on
/// the real-world benchmark at K = 8,192 (`benches/real_world.py`): the ShapeNet airplane's
/// farthest crust vertex went from 21.7% to 3.0% of the diagonal, the ModelNet chair's from
/// 11.5% to 1.5%.
/// Vertices whose foot is on the rim of a hole in the input are skipped, as in
/// [`pairs_at`]: they lie on the solid's cap across the hole, where they belong.
/// Only when [`CarveOptions::peels`]: the main job leaves them out for the winding solid of
/// a mesh without open edges, where every part has outside sites beyond it and the pairs
/// reach the spikes, and peels only changed which rounds followed (menger at K = 8,192:
/// Hausdorff 1.81% → 2.14% of the diagonal, genus kept 1,097 → 1,060 of 1,409). Soups
/// whose faces are doubled have no open edges either, but take the flood solid and keep
/// them (the ShapeNet airplane).
fn peel_sites(
    stray: &[Stray],
    mesh: &TriMesh,
    open_edges: &[(u32, u32)],
    tolerance: f64,
    budget: usize,
) -> Vec<[f64; 3]> {
    let mut out: Vec<[f64; 3]> = Vec::new();
    for st in stray.iter().filter(|s| !s.at_input && s.distance > PEEL_REACH * tolerance) {
        if out.len() >= budget {
            break;
        }
        if on_open_edge(mesh, st.triangle as usize, st.foot, open_edges, 1e-9) {
            continue;
        }
        // Inside the domain box like every inserted site: a crust vertex can lie on the box's
        // face (at menger's 8k a peel at y = 1.0 stopped the round's extraction).
        let v = [0, 1, 2].map(|i| (st.foot[i] + st.distance * st.direction[i]).clamp(1e-6, 1.0 - 1e-6));
        let spacing = 0.5 * st.distance;
        if out.iter().all(|p| distance_squared(*p, v) >= spacing * spacing) {
            out.push(v);
        }
    }
    out
}

/// How far (in tolerances) a crust vertex must be from the input for [`peel_sites`].
const PEEL_REACH: f64 = 4.0;

/// The crust after one round of [`carve`].
struct State {
    /// Sites so far (the state is the first `sites` of them).
    sites: usize,
    /// The farthest crust vertex from the input.
    farthest: f64,
    /// The input's farthest point from the crust (certified upper end).
    missed: f64,
    /// Summed excess Σ(d − t) over the crust vertices farther than the tolerance t.
    excess: f64,
    /// F-score at the tolerance ([`F_SAMPLES`] samples on each surface).
    fscore: f64,
}

/// The index of the best state. Only states whose F-score at the tolerance is at most
/// [`f_slack`] below the uncarved crust's count: at K = 2,048 on featuretype the first
/// round's 237 sites cut the farthest vertex in two rounds from 6.3% to 2.1% of the
/// diagonal but took the F-score from 0.992 to 0.962 (dents and bumps of the tolerance's
/// size along the part's edges), which the Hausdorff distance does not see. Among those,
/// first the two-sided farthest distance max(farthest vertex, the input's farthest point),
/// the Hausdorff distance: inserted outside sites whose cells cut into the solid leave
/// dents, which the crust's vertices do not show (on featuretype, cutting a spike of 1.7%
/// of the diagonal left a dent of 1.3%). States within [`TIE`] of the least are equal on
/// that count (where a hole or a notch the carving does not reach sets the input's side,
/// every state has it); among them the least farthest vertex, then the least excess, then
/// the earliest.
fn best_state(states: &[State]) -> usize {
    let two_sided = |s: &State| s.farthest.max(s.missed);
    let admissible = |s: &State| s.fscore >= states[0].fscore - f_slack(states[0].fscore);
    let least = states.iter().filter(|s| admissible(s)).map(two_sided).fold(f64::INFINITY, f64::min);
    (0..states.len())
        .filter(|&i| admissible(&states[i]) && two_sided(&states[i]) <= least * (1.0 + TIE))
        .min_by(|&i, &j| {
            let (a, b) = (&states[i], &states[j]);
            a.farthest.total_cmp(&b.farthest).then(a.excess.total_cmp(&b.excess)).then(i.cmp(&j))
        })
        .unwrap_or(0)
}

/// Relative slack within which two states' two-sided farthest distances count as equal.
const TIE: f64 = 0.01;

/// Samples on each surface for a state's F-score, and how far below the uncarved crust's
/// F-score a state may fall and still be kept.
const F_SAMPLES: usize = 50_000;
const F_SLACK: f64 = 0.002;

/// How far below the uncarved crust's F-score `f0` a state may fall and still be kept:
/// [`F_SLACK`], or a twentieth of what `f0` lacks of 1 where that is more. Where the crust
/// already misses much of the surface at the tolerance (the Menger sponge's unresolved
/// tunnels: F-score 0.84), moving it shifts thousandths of samples across the tolerance
/// either way; at the absolute slack alone a round that cut the farthest crust vertex
/// from 5.6% to 2.4% of the diagonal was undone for a drop of 0.006 there.
fn f_slack(f0: f64) -> f64 {
    F_SLACK.max(0.05 * (1.0 - f0))
}

/// [`INPUT_SAMPLES`] samples of the input (seed 0) less those on faces buried inside its
/// own solid (where bodies overlap: the solid on both sides at ±10⁻⁶ of the diagonal along
/// the normal, by `solid`). They are where [`carve`] looks for input far from the crust,
/// and, when some were left out, its measure of the input's side of the Hausdorff distance
/// (else that is certified). No crust comes near a buried face, and its distance to the
/// crust moves as the crust moves around it: on snowden (2.6% buried) a round that cut the
/// farthest crust vertex from 3.2% to 1.2% of the diagonal was undone because a buried
/// face's distance grew by 3%.
struct InputSamples {
    points: Vec<[f64; 3]>,
    /// The unit normal of the triangle each point is on.
    normals: Vec<[f64; 3]>,
    triangles: Vec<u32>,
    /// Whether any sample was left out.
    any_buried: bool,
}

/// The [`InputSamples`] of `mesh`.
fn unburied_samples(mesh: &TriMesh, solid: &dyn Solid) -> Result<InputSamples, FitError> {
    let sampler = occupancy::sample::SurfaceSampler::from_mesh(mesh).map_err(failure)?;
    let s = sampler.sample(INPUT_SAMPLES, 0);
    let eps = metrics::BURIED_OFFSET * mesh.diagonal();
    let Ok(is_buried) =
        metrics::buried(&s.points, &s.normals, eps, |q| Ok::<_, std::convert::Infallible>(solid.inside(q)));
    let mut out = InputSamples { points: Vec::new(), normals: Vec::new(), triangles: Vec::new(), any_buried: false };
    for (i, &b) in is_buried.iter().enumerate() {
        if b {
            out.any_buried = true;
        } else {
            out.points.push(s.points[i]);
            out.normals.push(s.normals[i]);
            out.triangles.push(s.triangles[i]);
        }
    }
    Ok(out)
}

/// The distance from each of `points` to `target`.
fn distances_to(points: &[[f64; 3]], target: &metrics::DistanceMesh) -> Vec<f64> {
    use rayon::prelude::*;
    points
        .par_chunks(1024)
        .flat_map_iter(|c| {
            let mut ws = occupancy::Workspace::new();
            c.iter().map(|&p| target.bvh().closest_point(p, &mut ws).squared_distance.sqrt()).collect::<Vec<_>>()
        })
        .collect()
}

/// Samples of the input for [`InputSamples`].
const INPUT_SAMPLES: usize = 100_000;

/// A failed occupancy query while carving, as the fit's error.
fn failure(source: occupancy::OccupancyError) -> FitError {
    FitError::Occupancy { during: "carving", source }
}

/// A failed distance measurement while carving, as the fit's error.
fn measure_failure(source: metrics::MetricsError) -> FitError {
    FitError::Metrics { during: "carving", source }
}

/// Whether `c` (a point of triangle `t`) lies within `eps` of one of `t`'s edges that is in
/// `open` (sorted, as [`mesh_io::topology::boundary_edges`] gives them).
fn on_open_edge(mesh: &TriMesh, t: usize, c: [f64; 3], open: &[(u32, u32)], eps: f64) -> bool {
    let tri = mesh.triangles[t];
    (0..3).any(|k| {
        let (a, b) = (tri[k], tri[(k + 1) % 3]);
        if open.binary_search(&(a.min(b), a.max(b))).is_err() {
            return false;
        }
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let e = [0, 1, 2].map(|i| pb[i] - pa[i]);
        let w = [0, 1, 2].map(|i| c[i] - pa[i]);
        let ee = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        let s = if ee > 0.0 { ((w[0] * e[0] + w[1] * e[1] + w[2] * e[2]) / ee).clamp(0.0, 1.0) } else { 0.0 };
        distance_squared(c, [0, 1, 2].map(|i| pa[i] + s * e[i])) <= eps * eps
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use mesh_io::shapes::cuboid;

    /// Peels for the winding solid only of an open mesh; for the other solids always.
    #[test]
    fn peels_for_open_meshes_and_other_solids() {
        let closed = cuboid([0.3, 0.3, 0.3], [0.7, 0.7, 0.7]);
        let mut open = closed.clone();
        open.triangles.truncate(open.triangles.len() - 2);
        assert!(!peels_for(true, &closed));
        assert!(peels_for(true, &open));
        assert!(peels_for(false, &closed) && peels_for(false, &open));
    }

    /// A peel site stays strictly inside the domain box even where the crust vertex lies on
    /// the box's face, and one nearer an earlier peel than half its distance is dropped.
    #[test]
    fn peel_sites_stay_inside_the_box() {
        let plate = cuboid([0.3, 0.3, 0.5], [0.7, 0.7, 0.6]);
        let stray = |foot: [f64; 3], distance: f64| Stray {
            distance,
            foot,
            direction: [0.0, 1.0, 0.0],
            triangle: 0,
            at_input: false,
        };
        // Crust vertices at y = 1.0 (on the box's face) and 0.01 beside the first.
        let strays = [stray([0.5, 0.7, 0.55], 0.3), stray([0.51, 0.7, 0.55], 0.3), stray([0.5, 0.7, 0.55], 0.1)];
        let out = peel_sites(&strays, &plate, &[], 0.01, 10);
        assert_eq!(out.len(), 2, "{out:?}");
        assert!(out.iter().flatten().all(|&c| c > 0.0 && c < 1.0), "{out:?}");
        assert_eq!(out[0], [0.5, 1.0 - 1e-6, 0.55]);
        assert!((out[1][1] - 0.8).abs() < 1e-12, "{out:?}");
        // Nearer the input than PEEL_REACH tolerances: none.
        assert!(peel_sites(&strays, &plate, &[], 0.1, 10).is_empty());
    }

    /// The mirror closure of `pair` (outside site first) at the centre of a square plate
    /// `w` thick (top face at z = 0.5 + w), tolerance `t`.
    fn closure_on_a_plate(w: f64, t: f64, pair: [[f64; 3]; 2]) -> Vec<[f64; 3]> {
        let plate = cuboid([0.3, 0.3, 0.5], [0.7, 0.7, 0.5 + w]);
        let oracle = MeshOracle::from_mesh(&plate, &occupancy::Config::default()).unwrap();
        let solid = soft_voronoi::MeshSolid { oracle: &oracle };
        let samples = unburied_samples(&plate, &solid).unwrap();
        let index = soft_voronoi::SiteIndex::new(&samples.points);
        let mut new = pair.to_vec();
        mirror_closure(&oracle, &solid, &samples, &index, &mut new, t, 100).unwrap();
        new
    }

    #[test]
    fn a_pair_in_a_thin_wall_gets_the_mirror_across_its_far_face() {
        let t = 0.004;
        // 1.5 t thick: the inside site, t under the top face, is 0.5 t over the bottom one;
        // its mirror across it (outside, 0.5 t under the plate) is added, and nothing else
        // (the mirrors across the top face are the pair itself; the others would have the
        // wrong label).
        let top = 0.5 + 1.5 * t;
        let pair = [[0.5, 0.5, top + t], [0.5, 0.5, top - t]];
        let new = closure_on_a_plate(1.5 * t, t, pair);
        assert_eq!(new.len(), 3, "{new:?}");
        assert_eq!(&new[..2], &pair);
        assert!((0..3).all(|k| (new[2][k] - [0.5, 0.5, 0.5 - 0.5 * t][k]).abs() < 1e-9), "{new:?}");
        // On a plate 10 t thick no face but the top is within reach: nothing is added.
        let top = 0.5 + 10.0 * t;
        let pair = [[0.5, 0.5, top + t], [0.5, 0.5, top - t]];
        assert_eq!(closure_on_a_plate(10.0 * t, t, pair), pair.to_vec());
    }

    #[test]
    fn a_pair_by_an_edge_is_turned_to_bisect_it() {
        let cube = cuboid([0.3; 3], [0.7; 3]);
        let oracle = MeshOracle::from_mesh(&cube, &occupancy::Config::default()).unwrap();
        let t = 0.004;
        // Feet on the top face: 0.3 t from the edge x = 0.7 (the inside site would stand
        // 0.3 t from the side face), and in the middle of the face.
        let feet = [[0.7 - 0.3 * t, 0.5, 0.7], [0.5, 0.5, 0.7]];
        let mut new: Vec<[f64; 3]> =
            feet.iter().flat_map(|c| [1.0, -1.0].map(|s| [c[0], c[1], c[2] + s * t])).collect();
        let straight = new.clone();
        aim_at_edges(&oracle, &cube, &feet, &mut new, t).unwrap();
        let h = std::f64::consts::FRAC_1_SQRT_2 * t;
        let turned = [[feet[0][0] + h, 0.5, 0.7 + h], [feet[0][0] - h, 0.5, 0.7 - h]];
        for (a, b) in new[..2].iter().zip(&turned) {
            assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-12), "{new:?}");
        }
        assert_eq!(new[2..], straight[2..]);
        // Both sites of the turned pair are now clear of the input.
        assert!(clearance_mask(&oracle, &new, t).unwrap().iter().all(|&c| c));
    }

    #[test]
    fn the_f_score_slack_grows_with_what_the_crust_misses() {
        assert_eq!(f_slack(1.0), F_SLACK);
        assert_eq!(f_slack(0.99), F_SLACK);
        assert!((f_slack(0.84) - 0.008).abs() < 1e-12);
    }

    #[test]
    fn buried_faces_are_left_out_of_the_input_side() {
        let outer = cuboid([0.1; 3], [0.9; 3]);
        let inner = cuboid([0.4; 3], [0.6; 3]);
        let n = outer.positions.len() as u32;
        let both = TriMesh {
            positions: outer.positions.iter().chain(&inner.positions).copied().collect(),
            triangles: outer
                .triangles
                .iter()
                .copied()
                .chain(inner.triangles.iter().map(|t| t.map(|v| v + n)))
                .collect(),
        };
        let solid_of = |m: &TriMesh| MeshOracle::from_mesh(m, &occupancy::Config::default()).unwrap();
        let oracle = solid_of(&both);
        let kept = unburied_samples(&both, &soft_voronoi::MeshSolid { oracle: &oracle }).unwrap();
        assert!(kept.any_buried);
        assert_eq!(kept.points.len(), kept.normals.len());
        assert_eq!(kept.points.len(), kept.triangles.len());
        // The inner box is 0.24 of 4.08 of the area; every kept sample is on the outer box.
        let share = 1.0 - kept.points.len() as f64 / INPUT_SAMPLES as f64;
        assert!((share - 0.24 / 4.08).abs() < 0.005, "{share}");
        let on_outer = |p: &[f64; 3]| p.iter().any(|&x| (x - 0.1).abs() < 1e-12 || (x - 0.9).abs() < 1e-12);
        assert!(kept.points.iter().all(on_outer));
        assert!(kept.triangles.iter().all(|&t| (t as usize) < outer.triangles.len()));
        // Without buried faces: every sample is kept, and the certified distance is used.
        let oracle = solid_of(&outer);
        let all = unburied_samples(&outer, &soft_voronoi::MeshSolid { oracle: &oracle }).unwrap();
        assert!(!all.any_buried && all.points.len() == INPUT_SAMPLES);
    }
}
