//! Outside sites that keep the crust inside the input's bounding box.
//!
//! The solid never leaves the input's bounding box (the winding-number solid lies in the
//! input's convex hull: from a point outside it the whole mesh subtends less than a
//! half-sphere, so |w| < 1/2), but an inside cell can: where no outside site stands
//! between an inside site and the empty margin of the unit cube, its cell runs on to the
//! cube's boundary sites, and the crust bulges out of the box (the Menger sponge at K =
//! 8,192: 0.056 units below the bottom face at a corner, its whole Hausdorff distance; the
//! soup: 3.3% of the diagonal).
//!
//! For such a cell, the mirror image m of its inside site s across the box face it crosses
//! is an outside site (it lies outside the box, so outside the solid), and the bisector of
//! s and m is the face's plane: s's cell ends there. Nothing on the box's side of the
//! plane changes: a point x there is at least as near s as m, and its nearest site was at
//! least as near as s, so m is nobody's nearest in the box. The guard therefore only
//! removes crust outside the box, never dents the surface and never adds crust, which is
//! why, unlike carving, it needs no test of the result.
//!
//! Which cells: those of the inside sites nearest to a crust vertex beyond the box by more
//! than the carving tolerance (a Voronoi vertex is equidistant from its sites, and the
//! inside ones are the nearest inside sites). The mirrors must lie in the unit cube; one
//! that would not (an inside site farther from the face than half the cube's margin) is
//! counted as skipped. A few rounds, as cutting one cell can leave a neighbour's
//! protruding part as the next crust.

use crust::{Crust, CrustConfig};

use crate::error::FitError;
pub use crate::report::GuardReport;

/// Rounds of [`guard`] at most.
pub const GUARD_ROUNDS: usize = 4;

/// Appends outside mirror sites (module doc) to `sites` and `labels` until no crust vertex
/// lies more than `threshold` beyond the box [`lo`, `hi`] (unit-cube coordinates), for up
/// to [`GUARD_ROUNDS`] rounds. Only inside sites within the box are mirrored.
///
/// # Errors
/// [`FitError::Crust`] when a crust cannot be extracted.
pub fn guard(
    sites: &mut Vec<[f64; 3]>,
    labels: &mut Vec<bool>,
    lo: [f64; 3],
    hi: [f64; 3],
    threshold: f64,
) -> Result<GuardReport, FitError> {
    Ok(guard_keeping(sites, labels, lo, hi, threshold)?.0)
}

/// [`guard`], with the crust of the sites as it leaves them: every round ends with an
/// extraction, and the guard stops before inserting anything after the last one, so
/// carving's first round can start from it instead of extracting the same sites again.
///
/// # Errors
/// As [`guard`].
pub fn guard_keeping(
    sites: &mut Vec<[f64; 3]>,
    labels: &mut Vec<bool>,
    lo: [f64; 3],
    hi: [f64; 3],
    threshold: f64,
) -> Result<(GuardReport, Crust), FitError> {
    let mut report = GuardReport { box_lo: lo, box_hi: hi, threshold, ..Default::default() };
    let beyond = |v: [f64; 3]| (0..3).fold(0.0f64, |m, k| m.max(lo[k] - v[k]).max(v[k] - hi[k]));
    let mut existing: std::collections::HashSet<[u64; 3]> = sites.iter().map(|p| p.map(f64::to_bits)).collect();
    let mut last = None;
    for round in 0..=GUARD_ROUNDS {
        let crust = last.insert(
            Crust::extract(sites, labels, &CrustConfig::default())
                .map_err(|source| FitError::Crust { during: "guarding the box", source })?,
        );
        let far: Vec<[f64; 3]> = crust.mesh.positions.iter().copied().filter(|&v| beyond(v) > threshold).collect();
        let reach = crust.mesh.positions.iter().fold(0.0f64, |m, &v| m.max(beyond(v)));
        if round == 0 {
            report.beyond_before = reach;
        }
        report.beyond_after = reach;
        if far.is_empty() || round == GUARD_ROUNDS {
            break;
        }
        let inside: Vec<[f64; 3]> = sites
            .iter()
            .zip(labels.iter())
            .filter(|(p, &l)| l && (0..3).all(|k| p[k] > lo[k] && p[k] < hi[k]))
            .map(|(p, _)| *p)
            .collect();
        if inside.is_empty() {
            break;
        }
        let tree = soft_voronoi::knn::KnnTree::new(&inside);
        let mut near = Vec::new();
        let mut added = 0;
        for v in far {
            for s in &owners(&tree, &inside, v, &mut near) {
                for k in 0..3 {
                    for (plane, out) in [(lo[k], v[k] < lo[k]), (hi[k], v[k] > hi[k])] {
                        if !out {
                            continue;
                        }
                        let mut m = *s;
                        m[k] = 2.0 * plane - s[k];
                        if !(m[k] > 0.0 && m[k] < 1.0) {
                            report.skipped_outside_cube += 1;
                            continue;
                        }
                        if existing.insert(m.map(f64::to_bits)) {
                            sites.push(m);
                            labels.push(false);
                            added += 1;
                        }
                    }
                }
            }
        }
        report.inserted_per_round.push(added);
        if added == 0 {
            break;
        }
    }
    // Every way out of the loop follows an extraction with nothing inserted after it.
    let last = last.ok_or(FitError::Internal("the guard ran no round"))?;
    Ok((report, last))
}

/// Rounds of [`guard_solid`] at most.
pub const SOLID_GUARD_ROUNDS: usize = 6;

/// The same cut as [`guard`]'s across the solid's own surface: for each crust vertex v
/// outside `solid` and farther than `threshold` from it (an inside cell running out into
/// empty space, where training left too few outside sites: the fins of a soup's thin wings),
/// c its closest point on the solid's surface and n = (v − c)/|v − c|, each inside site s
/// nearest to v (its cell's owner) that lies behind the tangent plane P through c (depth
/// d = (c − s)·n > 0) gets the outside site m = s + (2 + j)·d·n, j ∈ [0, 0.01) a fixed
/// jitter per site. The bisector of s and m is P moved out by j·d/2, so nothing behind it
/// changes (as for the box: a point there is nearer s than m, and its nearest site at
/// least as near as s), and s's cell stops there. The jitter keeps two mirrors across one
/// plane from making four cospherical sites, whose Voronoi vertex float32 rounding can
/// break. A mirror is added only where it is outside the solid and at least d/2 from it
/// (its cell cannot reach the solid beyond the plane), within the unit cube and new. Up to
/// `rounds` rounds, as for the box. Returns the sites added per round and the farthest
/// crust vertex outside the solid before the first round and after the last, unit-cube
/// lengths.
///
/// # Errors
/// [`FitError::Crust`] when a crust cannot be extracted.
pub fn guard_solid(
    sites: &mut Vec<[f64; 3]>,
    labels: &mut Vec<bool>,
    solid: &dyn soft_voronoi::Solid,
    threshold: f64,
    rounds: usize,
) -> Result<(Vec<usize>, f64, f64), FitError> {
    let (mut added_per_round, mut before, mut after) = (Vec::new(), 0.0, 0.0);
    let mut existing: std::collections::HashSet<[u64; 3]> = sites.iter().map(|p| p.map(f64::to_bits)).collect();
    let d2 = |a: [f64; 3], b: [f64; 3]| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>();
    for round in 0..=rounds {
        let crust = Crust::extract(sites, labels, &CrustConfig::default())
            .map_err(|source| FitError::Crust { during: "guarding the solid", source })?;
        let located = solid.locate(&crust.mesh.positions);
        let outside = crust.mesh.positions.iter().zip(&located).filter(|(_, l)| !l.inside);
        let reach = outside.clone().fold(0.0f64, |m, (v, l)| m.max(d2(*v, l.closest)));
        if round == 0 {
            before = reach.sqrt();
        }
        after = reach.sqrt();
        let far: Vec<([f64; 3], [f64; 3])> =
            outside.filter(|(v, l)| d2(**v, l.closest) > threshold * threshold).map(|(v, l)| (*v, l.closest)).collect();
        if far.is_empty() || round == rounds {
            break;
        }
        let inside: Vec<[f64; 3]> = sites.iter().zip(labels.iter()).filter(|(_, &l)| l).map(|(p, _)| *p).collect();
        if inside.is_empty() {
            break;
        }
        let tree = soft_voronoi::knn::KnnTree::new(&inside);
        let mut near = Vec::new();
        let mut mirrors: Vec<([f64; 3], f64)> = Vec::new();
        for (v, c) in far {
            let len = d2(v, c).sqrt();
            let n = [0, 1, 2].map(|k| (v[k] - c[k]) / len);
            for s in owners(&tree, &inside, v, &mut near) {
                let depth: f64 = (0..3).map(|k| (c[k] - s[k]) * n[k]).sum();
                if depth <= 0.0 {
                    continue;
                }
                let offset = (2.0 * depth).max(threshold) * (1.0 + jitter(s));
                let m = [0, 1, 2].map(|k| s[k] + offset * n[k]);
                if m.iter().all(|&x| x > 0.0 && x < 1.0) {
                    mirrors.push((m, offset));
                }
            }
        }
        let points: Vec<[f64; 3]> = mirrors.iter().map(|m| m.0).collect();
        let mut added = 0;
        // Not near a site already there (nor one added this round): two sites much nearer
        // each other than their neighbours make Voronoi features finer than float32 holds.
        let all = soft_voronoi::knn::KnnTree::new(sites);
        let mut new: Vec<[f64; 3]> = Vec::new();
        for ((m, offset), l) in mirrors.into_iter().zip(solid.locate(&points)) {
            let min2 = 0.0625 * offset * offset;
            if l.inside || d2(m, l.closest) < min2 {
                continue;
            }
            all.k_nearest(m, 1, &mut near);
            if near.first().is_some_and(|n| n.0 < min2) || new.iter().any(|&q| d2(q, m) < min2) {
                continue;
            }
            if existing.insert(m.map(f64::to_bits)) {
                new.push(m);
                added += 1;
            }
        }
        for m in new {
            sites.push(m);
            labels.push(false);
        }
        added_per_round.push(added);
        if added == 0 {
            break;
        }
    }
    Ok((added_per_round, before, after))
}

/// The inside sites nearest to the crust vertex `v`, the owners of the cells that meet
/// there: the inside sites of its tetrahedron (at most four unless the sites are
/// cospherical; eight are asked for). `near` is scratch space.
fn owners(
    tree: &soft_voronoi::knn::KnnTree,
    inside: &[[f64; 3]],
    v: [f64; 3],
    near: &mut Vec<(f64, u32)>,
) -> Vec<[f64; 3]> {
    tree.k_nearest(v, 8, near);
    let nearest = near.first().map_or(f64::INFINITY, |n| n.0);
    near.iter().filter(|n| n.0 <= nearest * (1.0 + 1e-9) + 1e-30).map(|n| inside[n.1 as usize]).collect()
}

/// A fixed number in [0, 0.01) for a site, from its coordinates' bits (splitmix64).
fn jitter(s: [f64; 3]) -> f64 {
    let mut z = s.iter().fold(0x9E37_79B9_7F4A_7C15u64, |h, x| h.rotate_left(21) ^ x.to_bits());
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    0.01 * (z >> 11) as f64 / (1u64 << 53) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cell_reaching_past_the_box_is_cut_at_its_face_and_nothing_else_moves() {
        // Two inside sites in a box [0.3, 0.7]³ and outside sites only around its sides
        // and top: the cells run down to the cube's bottom. The guard must cut them at
        // z = 0.3 and leave the crust inside the box as it was.
        let (lo, hi) = ([0.3; 3], [0.7; 3]);
        let mut sites = vec![[0.45, 0.5, 0.35], [0.55, 0.5, 0.35]];
        let mut labels = vec![true, true];
        for &(x, y) in &[(0.2, 0.5), (0.8, 0.5), (0.5, 0.2), (0.5, 0.8), (0.2, 0.2), (0.8, 0.8), (0.2, 0.8), (0.8, 0.2)]
        {
            for z in [0.35, 0.6] {
                sites.push([x, y, z]);
                labels.push(false);
            }
        }
        sites.push([0.5, 0.5, 0.8]);
        labels.push(false);
        for corner in 0..8 {
            sites.push([0, 1, 2].map(|k| if corner >> k & 1 == 1 { 0.98 } else { 0.02 }));
            labels.push(false);
        }
        let before = Crust::extract(&sites, &labels, &CrustConfig::default()).unwrap();
        let low = |c: &Crust| c.mesh.positions.iter().fold(1.0f64, |m, p| m.min(p[2]));
        assert!(low(&before) < 0.25, "the setup must reach below the box: {}", low(&before));
        let n = sites.len();
        let r = guard(&mut sites, &mut labels, lo, hi, 1e-3).unwrap();
        assert!(r.inserted_per_round[0] >= 2, "{r:?}");
        assert!(r.beyond_before > 0.2 && r.beyond_after <= 1e-3, "{r:?}");
        // The mirrors: outside, below the box's floor.
        assert!(sites[n..].iter().zip(&labels[n..]).all(|(p, &l)| !l && p[2] < 0.3), "{:?}", &sites[n..]);
        let after = Crust::extract(&sites, &labels, &CrustConfig::default()).unwrap();
        assert!(low(&after) >= 0.3 - 1e-12, "{}", low(&after));
        // Inside the box the occupancy is unchanged: nearest-site labels at random points.
        let nearest = |s: &[[f64; 3]], l: &[bool], x: [f64; 3]| {
            let d = |p: &[f64; 3]| (0..3).map(|k| (p[k] - x[k]).powi(2)).sum::<f64>();
            let i = (0..s.len()).min_by(|&a, &b| d(&s[a]).total_cmp(&d(&s[b]))).unwrap();
            l[i]
        };
        let mut state = 12345u64;
        for _ in 0..20_000 {
            let x = [0, 1, 2].map(|_| {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                0.3 + 0.4 * ((state >> 11) as f64 / (1u64 << 53) as f64)
            });
            assert_eq!(nearest(&sites[..n], &labels[..n], x), nearest(&sites, &labels, x), "{x:?}");
        }
        // A second call finds nothing to do.
        let again = guard(&mut sites, &mut labels, lo, hi, 1e-3).unwrap();
        assert!(again.inserted_per_round.is_empty(), "{again:?}");
    }

    /// The label of the nearest site at each point (ties to the lower index).
    fn labels_at(sites: &[[f64; 3]], labels: &[bool], points: &[[f64; 3]]) -> Vec<bool> {
        let tree = soft_voronoi::knn::KnnTree::new(sites);
        let mut near = Vec::new();
        points
            .iter()
            .map(|&p| {
                tree.k_nearest(p, 1, &mut near);
                labels[near[0].1 as usize]
            })
            .collect()
    }

    #[test]
    fn a_cell_running_out_of_the_solid_is_cut_at_its_tangent_plane_and_the_solid_keeps_its_labels() {
        // A ball of radius 0.2: inside sites on a sphere of radius 0.15 and at the centre,
        // outside sites on one of radius 0.27 except in a cone around +x, where the inside
        // cells run out to the cube's corner sites. The solid guard must cut them back near
        // the ball without changing the label of any point in the ball (every mirror's
        // bisector lies beyond a tangent plane).
        let ball = soft_voronoi::solid::Sphere { center: [0.5; 3], radius: 0.2 };
        let fib = |n: usize, r: f64| -> Vec<[f64; 3]> {
            (0..n)
                .map(|i| {
                    let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                    let (rho, phi) = ((1.0 - z * z).sqrt(), i as f64 * 2.399_963_229_728_653);
                    [0.5 + r * z, 0.5 + r * rho * phi.cos(), 0.5 + r * rho * phi.sin()]
                })
                .collect()
        };
        let mut sites = vec![[0.5; 3]];
        let mut labels = vec![true];
        for p in fib(200, 0.15) {
            sites.push(p);
            labels.push(true);
        }
        for p in fib(300, 0.27).into_iter().filter(|p| p[0] < 0.5 + 0.27 * 0.6) {
            sites.push(p);
            labels.push(false);
        }
        for corner in 0..8 {
            sites.push([0, 1, 2].map(|k| if corner >> k & 1 == 1 { 0.98 } else { 0.02 }));
            labels.push(false);
        }
        let threshold = 0.01;
        let beyond = |sites: &[[f64; 3]], labels: &[bool]| {
            let crust = Crust::extract(sites, labels, &CrustConfig::default()).unwrap();
            crust.mesh.positions.iter().fold(0.0f64, |m, &v| m.max(ball.center_distance(v) - ball.radius))
        };
        let before = beyond(&sites, &labels);
        assert!(before > 0.1, "the setup must run out of the ball: {before}");
        // Probes in the ball, on a grid.
        let probes: Vec<[f64; 3]> = (0..20 * 20 * 20)
            .map(|i| [i % 20, i / 20 % 20, i / 400].map(|c| 0.3 + 0.4 * (c as f64 + 0.5) / 20.0))
            .filter(|&p| ball.center_distance(p) < ball.radius)
            .collect();
        let inside_before = labels_at(&sites, &labels, &probes);
        let n = sites.len();
        let (per_round, from, to) = guard_solid(&mut sites, &mut labels, &ball, threshold, SOLID_GUARD_ROUNDS).unwrap();
        assert!(per_round[0] > 0 && sites.len() > n && labels[n..].iter().all(|&l| !l), "{per_round:?}");
        assert!((from - before).abs() < 1e-12, "{from} against {before}");
        assert!(to < 0.5 * before && (to - beyond(&sites, &labels)).abs() < 1e-12, "{before} -> {to}");
        assert_eq!(labels_at(&sites, &labels, &probes), inside_before, "a point of the ball changed its label");
    }
}
