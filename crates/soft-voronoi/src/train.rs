//! The training loop: initialisation, one Adam step at a time, resumable state.

use occupancy::sample::rng::ChunkRng;

use crate::adam;
use crate::config::{Init, TrainConfig};
use crate::error::TrainError;
use crate::kernel::{self, Kernel, Scratch, SiteIndex};
use crate::losses::{self, Located, SiteGraph, Solid};

/// RNG streams (distinct from the occupancy samplers' 1..=3).
const STREAM_INIT: u64 = 101;
const STREAM_BATCH: u64 = 102;

/// Distance of the boundary sites from the faces of the unit cube (they must lie
/// strictly inside it for the crust).
pub const BOUNDARY_INSET: f64 = 1e-3;

/// Training samples in the unit-cube frame with their ground-truth occupancy.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TrainingData {
    /// #N×3 points.
    pub points: Vec<[f64; 3]>,
    /// #N occupancy (true = inside).
    pub occupancy: Vec<bool>,
    /// Points on the surface (area-uniform) for [`Init::Surface`]; may be empty otherwise.
    pub surface: Vec<[f64; 3]>,
    /// Unit normals at `surface` (any orientation: labels come from the solid).
    pub normals: Vec<[f64; 3]>,
}

impl TrainingData {
    /// A fingerprint of the data (FNV-1a over the bits), stored in checkpoints so a resume
    /// on different data is refused.
    pub fn fingerprint(&self) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        let mut eat = |x: u64| {
            for b in x.to_le_bytes() {
                h ^= b as u64;
                h = h.wrapping_mul(0x0100_0000_01b3);
            }
        };
        eat(self.points.len() as u64);
        for (p, &o) in self.points.iter().zip(&self.occupancy) {
            eat(p[0].to_bits());
            eat(p[1].to_bits());
            eat(p[2].to_bits());
            eat(o as u64);
        }
        h
    }

    fn validate(&self) -> Result<(), TrainError> {
        if self.points.is_empty() || self.points.len() != self.occupancy.len() {
            return Err(TrainError::Data(format!(
                "{} points with {} occupancy values; need at least one of each, the same number",
                self.points.len(),
                self.occupancy.len()
            )));
        }
        if let Some(i) = self.points.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(TrainError::Data(format!("point {i} is not finite: {:?}", self.points[i])));
        }
        Ok(())
    }
}

/// Losses and settings of one step.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StepStats {
    /// 0-based step index.
    pub step: usize,
    /// Learning rate used.
    pub lr: f64,
    /// β used.
    pub beta: f64,
    /// Weighted sum of the terms.
    pub total: f64,
    /// E|O − V| on the batch.
    pub reconstruction: f64,
    /// Bounds loss.
    pub bounds: f64,
    /// Signed-distance loss (mean over sites).
    pub signed_distance: f64,
    /// Centroidal loss (mean over sites).
    pub centroidal: f64,
    /// Largest coordinate move of the step.
    pub max_move: f64,
}

impl StepStats {
    /// Number of f64 fields in [`StepStats::to_row`].
    pub const COLUMNS: usize = 9;
    /// Column names of [`StepStats::to_row`].
    pub const NAMES: [&'static str; 9] =
        ["step", "lr", "beta", "total", "reconstruction", "bounds", "signed_distance", "centroidal", "max_move"];

    /// The stats as one row of f64.
    pub fn to_row(&self) -> [f64; 9] {
        [
            self.step as f64,
            self.lr,
            self.beta,
            self.total,
            self.reconstruction,
            self.bounds,
            self.signed_distance,
            self.centroidal,
            self.max_move,
        ]
    }

    /// The inverse of [`StepStats::to_row`].
    pub fn from_row(r: &[f64]) -> Self {
        StepStats {
            step: r[0] as usize,
            lr: r[1],
            beta: r[2],
            total: r[3],
            reconstruction: r[4],
            bounds: r[5],
            signed_distance: r[6],
            centroidal: r[7],
            max_move: r[8],
        }
    }
}

/// Everything that changes during training: enough to continue bit-identically.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainState {
    /// Settings (fixed for the run).
    pub config: TrainConfig,
    /// Steps done.
    pub step: usize,
    /// K trainable sites followed by the fixed boundary sites.
    pub sites: Vec<[f64; 3]>,
    /// Labels of `sites` (boundary sites are outside).
    pub labels: Vec<bool>,
    /// Adam first moments (K×3).
    pub m: Vec<[f64; 3]>,
    /// Adam second moments (K×3).
    pub v: Vec<[f64; 3]>,
    /// Delaunay graph of the sites at the last refresh.
    pub graph: SiteGraph,
    /// Closest surface points of the trainable sites at the last refresh.
    pub located: Vec<Located>,
    /// Per-step statistics so far.
    pub history: Vec<StepStats>,
    /// [`TrainingData::fingerprint`] of the data.
    pub data_fingerprint: u64,
}

/// A training run over borrowed data and solid.
pub struct Trainer<'a> {
    state: TrainState,
    data: &'a TrainingData,
    solid: &'a dyn Solid,
    grad: Vec<[f64; 3]>,
    batch_points: Vec<[f64; 3]>,
    batch_occupancy: Vec<bool>,
}

impl<'a> Trainer<'a> {
    /// Initialises the sites (`config.init`) and the optimiser.
    ///
    /// # Errors
    /// Invalid settings or data; a Delaunay failure on the initial sites.
    pub fn new(config: TrainConfig, data: &'a TrainingData, solid: &'a dyn Solid) -> Result<Self, TrainError> {
        config.validate()?;
        data.validate()?;
        let k = config.num_sites;
        let (mut sites, mut labels) = match config.init {
            Init::Paper => paper_init(k, config.seed),
            Init::Samples => samples_init(k, data, config.seed)?,
            Init::Surface => surface_init(k, data, solid, config.surface_offset, config.seed)?,
        };
        let boundary = boundary_sites(config.boundary_sites.unwrap_or_else(|| (k as f64).sqrt().ceil() as usize));
        debug_assert_eq!(boundary.len(), config.num_boundary());
        labels.extend(std::iter::repeat_n(false, boundary.len()));
        sites.extend(boundary);
        let state = TrainState {
            step: 0,
            m: vec![[0.0; 3]; k],
            v: vec![[0.0; 3]; k],
            graph: SiteGraph::default(),
            located: Vec::new(),
            history: Vec::new(),
            data_fingerprint: data.fingerprint(),
            sites,
            labels,
            config,
        };
        Ok(Self::from_parts(state, data, solid))
    }

    /// Continues from a saved state, on the same data.
    ///
    /// # Errors
    /// [`TrainError::Checkpoint`] (with `path` for the message) when the data's fingerprint
    /// differs from the one the state was trained on, or the state is inconsistent.
    pub fn resume(
        state: TrainState,
        data: &'a TrainingData,
        solid: &'a dyn Solid,
        path: &str,
    ) -> Result<Self, TrainError> {
        state.config.validate()?;
        data.validate()?;
        let k = state.config.num_sites;
        let fail = |message: String| Err(TrainError::Checkpoint { path: path.to_string(), message });
        if state.data_fingerprint != data.fingerprint() {
            return fail(
                "it was trained on different samples (another mesh, seed or sample count); resume with the same \
                 mesh and settings, or start afresh without --resume"
                    .into(),
            );
        }
        if state.sites.len() != k + state.config.num_boundary()
            || state.labels.len() != state.sites.len()
            || state.m.len() != k
            || state.v.len() != k
            || state.step > state.config.steps
            || (state.step > 0 && state.config.weights.signed_distance > 0.0 && state.located.len() != k)
            || (state.step > 0 && state.config.weights.centroidal > 0.0 && state.graph.num_sites() != state.sites.len())
        {
            return fail("its arrays are inconsistent with its settings".into());
        }
        Ok(Self::from_parts(state, data, solid))
    }

    fn from_parts(state: TrainState, data: &'a TrainingData, solid: &'a dyn Solid) -> Self {
        let k = state.config.num_sites;
        let b = state.config.batch;
        Trainer {
            state,
            data,
            solid,
            grad: vec![[0.0; 3]; k],
            batch_points: Vec::with_capacity(b),
            batch_occupancy: Vec::with_capacity(b),
        }
    }

    /// The state (for checkpoints and results).
    pub fn state(&self) -> &TrainState {
        &self.state
    }

    /// Settings.
    pub fn config(&self) -> &TrainConfig {
        &self.state.config
    }

    /// Whether every step has been done.
    pub fn is_done(&self) -> bool {
        self.state.step >= self.state.config.steps
    }

    /// One step: refresh graph and closest points if due, draw the batch, losses and
    /// gradients, Adam.
    ///
    /// # Errors
    /// [`TrainError::Diverged`] on a non-finite loss or site; Delaunay failures.
    pub fn step(&mut self) -> Result<StepStats, TrainError> {
        let st = &mut self.state;
        let cfg = &st.config;
        let t = st.step;
        let k = cfg.num_sites;
        let w = cfg.weights.clone();
        let (lr, beta) = (cfg.lr_at(t), cfg.beta_at(t));
        let kernel = Kernel { beta, tau: cfg.tau };
        if t % cfg.refresh_every == 0 || (w.centroidal > 0.0 && st.graph.num_sites() != st.sites.len()) {
            if w.centroidal > 0.0 {
                st.graph = SiteGraph::delaunay(&st.sites)?;
            }
            if w.signed_distance > 0.0 {
                st.located = self.solid.locate(&st.sites[..k]);
            }
        }
        // The batch: indices drawn from the step's own random stream, so a resumed run
        // draws the same batches.
        let mut rng = ChunkRng::for_chunk(cfg.seed, STREAM_BATCH, t as u64);
        let n = self.data.points.len() as u64;
        self.batch_points.clear();
        self.batch_occupancy.clear();
        for _ in 0..cfg.batch {
            let i = (rng.next_u64() % n) as usize;
            self.batch_points.push(self.data.points[i]);
            self.batch_occupancy.push(self.data.occupancy[i]);
        }
        self.grad.iter_mut().for_each(|g| *g = [0.0; 3]);
        let index = SiteIndex::new(&st.sites);
        let rec = losses::reconstruction(
            &kernel,
            &index,
            &st.sites,
            &st.labels,
            &self.batch_points,
            &self.batch_occupancy,
            w.reconstruction,
            &mut self.grad,
        );
        let bnd = losses::bounds(&st.sites[..k], w.bounds, &mut self.grad);
        let sdf = if w.signed_distance > 0.0 {
            losses::signed_distance_cached(
                &st.located,
                &st.sites[..k],
                &st.labels[..k],
                w.signed_distance,
                &mut self.grad,
            )
        } else {
            0.0
        };
        let cen = if w.centroidal > 0.0 {
            losses::centroidal(&st.graph, &st.sites, w.centroidal, &mut self.grad)
        } else {
            0.0
        };
        let total = w.reconstruction * rec + w.bounds * bnd + w.signed_distance * sdf + w.centroidal * cen;
        if !total.is_finite() || !self.grad.iter().flatten().all(|g| g.is_finite()) {
            return Err(TrainError::Diverged { step: t, what: format!("loss {total}") });
        }
        let max_move = adam::step(&cfg.adam, t as u64 + 1, lr, &mut st.sites[..k], &self.grad, &mut st.m, &mut st.v);
        let stats = StepStats {
            step: t,
            lr,
            beta,
            total,
            reconstruction: rec,
            bounds: bnd,
            signed_distance: sdf,
            centroidal: cen,
            max_move,
        };
        st.history.push(stats);
        st.step += 1;
        Ok(stats)
    }

    /// The sites for the crust: all sites (trainable then boundary), projected into
    /// [ε, 1 − ε]³ with ε = 1e-9 (the crust needs them strictly inside the unit cube),
    /// their labels, and how many sites the projection moved.
    pub fn final_sites(&self) -> (Vec<[f64; 3]>, Vec<bool>, usize) {
        project_sites(&self.state.sites, &self.state.labels)
    }
}

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
    let mut rng = ChunkRng::for_chunk(seed, STREAM_INIT, 0);
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
    let mut rng = ChunkRng::for_chunk(seed, STREAM_INIT, 1);
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
    let mut rng = ChunkRng::for_chunk(seed, STREAM_INIT, 2);
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

/// Hard Voronoi occupancy (nearest site's label) of each point, in parallel.
pub fn classify(sites: &[[f64; 3]], labels: &[bool], points: &[[f64; 3]]) -> Vec<bool> {
    use rayon::prelude::*;
    let index = SiteIndex::new(sites);
    points.par_iter().map(|&x| kernel::hard_label(&index, sites, labels, x)).collect()
}

/// Soft occupancy V of each point at temperature `kernel`, in parallel.
pub fn soft_values(kernel: &Kernel, sites: &[[f64; 3]], labels: &[bool], points: &[[f64; 3]]) -> Vec<f64> {
    use rayon::prelude::*;
    let index = SiteIndex::new(sites);
    points
        .par_chunks(losses::CHUNK)
        .flat_map_iter(|xs| {
            let mut s = Scratch::default();
            xs.iter().map(|&x| kernel::value(kernel, &index, sites, labels, x, &mut s)).collect::<Vec<_>>()
        })
        .collect()
}
