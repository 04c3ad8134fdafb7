//! The winding solid of an open mesh: samples on the caps across its holes (the |w| = 0.5
//! level set) and on the rims where the caps meet the input's open edges.

use mesh_io::TriMesh;
use occupancy::MeshOracle;
use soft_voronoi::init::greedy_disk;
use soft_voronoi::TrainingData;
use vf_common::rng::{ChunkRng, Stream};
use vf_common::vec3::{cross, distance, normalize};

use super::rim::{boundary_edges, rim_with_frames, RimEdge};
use crate::error::FitError;

/// Points where the winding solid's boundary leaves the input: across the holes of an
/// open mesh the solid is closed by the |w| = 0.5 level set, a smooth cap with no input
/// surface and so no surface samples, pairs or polish targets; its crust came out as fans
/// of long Voronoi faces between the sites at the hole's rim (libigl's halftunnel and
/// camelhead).
///
/// Uniform pool points with ||w| − 0.5| < [`CAP_BAND`] farther than [`CAP_CLEARANCE`]
/// pair spacings from the input are moved onto the level set by Newton steps along the
/// gradient of |w| (central differences at a quarter spacing): one step, then thinned to
/// one point per `radius` (greedy, in pool order), then up to [`CAP_NEWTON_STEPS`] − 1
/// more. A point is kept when its distance to the level set, estimated as
/// ||w| − 0.5| / |∇w|, is at most [`CAP_PRECISION`] spacings and it is still that far from
/// the input, with the gradient's direction as its normal.
///
/// Then the caps get the input's sample density, `area_per_sample` of area per sample: a
/// point the first step keeps stands for 1 / (2·ρ·min([`CAP_BAND`]/|∇w|, 2e)) of the
/// level set (ρ: the pool's points per unit volume; the step keeps the points of a slab
/// that thick, e the probes' offset), so the caps' area is the sum over those points,
/// shared evenly by the kept points; each kept point is joined by points uniform in its
/// tangent disk of that area (the cap is smooth: at the disk's radius, a fraction of a
/// spacing, it leaves the plane by far less than the carving tolerance). Returns (points,
/// normals, how many of them are the kept points, which come first), unit frame.
///
/// # Errors
/// [`FitError::Occupancy`] when an oracle query fails.
pub fn cap_samples(
    oracle: &MeshOracle,
    uniform: &[[f64; 3]],
    spacing: f64,
    radius: f64,
    area_per_sample: f64,
    seed: u64,
) -> Result<CapSamples, FitError> {
    Ok(cap_points(oracle, uniform, spacing, radius)?.samples(area_per_sample, seed))
}

/// The points Newton put on the caps ([`cap_samples`]' first part), their unit normals
/// and the caps' estimated area, unit frame.
#[derive(Clone, Debug, Default)]
pub struct CapPoints {
    kept: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    area: f64,
}

impl CapPoints {
    /// The caps' estimated area (unit-cube lengths squared): the Newton points' slab
    /// estimate, less the share of the points dropped after the thinning.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The points with their tangent disks at `area_per_sample` ([`cap_samples`]).
    fn samples(self, area_per_sample: f64, seed: u64) -> CapSamples {
        let CapPoints { kept, normals, area } = self;
        let base = kept.len();
        if base == 0 || area_per_sample.is_nan() || area_per_sample <= 0.0 {
            return (kept, normals, base);
        }
        let share = area / kept.len() as f64;
        let extra = ((share / area_per_sample).round() as usize).clamp(1, CAP_MAX_PER_POINT) - 1;
        let disk = (share / std::f64::consts::PI).sqrt();
        let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 7);
        let (mut points, mut frames) = (kept.clone(), normals.clone());
        for (p, n) in kept.iter().zip(&normals) {
            let (u, v) = tangents(*n);
            for _ in 0..extra {
                let (rho, phi) = (disk * rng.uniform().sqrt(), std::f64::consts::TAU * rng.uniform());
                let (a, b) = (rho * phi.cos(), rho * phi.sin());
                points.push([0, 1, 2].map(|c| (p[c] + a * u[c] + b * v[c]).clamp(0.0, 1.0)));
                frames.push(*n);
            }
        }
        (points, frames, base)
    }
}

/// [`cap_samples`] up to the disks: the Newton points and the caps' area.
///
/// # Errors
/// [`FitError::Occupancy`] when an oracle query fails.
pub fn cap_points(oracle: &MeshOracle, uniform: &[[f64; 3]], spacing: f64, radius: f64) -> Result<CapPoints, FitError> {
    let fail = |source| FitError::Occupancy { during: "cap samples", source };
    let fast = occupancy::WindingMode::Fast;
    let w = oracle.winding_numbers(uniform, fast).map_err(fail)?;
    let band: Vec<[f64; 3]> =
        uniform.iter().zip(&w).filter(|(_, w)| (w.abs() - 0.5).abs() < CAP_BAND).map(|(p, _)| *p).collect();
    if band.is_empty() {
        return Ok(CapPoints::default());
    }
    let clearance2 = (CAP_CLEARANCE * spacing).powi(2);
    let far = |points: &[[f64; 3]]| -> Result<Vec<bool>, FitError> {
        Ok(oracle.closest_points(points).map_err(fail)?.iter().map(|c| c.squared_distance > clearance2).collect())
    };
    let band: Vec<[f64; 3]> = band.iter().zip(far(&band)?).filter(|(_, f)| *f).map(|(p, _)| *p).collect();
    let e = 0.25 * spacing;
    // |w| − 0.5 and the gradient of |w| at each point (w keeps its sign this near the
    // level set; exact within the fast mode's fallback margin of 0.5).
    let probe = |points: &[[f64; 3]]| -> Result<Vec<(f64, [f64; 3])>, FitError> {
        let mut probes = Vec::with_capacity(7 * points.len());
        for p in points {
            probes.push(*p);
            for axis in 0..3 {
                for sign in [1.0, -1.0] {
                    let mut q = *p;
                    q[axis] += sign * e;
                    probes.push(q);
                }
            }
        }
        let v = oracle.winding_numbers(&probes, fast).map_err(fail)?;
        Ok(v.chunks_exact(7)
            .map(|v| {
                let s = v[0].signum();
                (s * v[0] - 0.5, [0, 1, 2].map(|a| s * (v[1 + 2 * a] - v[2 + 2 * a]) / (2.0 * e)))
            })
            .collect())
    };
    let norm2 = |g: [f64; 3]| g[0] * g[0] + g[1] * g[1] + g[2] * g[2];
    // One Newton step of every point: the moved point and |∇w| where it started, or None
    // where the gradient vanishes or the step is longer than two probe offsets (off the
    // level set's reach).
    let step = |points: &[[f64; 3]]| -> Result<Vec<Stepped>, FitError> {
        Ok(points
            .iter()
            .zip(probe(points)?)
            .map(|(p, (r, g))| {
                let g2 = norm2(g);
                if !(g2 > 0.0 && g2.is_finite()) {
                    return None;
                }
                let t = r / g2;
                let d = [0, 1, 2].map(|a| -t * g[a]);
                (norm2(d) <= (2.0 * e).powi(2)).then(|| ([0, 1, 2].map(|a| (p[a] + d[a]).clamp(0.0, 1.0)), g2.sqrt()))
            })
            .collect())
    };
    let first: Vec<([f64; 3], f64)> = step(&band)?.into_iter().flatten().collect();
    let density = uniform.len() as f64;
    // The points a step keeps lie within CAP_BAND/|∇w| of the level set in |w| and 2e
    // in the step's length: a slab twice the smaller of the two thick.
    let mut area: f64 = first.iter().map(|(_, g)| 1.0 / (2.0 * density * (CAP_BAND / g).min(2.0 * e))).sum();
    let mut points: Vec<[f64; 3]> = first.iter().map(|(p, _)| *p).collect();
    // Thinned before the further steps, which then cost little (the band holds many times
    // more points than the caps need).
    points = greedy_disk(&points, radius).into_iter().map(|i| points[i as usize]).collect();
    let thinned = points.len();
    for _ in 1..CAP_NEWTON_STEPS {
        points = step(&points)?.into_iter().flatten().map(|(p, _)| p).collect();
    }
    if points.is_empty() {
        return Ok(CapPoints::default());
    }
    let at = probe(&points)?;
    let far = far(&points)?;
    let (mut kept, mut normals) = (Vec::new(), Vec::new());
    for ((p, (r, g)), f) in points.iter().zip(at).zip(far) {
        let gl = norm2(g).sqrt();
        if f && gl > 0.0 && gl.is_finite() && r.abs() <= CAP_PRECISION * spacing * gl {
            kept.push(*p);
            normals.push(g.map(|x| x / gl));
        }
    }
    // The points dropped after the thinning take their share of the area with them.
    if thinned > 0 {
        area *= kept.len() as f64 / thinned as f64;
    }
    Ok(CapPoints { kept, normals, area })
}

/// Points on the caps' rims: the ring, [`CAP_CLEARANCE`] pair spacings wide, where a cap
/// meets the input and [`cap_samples`] keeps none. Near an open edge the winding number
/// turns with the angle about the edge (by 1/2π a radian), so the level set |w| = 0.5
/// leaves the edge as a half-plane: in the input's own plane where the rest of the mesh
/// adds 0.5 (a smooth hole), at an angle where it does not (a hole's rim on a fold). Each
/// boundary edge's ring is cut into [`RIM_SLABS`] slabs by the distance s from the edge;
/// at the edge's midpoint and each slab's middle s, the angle φ out of the triangle's plane
/// (kept within [`RIM_MAX_TURN`] of it, so the search never crosses the input) where
/// |w| = 0.5 is found by secant steps, with one winding number a step (Newton on the
/// gradient, as the caps are found, needs six a step and probes so close to the edge that
/// the fast mode falls back to the exact sum: libigl's truck took 8 s more). A slab is
/// kept when its point lands within [`CAP_PRECISION`] spacings of the level set and its own
/// edge is the nearest part of the input (a rim that runs into other faces, as in a soup,
/// has no cap there; above [`RIM_SEARCH_BUDGET`] searches, slabs whose straight
/// continuation fails that are not searched); it gets one point per `area_per_sample` of
/// its area, uniform over the edge's length and the slab's width, on that half-plane, with
/// the half-plane's unit normal, and each point is kept when it passes the same two tests
/// where it stands (within [`RIM_PRECISION`]). Unit frame.
///
/// Why: without them the crust over the ring was left to the pairs nearby, and the polish,
/// which pulls the crust only where there are samples, left a sawtooth along every cap's
/// rim (libigl's halftunnel, face, camelhead).
#[allow(clippy::neg_cmp_op_on_partial_ord, reason = "a NaN must fail these tests, and !(x > 0.0) holds for it")]
pub(super) fn rim_samples(
    oracle: &MeshOracle,
    unit: &TriMesh,
    spacing: f64,
    area_per_sample: f64,
    seed: u64,
) -> Result<RimSamples, FitError> {
    let fail = |source| FitError::Occupancy { during: "rim samples", source };
    let width = CAP_CLEARANCE * spacing;
    let frames = rim_pieces(unit, width);
    if frames.is_empty() || !(area_per_sample > 0.0) {
        return Ok((Vec::new(), Vec::new()));
    }
    let slab = width / RIM_SLABS as f64;
    // The point at distance s from the edge's point m, turned by φ out of the triangle's plane.
    let at = |(_, _, n, d): &RimEdge, m: [f64; 3], s: f64, phi: f64| {
        let (c, sn) = (phi.cos(), phi.sin());
        [0, 1, 2].map(|k| m[k] + s * (c * d[k] + sn * n[k]))
    };
    let mid = |(a, b, ..): &RimEdge| [0, 1, 2].map(|k| 0.5 * (a[k] + b[k]));
    // One solve per (edge, slab): its middle distance.
    let solves: Vec<(usize, f64)> =
        (0..frames.len()).flat_map(|e| (0..RIM_SLABS).map(move |j| (e, slab * (j as f64 + 0.5)))).collect();
    // Beyond a budget, first the cheap test (one closest point each) on the edge's own
    // continuation: where other faces are already nearer there (a soup's neighbours, a
    // crack's far side), the search is not run. On a 7,000-triangle soup whose every edge is
    // open the search took 6 s and kept nothing; below the budget it is not used because it
    // also drops slabs whose half-plane turns clear of those faces (the benchmark's soup:
    // Hausdorff 10.03 → 10.28%).
    let solves = if solves.len() > RIM_SEARCH_BUDGET {
        let start: Vec<[f64; 3]> =
            solves.iter().map(|&(e, s)| at(&frames[e], mid(&frames[e]), s, 0.0).map(|x| x.clamp(0.0, 1.0))).collect();
        let clear = oracle.closest_points(&start).map_err(fail)?;
        solves
            .into_iter()
            .zip(clear)
            .filter(|((_, s), c)| c.squared_distance >= (RIM_OWN_EDGE * s).powi(2))
            .map(|(solve, _)| solve)
            .collect()
    } else {
        solves
    };
    if solves.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let value = |phis: &[f64]| -> Result<Vec<f64>, FitError> {
        let points: Vec<[f64; 3]> = solves
            .iter()
            .zip(phis)
            .map(|(&(e, s), &phi)| at(&frames[e], mid(&frames[e]), s, phi).map(|x| x.clamp(0.0, 1.0)))
            .collect();
        let w = oracle.winding_numbers(&points, occupancy::WindingMode::Fast).map_err(fail)?;
        Ok(w.iter().map(|w| w.abs() - 0.5).collect())
    };
    let (mut p0, mut p1) = (vec![0.0; solves.len()], vec![RIM_FIRST_TURN; solves.len()]);
    let (mut f0, mut f1) = (value(&p0)?, value(&p1)?);
    for _ in 0..RIM_SECANT_STEPS {
        let p2: Vec<f64> = (0..solves.len())
            .map(|i| {
                let df = f1[i] - f0[i];
                if df != 0.0 && df.is_finite() {
                    (p1[i] - f1[i] * (p1[i] - p0[i]) / df).clamp(-RIM_MAX_TURN, RIM_MAX_TURN)
                } else {
                    p1[i]
                }
            })
            .collect();
        let f2 = value(&p2)?;
        (p0, f0) = (std::mem::replace(&mut p1, p2), std::mem::replace(&mut f1, f2));
    }
    let points: Vec<[f64; 3]> =
        solves.iter().zip(&p1).map(|(&(e, s), &phi)| at(&frames[e], mid(&frames[e]), s, phi)).collect();
    let nearest = oracle
        .closest_points(&points.iter().map(|p| p.map(|x| x.clamp(0.0, 1.0))).collect::<Vec<_>>())
        .map_err(fail)?;
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 8);
    // Candidates: point, normal, distance from its edge piece's line.
    let mut candidates: Vec<([f64; 3], [f64; 3], f64)> = Vec::new();
    for (i, &(e, s)) in solves.iter().enumerate() {
        // Distance to the level set: |f| over |w|'s rate across the half-plane, 1/(2π s)
        // by the edge alone; the edge is the nearest input.
        let off = 2.0 * std::f64::consts::PI * s * f1[i].abs();
        if !(off <= CAP_PRECISION * spacing) || nearest[i].squared_distance < (RIM_OWN_EDGE * s).powi(2) {
            continue;
        }
        let frame = &frames[e];
        let (a, b, ..) = *frame;
        let turned = at(frame, [0.0; 3], 1.0, p1[i]);
        let along = [0, 1, 2].map(|k| b[k] - a[k]);
        let c = cross(along, turned);
        let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
        if !(l > 0.0) {
            continue;
        }
        let normal = c.map(|x| x / l);
        let expected = distance(a, b) * slab / area_per_sample;
        let count = expected.floor() as usize + usize::from(rng.uniform() < expected.fract());
        for _ in 0..count {
            let u = rng.uniform();
            let r = s + slab * (rng.uniform() - 0.5);
            let base = [0, 1, 2].map(|k| a[k] + u * along[k]);
            let q = [0, 1, 2].map(|k| base[k] + r * turned[k]);
            if q.iter().all(|x| (0.0..=1.0).contains(x)) {
                candidates.push((q, normal, r));
            }
        }
    }
    checked_rim_points(oracle, candidates, spacing)
}

/// Points on the caps' rims and their unit normals ([`rim_samples`]).
pub(super) type RimSamples = (Vec<[f64; 3]>, Vec<[f64; 3]>);

/// The boundary edges of `unit` with their frames, those longer than the ring is `width`
/// wide cut into pieces no longer: along a long edge the rest of the mesh adds different
/// amounts, and the half-plane turns (a soup's).
fn rim_pieces(unit: &TriMesh, width: f64) -> Vec<RimEdge> {
    rim_with_frames(unit, &boundary_edges(unit))
        .into_iter()
        .flat_map(|(a, b, n, d)| {
            let pieces = (distance(a, b) / width).ceil().clamp(1.0, 1e6) as usize;
            (0..pieces).map(move |i| {
                let (t0, t1) = (i as f64 / pieces as f64, (i + 1) as f64 / pieces as f64);
                ([0, 1, 2].map(|k| a[k] + t0 * (b[k] - a[k])), [0, 1, 2].map(|k| a[k] + t1 * (b[k] - a[k])), n, d)
            })
        })
        .collect()
}

/// The rim `candidates` (point, normal, distance from its edge) that pass
/// [`rim_samples`]' two tests where they stand (one winding number and one closest point
/// each: the half-plane was found at its piece's middle only), with their normals.
fn checked_rim_points(
    oracle: &MeshOracle,
    candidates: Vec<([f64; 3], [f64; 3], f64)>,
    spacing: f64,
) -> Result<RimSamples, FitError> {
    let fail = |source| FitError::Occupancy { during: "rim samples", source };
    let points: Vec<[f64; 3]> = candidates.iter().map(|c| c.0).collect();
    let w = oracle.winding_numbers(&points, occupancy::WindingMode::Fast).map_err(fail)?;
    let nearest = oracle.closest_points(&points).map_err(fail)?;
    let (mut out, mut normals) = (Vec::new(), Vec::new());
    for (((q, normal, r), w), c) in candidates.into_iter().zip(w).zip(nearest) {
        let off = 2.0 * std::f64::consts::PI * r * (w.abs() - 0.5).abs();
        if off <= RIM_PRECISION * spacing && c.squared_distance >= (RIM_OWN_EDGE * r).powi(2) {
            out.push(q);
            normals.push(normal);
        }
    }
    Ok((out, normals))
}

/// Largest distance of a rim point from the level set, estimated as 2π·r·||w| − 0.5| (r its
/// distance from the edge), in pair spacings: looser than [`CAP_PRECISION`], which the
/// piece's middle meets, since the level set curves away from the half-plane.
pub(super) const RIM_PRECISION: f64 = 0.03;

/// Searches (edge pieces × slabs) above which [`rim_samples`] first drops the slabs whose
/// straight continuation has other faces nearer than their edge (eight winding numbers a
/// search).
pub(super) const RIM_SEARCH_BUDGET: usize = 40_000;

/// Slabs of a rim's ring ([`rim_samples`]), by distance from the edge.
pub(super) const RIM_SLABS: usize = 4;

/// The second angle of the secant search, radians out of the triangle's plane.
pub(super) const RIM_FIRST_TURN: f64 = 0.2;

/// Secant steps of the rim's search after its first two angles.
pub(super) const RIM_SECANT_STEPS: usize = 6;

/// Largest turn of a rim's half-plane out of its triangle's plane, radians (short of the
/// triangle itself, at ±π).
pub(super) const RIM_MAX_TURN: f64 = 2.8;

/// A rim slab is kept when the input is no nearer to its point than this share of its
/// distance from its own edge.
pub(super) const RIM_OWN_EDGE: f64 = 0.9;

/// A Newton step's moved point and |∇w| where it started ([`cap_samples`]), if it held.
pub(super) type Stepped = Option<([f64; 3], f64)>;

/// Two unit vectors orthogonal to the unit vector `n` and to each other.
pub(super) fn tangents(n: [f64; 3]) -> ([f64; 3], [f64; 3]) {
    let a = if n[0].abs() < 0.9 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let u = normalize(cross(n, a));
    (u, cross(n, u))
}

/// Points on a cap, their unit normals and how many of them (the first) were Newton's
/// ([`cap_samples`]).
pub type CapSamples = (Vec<[f64; 3]>, Vec<[f64; 3]>, usize);

/// Half-width of the band of |w| around 0.5 from which [`cap_samples`] starts.
pub(super) const CAP_BAND: f64 = 0.15;

/// Newton steps onto the level set |w| = 0.5 ([`cap_samples`]). One step, as before, left
/// the cap samples within 0.02 of 0.5 in |w|, which on libigl's halftunnel (|∇w| about 4
/// per diagonal) is 0.5% of the diagonal: the crust over its two holes came out faceted
/// (normal consistency against ∇w 0.930).
pub(super) const CAP_NEWTON_STEPS: usize = 4;

/// Largest distance of a cap sample from the level set, ||w| − 0.5| / |∇w|, in pair
/// spacings.
pub(super) const CAP_PRECISION: f64 = 0.01;

/// Least distance of a cap sample from the input, in pair spacings √(2A/K): nearer, the
/// input's own pairs shape the crust.
pub(super) const CAP_CLEARANCE: f64 = 0.4;

/// Most samples a kept cap point stands for (itself and those in its tangent disk).
pub(super) const CAP_MAX_PER_POINT: usize = 256;

/// Spacing of the cap points kept for the further Newton steps, in pair spacings.
pub(super) const CAP_THINNING: f64 = 0.5;

/// The pairs' spacing √(2A/K) the caps are found at, for the input's area `area` (unit
/// frame) and K sites.
pub(super) fn cap_spacing(area: f64, k: usize) -> f64 {
    (2.0 * area / k as f64).sqrt()
}

/// [`cap_points`] of the uniform part of `data`'s pool (its first `num_uniform` points) at
/// the pairs' spacing for the input's area `area` and K sites.
///
/// # Errors
/// [`FitError::Occupancy`] when an oracle query fails.
pub(super) fn pool_cap_points(
    oracle: &MeshOracle,
    data: &TrainingData,
    num_uniform: usize,
    area: f64,
    k: usize,
) -> Result<CapPoints, FitError> {
    if k < 2 {
        return Ok(CapPoints::default());
    }
    let spacing = cap_spacing(area, k);
    cap_points(oracle, &data.points[..num_uniform.min(data.points.len())], spacing, CAP_THINNING * spacing)
}

/// The caps' samples ([`CapPoints`] of the uniform part of `data`'s pool, found by
/// [`pool_cap_points`]) added to `data`'s surface samples,
/// as dense as the surface samples (one per A/n of area, A the input's area). The points
/// Newton put on the caps (half a pair spacing apart) go to seeded places among the first
/// 12·K surface samples (the initialisation's candidates), with the samples they displace
/// moved to the end, so the initialisation puts pairs there; the points of their tangent
/// disks are appended, for the polish, and so are the points of the rims' rings
/// ([`rim_samples`] of `unit`, the input in the unit frame). Returns how many were added.
///
/// Why as dense: the polish draws its batches from the surface samples, and caps with a
/// few thousand of the million (0.2% of the batches for a third of the area, libigl's
/// halftunnel) were pulled so rarely that Adam's normalised steps scattered their sites:
/// the caps came out faceted (normal consistency against ∇w 0.930). Why not more of the
/// candidates: with the caps in proportion to their area among them (a seeded shuffle),
/// the benchmark's teapots moved away from the VoroMesh-style fit's Hausdorff distance
/// (4.16 → 4.17%, 4.186 → 4.194%; their caps are smooth and need fewer pairs).
pub(super) fn add_cap_samples(
    oracle: &MeshOracle,
    unit: &TriMesh,
    data: &mut TrainingData,
    caps: CapPoints,
    area: f64,
    k: usize,
    seed: u64,
) -> Result<usize, FitError> {
    let n = data.surface.len();
    if n == 0 || data.normals.len() != n || k < 2 {
        return Ok(0);
    }
    let spacing = cap_spacing(area, k);
    let (points, normals, base) = caps.samples(area / n as f64, seed);
    let m = n.min(12 * k);
    let mut rng = ChunkRng::for_chunk(seed, Stream::SitesInit, 6);
    for (i, (&point, &normal)) in points.iter().zip(&normals).enumerate() {
        if i < base {
            let j = (rng.next_u64() % m as u64) as usize;
            let (p, nrm) = (data.surface[j], data.normals[j]);
            data.surface.push(p);
            data.normals.push(nrm);
            data.surface[j] = point;
            data.normals[j] = normal;
        } else {
            data.surface.push(point);
            data.normals.push(normal);
        }
    }
    // The rims' points are appended, for the polish only: the caps' Newton points already
    // give the initialisation its pairs beside them.
    let (rim, rim_normals) = rim_samples(oracle, unit, spacing, area / n as f64, seed)?;
    data.surface.extend_from_slice(&rim);
    data.normals.extend_from_slice(&rim_normals);
    Ok(points.len() + rim.len())
}
