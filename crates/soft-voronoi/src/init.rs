//! Where the sites start ([`crate::Init`]) and the fixed outside sites on the faces of the
//! unit cube that bound every Voronoi cell.

use vf_common::rng::{ChunkRng, Stream};

use crate::error::TrainError;
use crate::kernel::SiteIndex;
use crate::losses::Solid;
use crate::data::TrainingData;

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
