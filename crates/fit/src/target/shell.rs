//! The thin shell's sites as constructed: triplets across the sheet, graded by how far
//! it bends, and quadruplets along its open rim.

use rayon::prelude::*;

use mesh_io::TriMesh;
use soft_voronoi::init::greedy_disk;
use soft_voronoi::{ShellSolid, Solid, TrainingData};
use vf_common::rng::{ChunkRng, Stream};
use vf_common::vec3::distance;

use super::*;
use crate::grading;

/// What the shell's sites are placed from, whatever the band's thickness: the candidate
/// rim points (corners first, with their two edges' outward directions) and how much the
/// sheet bends around every candidate surface and rim point ([`crate::grading`]).
pub(super) struct ShellPlan {
    /// The spacing ladder, widest (2s) first.
    radii: [f64; grading::LEVELS],
    /// Bending of the sheet around each candidate surface point, per radius.
    surface_bend: Vec<[f64; grading::LEVELS]>,
    /// Candidate rim points, the corners first.
    rim: Vec<RimPoint>,
    /// The outward directions of each corner's two edges (the first `corner_edges.len()`
    /// of `rim`).
    corner_edges: Vec<[[f64; 3]; 2]>,
    /// Bending around each rim candidate: of the sheet, or of the rim in the sheet's plane.
    rim_bend: Vec<[f64; grading::LEVELS]>,
    /// The rim candidates' positions, indexed: the rim itself for [`clear_of_rim`].
    rim_at: Vec<[f64; 3]>,
    line: Option<soft_voronoi::SiteIndex>,
    /// Distance of each surface candidate from the rim (its nearest rim candidate).
    to_rim: Vec<f64>,
}

impl ShellPlan {
    pub(super) fn new(unit: &TriMesh, area: f64, surface: &[[f64; 3]], normals: &[[f64; 3]], k: usize) -> ShellPlan {
        let rim = boundary_edges(unit);
        let length: f64 = rim.iter().map(|e| distance(e.0, e.1)).sum();
        let b = 4.0 * length / RIM_SPACING;
        let u = (-b + (b * b + 12.0 * area * k as f64).sqrt()) / (6.0 * area).max(1e-300);
        let s = 1.0 / u.max(1e-300);
        let radii = grading::ladder(2.0 * s);
        // Rim candidates every quarter of the finest rim spacing along each boundary edge (at
        // least one per edge). The rim's corners come first and are always kept: without a
        // point there the band stays open around the corner (the benchmark's sheet grew a
        // spike of 4.6% of the diagonal past a corner at K = 2,048).
        let frames = rim_with_frames(unit, &rim);
        let corners = rim_corners(&frames);
        let mut candidates: Vec<RimPoint> = corners.iter().map(|c| c.0).collect();
        let step = RIM_SPACING * radii[grading::LEVELS - 1] / 4.0;
        for &(a, b, n, d) in &frames {
            let count = (distance(a, b) / step).ceil().max(1.0) as usize;
            for j in 0..count {
                let t = (j as f64 + 0.5) / count as f64;
                candidates.push(([0, 1, 2].map(|c| a[c] + t * (b[c] - a[c])), n, d));
            }
        }
        // Every fourth candidate as the neighbours measured (the candidates are random and
        // about 36 to a uniform spacing's square: the same answer at a quarter of the cost).
        let cloud: Vec<[f64; 3]> = surface.iter().step_by(grading::CLOUD_STRIDE).copied().collect();
        let surface_bend = grading::spread(surface, &grading::bending(surface, normals, &cloud, &radii), &radii);
        let at: Vec<[f64; 3]> = candidates.iter().map(|c| c.0).collect();
        let (rim_n, rim_d): (Vec<[f64; 3]>, Vec<[f64; 3]>) = candidates.iter().map(|c| (c.1, c.2)).unzip();
        let sheet = grading::bending(&at, &rim_n, &cloud, &radii);
        let turn = grading::bending(&at, &rim_d, &at, &radii);
        let rim_bend = sheet.iter().zip(&turn).map(|(a, b)| std::array::from_fn(|l| a[l].max(b[l]))).collect();
        let line = (!at.is_empty()).then(|| soft_voronoi::SiteIndex::new(&at));
        let to_rim = match &line {
            Some(index) => surface.par_iter().map(|&x| index.nearest(&at, x).1).collect(),
            None => vec![f64::INFINITY; surface.len()],
        };
        ShellPlan {
            radii,
            surface_bend,
            rim: candidates,
            corner_edges: corners.iter().map(|c| c.1).collect(),
            rim_bend,
            rim_at: at,
            line,
            to_rim,
        }
    }
}

/// The rim points and triplet centres for the band of half-thickness `h` (indices into the
/// plan's rim candidates and into the surface candidates), within K sites.
///
/// Each candidate's spacing is the widest over which the sheet (and for a rim point, the
/// rim) bends less than [`grading::BEND_SHARE`]·h, clamped to [lo, hi]: hi is lowered from
/// 2s (flat parts give sites to curved ones) to the densest layout that fits in K; if the
/// bends need more than K even so, lo is raised instead (the band's thinnest parts then
/// rest on fewer triplets than they need, and the band's check will tell). Rim points lie
/// at [`RIM_SPACING`] times the spacing (at most that of the uniform spacing s), spread
/// wider where the rim would take more than a third of K. The triplets keep their spacing
/// from the rim points and stay [`clear_of_rim`]: an inside site nearer the rim than the
/// rim points are to each other has a cell running on beyond the rim, between the rim
/// points' outside sites (the sheets' farthest crust points were there: libigl's grid.off
/// 3.3h beyond its edges by each corner).
pub(super) fn shell_layout(plan: &ShellPlan, surface: &[[f64; 3]], h: f64, k: usize) -> Layout {
    let limit = grading::BEND_SHARE * h;
    let radii = &plan.radii;
    let cap_surface: Vec<f64> = plan.surface_bend.iter().map(|b| grading::widest_flat(b, radii, limit)).collect();
    let cap_rim: Vec<f64> = plan.rim_bend.iter().map(|b| grading::widest_flat(b, radii, limit)).collect();
    let rim_at = &plan.rim_at;
    let corners = plan.corner_edges.len();
    let layout = |lo: f64, hi: f64| -> Layout {
        let mut spread = 1.0;
        let (rim, rim_sites) = loop {
            // Never sparser than the uniform spacing's rim (radii[2] = s): between rim points
            // 2s apart, as a flat part's spacing would allow, a petal's tip of libigl's
            // lilium grew a spike of 2.9% of the diagonal at K = 2,048 (1.7% before).
            let r: Vec<f64> = cap_rim.iter().map(|c| spread * RIM_SPACING * c.clamp(lo, hi).min(radii[2])).collect();
            let mut rim = grading::graded_subset(&[], &rim_at[..corners], &r[..corners]);
            let kept: Vec<[f64; 3]> = rim.iter().map(|&i| rim_at[i as usize]).collect();
            rim.extend(
                grading::graded_subset(&kept, &rim_at[corners..], &r[corners..])
                    .into_iter()
                    .map(|i| i + corners as u32),
            );
            let sites = 4 * rim.len() + 2 * rim.iter().filter(|&&i| (i as usize) < corners).count();
            // More rim than a third of the budget: spread the rim points wider (a cap of a
            // quarter of the budget left the rim of libigl's beetle too sparse at K = 2,048).
            if sites <= k / 3 || spread > 64.0 {
                break (rim, sites);
            }
            spread *= 1.25;
        };
        let kept: Vec<[f64; 3]> = rim.iter().map(|&i| rim_at[i as usize]).collect();
        let clear = clear_of_rim(&kept, plan, h, surface);
        let ids: Vec<u32> = (0..surface.len() as u32).filter(|&i| clear[i as usize]).collect();
        let pts: Vec<[f64; 3]> = ids.iter().map(|&i| surface[i as usize]).collect();
        let r: Vec<f64> = ids.iter().map(|&i| cap_surface[i as usize].clamp(lo, hi)).collect();
        let triplets: Vec<u32> = grading::graded_subset(&kept, &pts, &r).into_iter().map(|j| ids[j as usize]).collect();
        let total = rim_sites + 3 * triplets.len();
        Layout { rim, triplets, total, clear }
    };
    let (finest, widest) = (radii[grading::LEVELS - 1], radii[0]);
    let at_widest = layout(finest, widest);
    // Within K at the widest spacing: lower hi (log-bisection) to the densest layout within
    // K. Too many bends for K: raise lo until it fits (at lo = hi = 2s it always does).
    let fits = at_widest.total <= k;
    let mut best = fits.then_some(at_widest);
    let (mut a, mut b) = (finest.ln(), widest.ln());
    for _ in 0..9 {
        let mid = 0.5 * (a + b);
        let got = if fits { layout(finest, mid.exp()) } else { layout(mid.exp(), widest) };
        if got.total <= k {
            b = mid;
            best = Some(got);
        } else {
            a = mid;
        }
    }
    let Layout { mut rim, mut triplets, clear, .. } = best.unwrap_or_else(|| layout(widest, widest));
    // Within K even when the last layout overshoots (a rim alone over K): rim points beyond
    // K are dropped (a corner's two extra sites are placed only where room is left).
    rim.truncate(k / 4);
    let rim_sites = 4 * rim.len() + 2 * rim.iter().filter(|&&i| (i as usize) < corners).count();
    triplets.truncate(k.saturating_sub(rim_sites) / 3);
    Layout { rim, triplets, total: 0, clear }
}

/// A thin shell's layout: rim points (indices into the plan's rim candidates), triplet
/// centres (into the surface candidates), the sites they take, and which surface
/// candidates lie clear of the rim ([`clear_of_rim`]).
pub(super) struct Layout {
    rim: Vec<u32>,
    triplets: Vec<u32>,
    total: usize,
    clear: Vec<bool>,
}

/// Which of the `surface` candidates lie far enough from the rim for a triplet of the band
/// of half-thickness `h`, given the rim points kept (`rim`) and the rim itself (the plan's
/// rim candidates, closer together than the rim points, and each candidate's distance from
/// them). A point y = c + e·d beyond the rim (c on the rim, d outward) is nearer an inside
/// site x, at distance a from the rim, than the outside sites 2h beyond the rim points, τ_c
/// from c, when about
/// |x − c|² + e² + 2a·e < τ_c² + (2h − e)²: x's cell runs on past the band's end (e = h)
/// unless |x − c|² + 2a·h ≥ τ_c² for every c. Points for which that fails are not clear;
/// the rim points' own cells cover them. A repair triplet 0.003 from the bottom edge of
/// libigl's beetle at K = 2,048 grew a spike of 8.7% of the diagonal, and on a square sheet
/// at K = 1,024 a triplet 0.042 from the edge, across from the middle of a gap of 0.125
/// between rim points, one of 4h. (Outside sites alone beyond the rim between spread rim
/// points, a "fence" a quarter of a rim point's cost, were tried: they bit notches into the
/// strip, which no inside site was near enough to hold, and a square sheet's normal
/// consistency fell from 0.981 to 0.958.)
pub(super) fn clear_of_rim(rim: &[[f64; 3]], plan: &ShellPlan, h: f64, surface: &[[f64; 3]]) -> Vec<bool> {
    let (Some(along), false) = (&plan.line, rim.is_empty()) else {
        return vec![true; plan.to_rim.len()];
    };
    let line = &plan.rim_at;
    let kept = soft_voronoi::SiteIndex::new(rim);
    let tau: Vec<f64> = line.par_iter().map(|&c| kept.nearest(rim, c).1).collect();
    let reach = tau.iter().copied().fold(0.0, f64::max);
    plan.to_rim
        .par_iter()
        .enumerate()
        .map_init(Vec::new, |near, (i, &a)| {
            if a >= reach {
                return true;
            }
            along.candidates(line, surface[i], reach - a, near);
            near.iter().all(|&(c, d)| d * d + 2.0 * a * h >= tau[c as usize] * tau[c as usize])
        })
        .collect()
}

/// Initial sites for the shell of half-thickness h around `unit`: at Poisson-disk points p
/// of the surface (from `surface`, area-uniform, with `normals`) an inside site at p and
/// outside sites at p ± 2h·n, whose bisectors are the shell's two sides (exactly, on a flat
/// part, whatever the spacing); along open boundary edges (meshes welded by position) the
/// same plus an outside site 2h beyond the edge in the surface's plane, which closes the
/// band there, and at a rim's corner one more beyond each of its two edges. The points are
/// spaced by how much the sheet bends ([`shell_layout`]) within K less a reserve for
/// repairs: triplets where surface samples are left in a hole. Labels come from the solid;
/// an outside site it holds is left out ([`append_unless_held`]). Unused slots are filled
/// with training samples far from the band. Returns sites, labels and the counts of triplets (repairs
/// included) and rim points.
pub(super) fn shell_sites(
    plan: &ShellPlan,
    surface: &[[f64; 3]],
    normals: &[[f64; 3]],
    solid: &ShellSolid,
    k: usize,
    data: &TrainingData,
    seed: u64,
) -> (Vec<[f64; 3]>, Vec<bool>, (usize, usize)) {
    let h = solid.half_thickness;
    let Layout { rim, triplets: chosen, clear, .. } = shell_layout(plan, surface, h, k - k / SHELL_REPAIR_RESERVE);
    let rim_points: Vec<RimPoint> = rim.iter().map(|&i| plan.rim[i as usize]).collect();
    // A corner's two edges each get an outside site 2h beyond them as well: the one along
    // the mean direction alone left the band running on past both edges near the corner
    // (libigl's grid.off: 3.3h beyond its edges by each corner, its Hausdorff distance).
    let corner_edges: Vec<([f64; 3], [[f64; 3]; 2])> = rim
        .iter()
        .filter(|&&i| (i as usize) < plan.corner_edges.len())
        .map(|&i| (plan.rim[i as usize].0, plan.corner_edges[i as usize]))
        .collect();
    let clamp = |p: [f64; 3]| p.map(|x| x.clamp(1e-6, 1.0 - 1e-6));
    let along = |p: [f64; 3], v: [f64; 3], f: f64| clamp([0, 1, 2].map(|c| p[c] + f * v[c]));
    let triplet = |p: [f64; 3], n: [f64; 3]| [clamp(p), along(p, n, 2.0 * h), along(p, n, -2.0 * h)];
    let (mut new, mut centre) = (Vec::with_capacity(k), Vec::with_capacity(k));
    for &i in &chosen {
        new.extend(triplet(surface[i as usize], normals[i as usize]));
        centre.extend([true, false, false]);
    }
    for &(p, n, d) in &rim_points {
        new.extend(triplet(p, n));
        new.push(along(p, d, 2.0 * h));
        centre.extend([true, false, false, false]);
    }
    for &(p, edges) in &corner_edges {
        if new.len() + 2 <= k {
            new.extend(edges.map(|d| along(p, d, 2.0 * h)));
            centre.extend([false, false]);
        }
    }
    let (mut sites, mut labels) = (Vec::with_capacity(k), Vec::with_capacity(k));
    append_unless_held(&mut sites, &mut labels, &new, &centre, solid);
    // Repairs: a surface point whose nearest site is outside lies in a hole through the band
    // (the sheet bends more between triplets than the spacing's measure saw, or two
    // triplets' spacings differ too much); a triplet there closes it. Up to the reserve of K.
    let mut repaired = 0;
    for _ in 0..SHELL_REPAIR_ROUNDS {
        let room = k.saturating_sub(sites.len()) / 3;
        if room == 0 || sites.is_empty() {
            break;
        }
        let index = soft_voronoi::SiteIndex::new(&sites);
        // Not by the rim (see [`clear_of_rim`]): the rim points' own cells cover it.
        let holes: Vec<usize> = (0..surface.len())
            .into_par_iter()
            .filter(|&i| clear[i] && !labels[index.nearest(&sites, surface[i]).0 as usize])
            .collect();
        if holes.is_empty() {
            break;
        }
        let at: Vec<[f64; 3]> = holes.iter().map(|&i| surface[i]).collect();
        let mut fix = greedy_disk(&at, plan.radii[grading::LEVELS - 1]);
        fix.truncate(room);
        let new: Vec<[f64; 3]> =
            fix.iter().flat_map(|&j| triplet(surface[holes[j as usize]], normals[holes[j as usize]])).collect();
        let centre: Vec<bool> = fix.iter().flat_map(|_| [true, false, false]).collect();
        append_unless_held(&mut sites, &mut labels, &new, &centre, solid);
        repaired += fix.len();
    }
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 5);
    // The slots the triplets, rim points and repairs leave (up to the unused repair reserve)
    // get pool points outside the band and far from it, labelled outside: they only split
    // empty space. A pool point inside the band, off the triplets' lines, put a speck in the
    // flat crust of libigl's grid.off (the one fill site, 0.0015 from the sheet); a point
    // that close outside would dent it. Points elsewhere (labelled by the band) only if the pool has none so far.
    let missing = k.saturating_sub(sites.len());
    // Farther from the band than the widest spacing between triplet centres, so no sheet
    // point is nearer a fill site than its nearest centre (at 2h only, fill sites punched
    // holes between the widely spaced centres of a flat part).
    let clearance = plan.radii[0] + h;
    let mut far = Vec::with_capacity(missing);
    let mut tried = 0;
    while far.len() < missing && tried < 64 * missing.max(1) && !data.points.is_empty() {
        let batch: Vec<[f64; 3]> =
            (0..256).map(|_| data.points[(rng.next_u64() % data.points.len() as u64) as usize]).collect();
        tried += batch.len();
        for (p, l) in batch.iter().zip(solid.locate(&batch)) {
            if far.len() < missing && !l.inside && distance(*p, l.closest) >= clearance && !far.contains(p) {
                far.push(*p);
            }
        }
    }
    labels.extend(std::iter::repeat_n(false, far.len()));
    sites.extend(far);
    let filled = sites.len();
    while sites.len() < k && !data.points.is_empty() {
        sites.push(data.points[(rng.next_u64() % data.points.len() as u64) as usize]);
    }
    // Labelled by this band (the pool's labels may be another solid's).
    labels.extend(solid.inside(&sites[filled..]));
    (sites, labels, (chosen.len() + repaired, rim_points.len()))
}

/// A shell's layout leaves K/`SHELL_REPAIR_RESERVE` sites for the triplets that close its
/// holes.
pub(super) const SHELL_REPAIR_RESERVE: usize = 8;

/// Rounds of hole repair in a shell's sites.
pub(super) const SHELL_REPAIR_ROUNDS: usize = 6;

/// Appends `new` sites with their labels by `solid`, leaving out every one that is not a
/// triplet's or rim point's centre (`centre`) yet lies inside the band: an outside site the
/// band holds (by a fold, a wheel arch's turn of the rim: another part of the sheet within
/// h of it), labelled inside with no outside site beyond it, has a cell running on far from
/// the sheet (libigl's beetle at K = 2,048: a spike of 13% of the diagonal from one 0.015
/// from its bottom edge).
pub(super) fn append_unless_held(
    sites: &mut Vec<[f64; 3]>,
    labels: &mut Vec<bool>,
    new: &[[f64; 3]],
    centre: &[bool],
    solid: &ShellSolid,
) {
    for ((&p, &c), l) in new.iter().zip(centre).zip(solid.inside(new)) {
        if c || !l {
            sites.push(p);
            labels.push(l);
        }
    }
}

/// Spacing of the shell's rim points as a share of the triplets' spacing s. Measured by
/// the misclassification against the shell and the Hausdorff distance to the sheet (share
/// of the diagonal), default settings, K = 8,192, against one point per boundary edge at
/// least as before: libigl's beetle body 1.22% / 3.6% → 0.90% / 2.2% (triplets 1,216 →
/// 2,061, rim points 1,136 → 502), lilium 0.405% / 1.26% → 0.396% / 1.38%, the benchmark's
/// open sheet 0.198% / 1.97% → 0.20% / 1.52% (2.81% against 3.12% at K = 2,048), all with
/// the corners kept ([`rim_corners`]). Rim points at 1·s left the sheet's rim saw-toothed
/// with a spike at a corner (4.1%); at 0.35·s the beetle's misclassification rose again
/// (0.99%: fewer triplets).
pub(super) const RIM_SPACING: f64 = 0.5;
