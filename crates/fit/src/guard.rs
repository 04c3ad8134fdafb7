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
    let mut report = GuardReport { box_lo: lo, box_hi: hi, threshold, ..Default::default() };
    let beyond = |v: [f64; 3]| (0..3).fold(0.0f64, |m, k| m.max(lo[k] - v[k]).max(v[k] - hi[k]));
    let mut existing: std::collections::HashSet<[u64; 3]> = sites.iter().map(|p| p.map(f64::to_bits)).collect();
    for round in 0..=GUARD_ROUNDS {
        let crust = Crust::extract(sites, labels, &CrustConfig::default())
            .map_err(|source| FitError::Crust { during: "guarding the box", source })?;
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
            // The inside sites nearest to v: the inside sites of its tetrahedron (at most
            // four unless the sites are cospherical; eight are asked for).
            tree.k_nearest(v, 8, &mut near);
            let nearest = near.first().map_or(f64::INFINITY, |n| n.0);
            let owners: Vec<[f64; 3]> =
                near.iter().filter(|n| n.0 <= nearest * (1.0 + 1e-9) + 1e-30).map(|n| inside[n.1 as usize]).collect();
            for s in &owners {
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
    Ok(report)
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
}
