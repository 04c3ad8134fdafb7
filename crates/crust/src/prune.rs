//! Sites that change nothing: removing them leaves the occupancy (the label of the nearest
//! site) the same everywhere but on a set of measure zero, and so leaves the crust the same.
//!
//! A site s whose Delaunay neighbours all carry its own label is such a site. Removing it
//! hands each point x of its cell to x's second-nearest site, which is a Delaunay neighbour
//! of s: the part of s's cell that a neighbour t takes over is a full-dimensional convex
//! piece on s's side of their bisector, so s and t share a Voronoi face of positive area and
//! the edge st is in every Delaunay triangulation of the sites, whatever the perturbation
//! picks among cospherical ones. Every point of the cell therefore keeps its label.
//! Several such sites can go at once when no two of them are neighbours (the second-nearest
//! site of a point of one removed cell is then never removed), so the removal runs in
//! rounds of an independent set, each on a fresh tetrahedralization.
//!
//! The crust is read from the sites snapped to the power-of-two grid of
//! [`crate::Crust::extract`], and the nearest-site occupancy from the sites as they are;
//! the two tetrahedralizations can differ where sites are nearly cospherical, so a site is
//! removed only when it is redundant, and independent of the others removed, in both.
//! Every test is combinatorial on exact tetrahedralizations: nothing here rounds.
//!
//! "The same crust" is the same surface, not always the same vertex list: where sites are
//! exactly degenerate (mirrored pairs can be), four cells meet along a segment rather than
//! at a point, and which end of it becomes a crust vertex is the tetrahedralization's
//! perturbation's choice, which depends on the other sites (`tests/prune.rs` compares
//! the surfaces, their volume and area, and the occupancy).
//!
//! Nothing in the crate's other code needs this; the main job uses it to hand back sites
//! that cost file size and no accuracy (the boundary sites on the cube's faces, sites deep
//! inside or far outside the shape).

use delaunay3::{Delaunay3, DelaunayError};

use crate::error::CrustError;
use crate::extract::{check_inputs, snap_to_grid};
use crate::CrustConfig;

/// What [`prune`] did.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct PruneReport {
    /// Sites removed in each round.
    pub removed_per_round: Vec<usize>,
}

impl PruneReport {
    /// Sites removed in all.
    pub fn removed(&self) -> usize {
        self.removed_per_round.iter().sum()
    }
}

/// For each site, whether it can be removed now: its Delaunay neighbours all carry its
/// label, and no earlier site (by index) chosen in the same call is its neighbour, in the
/// tetrahedralizations of both `sites` and `sites` snapped as [`crate::Crust::extract`]
/// snaps them. Sites listed in `keep` (sorted or not) and coincident sites (in either
/// tetrahedralization) are never chosen. All `false` when the sites cannot be
/// tetrahedralized (fewer than four independent ones).
///
/// # Errors
/// The inputs [`crate::Crust::extract`] refuses (mismatched lengths, NaN, sites outside the
/// box) and a failed tetrahedralization.
pub fn removable(
    sites: &[[f64; 3]],
    inside: &[bool],
    keep: &[usize],
    config: &CrustConfig,
) -> Result<Vec<bool>, CrustError> {
    check_inputs(sites, inside, config)?;
    let (snapped, _) = snap_to_grid(sites, config)?;
    let mut blocked = vec![false; sites.len()];
    for &i in keep {
        if let Some(b) = blocked.get_mut(i) {
            *b = true;
        }
    }
    let mut graphs = Vec::with_capacity(2);
    for points in [sites, snapped.as_slice()] {
        match Delaunay3::new(points) {
            Ok(dt) => graphs.push(Neighbours::build(&dt)),
            Err(DelaunayError::Degenerate { .. }) => return Ok(vec![false; sites.len()]),
            Err(e) => return Err(e.into()),
        }
    }
    for g in &graphs {
        for (i, b) in blocked.iter_mut().enumerate() {
            *b |= g.coincident[i] || g.of(i).iter().any(|&j| inside[j as usize] != inside[i]);
        }
    }
    let mut chosen = vec![false; sites.len()];
    for i in 0..sites.len() {
        if !blocked[i] && graphs.iter().all(|g| g.of(i).iter().all(|&j| !chosen[j as usize])) {
            chosen[i] = true;
        }
    }
    Ok(chosen)
}

/// Removes sites that change neither the crust nor the nearest-site occupancy (see the
/// module's documentation), in up to `max_rounds` rounds of [`removable`], keeping the order
/// of the others; sites whose index (in the input) is below `keep_below` are never removed.
///
/// # Errors
/// As [`removable`].
pub fn prune(
    sites: &mut Vec<[f64; 3]>,
    inside: &mut Vec<bool>,
    keep_below: usize,
    max_rounds: usize,
    config: &CrustConfig,
) -> Result<PruneReport, CrustError> {
    let mut report = PruneReport::default();
    // Original index of every site still present, to honour `keep_below` across rounds.
    let mut original: Vec<usize> = (0..sites.len()).collect();
    for _ in 0..max_rounds {
        let keep: Vec<usize> = (0..original.len()).filter(|&i| original[i] < keep_below).collect();
        let gone = removable(sites, inside, &keep, config)?;
        let n = gone.iter().filter(|&&g| g).count();
        if n == 0 {
            break;
        }
        let mut k = 0;
        for i in 0..gone.len() {
            if !gone[i] {
                sites[k] = sites[i];
                inside[k] = inside[i];
                original[k] = original[i];
                k += 1;
            }
        }
        sites.truncate(k);
        inside.truncate(k);
        original.truncate(k);
        report.removed_per_round.push(n);
    }
    Ok(report)
}

/// The Delaunay neighbours of every input site (input indices, coincident sites mapped to
/// their first), in compressed rows.
struct Neighbours {
    offsets: Vec<usize>,
    list: Vec<u32>,
    /// Whether another input site has the same position.
    coincident: Vec<bool>,
}

impl Neighbours {
    fn build(dt: &Delaunay3) -> Neighbours {
        let n = dt.num_inputs();
        let to_input = dt.input_of_vertex_map();
        let mut per_vertex: Vec<Vec<u32>> = vec![Vec::new(); dt.num_vertices()];
        // `edges` lists the finite edges only.
        for e in dt.edges() {
            let [a, b] = e.vertices;
            per_vertex[a as usize].push(to_input[b as usize]);
            per_vertex[b as usize].push(to_input[a as usize]);
        }
        let mut count = vec![0usize; dt.num_vertices()];
        for i in 0..n {
            count[dt.vertex_of_input(i) as usize] += 1;
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut list = Vec::new();
        let mut coincident = Vec::with_capacity(n);
        offsets.push(0);
        for i in 0..n {
            let v = dt.vertex_of_input(i) as usize;
            list.extend_from_slice(&per_vertex[v]);
            offsets.push(list.len());
            coincident.push(count[v] > 1);
        }
        Neighbours { offsets, list, coincident }
    }

    fn of(&self, i: usize) -> &[u32] {
        &self.list[self.offsets[i]..self.offsets[i + 1]]
    }
}
