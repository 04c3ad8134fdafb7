//! The training loop: initialisation, one Adam step at a time, resumable state.

use vf_common::rng::{ChunkRng, Stream};

use crate::config::{Init, TrainConfig};
pub use crate::data::TrainingData;
use crate::error::TrainError;
use crate::init::{pairs_init, paper_init, project_sites, samples_init, surface_init};
use crate::kernel::{self, Kernel, Scratch, SiteIndex};
use crate::losses::{self, Located, SiteGraph, Solid};

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
    /// Surface term (mean squared distance of surface samples to their bisectors).
    #[serde(default)]
    pub surface: f64,
}

impl StepStats {
    /// Number of f64 fields in [`StepStats::to_row`].
    pub const COLUMNS: usize = 10;
    /// Column names of [`StepStats::to_row`].
    pub const NAMES: [&'static str; 10] = [
        "step",
        "lr",
        "beta",
        "total",
        "reconstruction",
        "bounds",
        "signed_distance",
        "centroidal",
        "max_move",
        "surface",
    ];

    /// The stats as one row of f64.
    pub fn to_row(&self) -> [f64; 10] {
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
            self.surface,
        ]
    }

    /// The inverse of [`StepStats::to_row`] (a 9-column row, written before the surface
    /// term existed, reads with surface 0).
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
            surface: r.get(9).copied().unwrap_or(0.0),
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
    /// The best iterate so far by the fixed evaluation batch (`config.select_every` > 0).
    pub best: Option<BestIterate>,
}

/// The iterate with the lowest total loss on the fixed evaluation batch
/// ([`TrainConfig::select_every`]).
#[derive(Clone, Debug, PartialEq)]
pub struct BestIterate {
    /// Steps done when it was measured (0 = the initialisation).
    pub step: usize,
    /// Its total loss on the evaluation batch.
    pub loss: f64,
    /// Its K trainable sites (the boundary sites never move).
    pub sites: Vec<[f64; 3]>,
}

/// The fixed evaluation batch of [`TrainConfig::select_every`]: drawn once from the data
/// with its own streams, so a resumed run rebuilds the same one.
struct SelectionBatch {
    points: Vec<[f64; 3]>,
    occupancy: Vec<bool>,
    surface: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    hints: Hints,
}

impl SelectionBatch {
    fn draw(config: &TrainConfig, data: &TrainingData) -> Option<Self> {
        if config.select_every == 0 {
            return None;
        }
        let n = config.selection_batch;
        let mut rng = ChunkRng::for_chunk(config.seed, Stream::SelectionBatch, 0);
        let (mut points, mut occupancy) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for _ in 0..n {
            let i = (rng.next_u64() % data.points.len() as u64) as usize;
            points.push(data.points[i]);
            occupancy.push(data.occupancy[i]);
        }
        let (mut surface, mut normals) = (Vec::new(), Vec::new());
        if !data.surface.is_empty() {
            let mut rng = ChunkRng::for_chunk(config.seed, Stream::SelectionSurface, 0);
            for _ in 0..n {
                let i = (rng.next_u64() % data.surface.len() as u64) as usize;
                surface.push(data.surface[i]);
                normals.push(data.normals.get(i).copied().unwrap_or([0.0; 3]));
            }
        }
        let hints = Hints::new(points.len(), surface.len());
        Some(SelectionBatch { points, occupancy, surface, normals, hints })
    }
}

/// Warm starts of the nearest-site queries, one per training sample and per surface
/// sample: the site(s) that were nearest the last time the sample was drawn
/// ([`SiteIndex::candidates_hinted`], [`losses::LabelledIndex::nearest_pair_hinted`]).
/// They only make the queries faster (a sample's nearest site rarely changes between
/// draws) and never change a result, so they are not part of the saved state: a resumed
/// run starts without them and continues bit-identically.
struct Hints {
    points: Vec<u32>,
    surface: Vec<[u32; 2]>,
}

impl Hints {
    fn new(points: usize, surface: usize) -> Self {
        Hints { points: vec![kernel::NO_HINT; points], surface: vec![[kernel::NO_HINT; 2]; surface] }
    }
}

/// A training run over borrowed data and solid.
pub struct Trainer<'a> {
    state: TrainState,
    data: &'a TrainingData,
    solid: &'a dyn Solid,
    grad: Vec<[f64; 3]>,
    batch_points: Vec<[f64; 3]>,
    batch_occupancy: Vec<bool>,
    surface_points: Vec<[f64; 3]>,
    surface_normals: Vec<[f64; 3]>,
    selection: Option<SelectionBatch>,
    /// Hints of the whole sample pool (`data.points`, `data.surface`).
    pool_hints: Hints,
    /// Indices into the pool of this step's batch and surface batch.
    batch_ids: Vec<u32>,
    surface_ids: Vec<u32>,
    /// This step's hints, gathered from the pool and scattered back after the step.
    batch_hints: Hints,
    /// Cell width of the grids in front of the trees ([`SiteIndex::with_cell`],
    /// [`losses::LabelledIndex::with_cell`]); set by [`Trainer::refresh_cell`]. Only the
    /// speed depends on it.
    cell: f64,
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
        let (sites, labels) = match config.init {
            Init::Paper => paper_init(k, config.seed),
            Init::Samples => samples_init(k, data, config.seed)?,
            Init::Surface => surface_init(k, data, solid, config.surface_offset, config.seed)?,
            Init::Pairs => {
                let (sites, labels, _) =
                    pairs_init(k, data, solid, config.surface_offset, config.density, config.seed)?;
                (sites, labels)
            }
        };
        Self::from_sites(config, data, solid, sites, labels)
    }

    /// Starts from sites placed by the caller (an initialisation that needs more than
    /// `data` and the solid, such as the fit's triplets across a thin shell) instead of
    /// `config.init`: `sites` and `labels` are the K trainable sites; the boundary sites
    /// and the optimiser are set up as in [`Trainer::new`].
    ///
    /// # Errors
    /// Invalid settings or data; not exactly K finite sites in the unit cube with labels.
    pub fn from_sites(
        config: TrainConfig,
        data: &'a TrainingData,
        solid: &'a dyn Solid,
        mut sites: Vec<[f64; 3]>,
        mut labels: Vec<bool>,
    ) -> Result<Self, TrainError> {
        config.validate()?;
        data.validate()?;
        let k = config.num_sites;
        if sites.len() != k || labels.len() != k {
            return Err(TrainError::Data(format!(
                "{} initial sites with {} labels; the settings ask for {k}",
                sites.len(),
                labels.len()
            )));
        }
        if let Some(i) = sites.iter().position(|p| !p.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x))) {
            return Err(TrainError::Data(format!("initial site {i} is not in the unit cube: {:?}", sites[i])));
        }
        let boundary = config.boundary_positions();
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
            best: None,
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
            || state.best.as_ref().is_some_and(|b| b.sites.len() != k || b.step > state.step)
        {
            return fail("its arrays are inconsistent with its settings".into());
        }
        Ok(Self::from_parts(state, data, solid))
    }

    fn from_parts(state: TrainState, data: &'a TrainingData, solid: &'a dyn Solid) -> Self {
        let k = state.config.num_sites;
        let b = state.config.batch;
        Trainer {
            data,
            solid,
            grad: vec![[0.0; 3]; k],
            batch_points: Vec::with_capacity(b),
            batch_occupancy: Vec::with_capacity(b),
            surface_points: Vec::new(),
            surface_normals: Vec::new(),
            selection: SelectionBatch::draw(&state.config, data),
            pool_hints: Hints::new(data.points.len(), data.surface.len()),
            batch_ids: Vec::with_capacity(b),
            surface_ids: Vec::new(),
            batch_hints: Hints::new(0, 0),
            cell: f64::NAN,
            state,
        }
    }

    /// Sets the grids' cell width from the current sites ([`grid_cell`]).
    fn refresh_cell(&mut self) {
        self.cell = grid_cell(&self.state.sites, self.data);
    }

    /// The total loss of the current sites on the fixed evaluation batch, at the final β
    /// (so iterates are compared on one scale whatever the annealing), without touching
    /// the optimiser. Centroidal and signed-distance terms use the state's last refresh.
    fn selection_loss(&self, batch: &mut SelectionBatch) -> f64 {
        let cfg = &self.state.config;
        let kernel = Kernel { beta: cfg.beta, tau: cfg.tau };
        let mut grad = vec![[0.0; 3]; cfg.num_sites];
        let sel = Batch {
            points: &batch.points,
            occupancy: &batch.occupancy,
            surface: &batch.surface,
            normals: &batch.normals,
        };
        objective(&self.state, &kernel, &sel, &mut batch.hints, self.cell, &mut grad).total
    }

    /// Measures the current sites on the evaluation batch and keeps them if they are the
    /// best so far (ties keep the earlier iterate).
    fn consider_current(&mut self) {
        let Some(mut batch) = self.selection.take() else { return };
        if !self.cell.is_finite() {
            self.refresh_cell();
        }
        let loss = self.selection_loss(&mut batch);
        self.selection = Some(batch);
        let st = &mut self.state;
        if loss.is_finite() && st.best.as_ref().is_none_or(|b| loss < b.loss) {
            let k = st.config.num_sites;
            st.best = Some(BestIterate { step: st.step, loss, sites: st.sites[..k].to_vec() });
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
        let every = self.state.config.select_every;
        if every > 0 && self.state.step.is_multiple_of(every) {
            self.consider_current();
        }
        let stats = self.update()?;
        if self.is_done() {
            self.consider_current();
        }
        Ok(stats)
    }

    fn update(&mut self) -> Result<StepStats, TrainError> {
        if self.state.step.is_multiple_of(self.state.config.refresh_every) || !self.cell.is_finite() {
            self.refresh_cell();
        }
        let st = &mut self.state;
        let cfg = &st.config;
        let t = st.step;
        let k = cfg.num_sites;
        let w = cfg.weights.clone();
        let (lr, beta) = (cfg.lr_at(t), cfg.beta_at(t));
        let kernel = Kernel { beta, tau: cfg.tau };
        if t.is_multiple_of(cfg.refresh_every) || (w.centroidal > 0.0 && st.graph.num_sites() != st.sites.len()) {
            if w.centroidal > 0.0 {
                st.graph = SiteGraph::delaunay(&st.sites)?;
            }
            if w.signed_distance > 0.0 {
                st.located = self.solid.locate(&st.sites[..k]);
            }
        }
        // The batch: indices drawn from the step's own random stream, so a resumed run
        // draws the same batches.
        let mut rng = ChunkRng::for_chunk(cfg.seed, Stream::TrainBatch, t as u64);
        let n = self.data.points.len() as u64;
        self.batch_points.clear();
        self.batch_occupancy.clear();
        self.batch_ids.clear();
        self.batch_hints.points.clear();
        for _ in 0..cfg.batch {
            let i = (rng.next_u64() % n) as usize;
            self.batch_points.push(self.data.points[i]);
            self.batch_occupancy.push(self.data.occupancy[i]);
            self.batch_ids.push(i as u32);
            self.batch_hints.points.push(self.pool_hints.points[i]);
        }
        self.surface_points.clear();
        self.surface_normals.clear();
        self.surface_ids.clear();
        self.batch_hints.surface.clear();
        if w.surface > 0.0 && !self.data.surface.is_empty() {
            let mut rng = ChunkRng::for_chunk(cfg.seed, Stream::SurfaceBatch, t as u64);
            let m = self.data.surface.len() as u64;
            for _ in 0..cfg.surface_batch {
                let i = (rng.next_u64() % m) as usize;
                self.surface_points.push(self.data.surface[i]);
                self.surface_normals.push(self.data.normals.get(i).copied().unwrap_or([0.0; 3]));
                self.surface_ids.push(i as u32);
                self.batch_hints.surface.push(self.pool_hints.surface[i]);
            }
        }
        self.grad.iter_mut().for_each(|g| *g = [0.0; 3]);
        let batch = Batch {
            points: &self.batch_points,
            occupancy: &self.batch_occupancy,
            surface: &self.surface_points,
            normals: &self.surface_normals,
        };
        let Terms { total, reconstruction: rec, bounds: bnd, signed_distance: sdf, centroidal: cen, surface: srf } =
            objective(st, &kernel, &batch, &mut self.batch_hints, self.cell, &mut self.grad);
        for (&i, &h) in self.batch_ids.iter().zip(&self.batch_hints.points) {
            self.pool_hints.points[i as usize] = h;
        }
        for (&i, &h) in self.surface_ids.iter().zip(&self.batch_hints.surface) {
            self.pool_hints.surface[i as usize] = h;
        }
        if !total.is_finite() || !self.grad.iter().flatten().all(|g| g.is_finite()) {
            return Err(TrainError::Diverged { step: t, what: format!("loss {total}") });
        }
        let max_move = cfg.adam.at::<f64>(t as u64 + 1, lr).apply(
            st.sites[..k].as_flattened_mut(),
            self.grad.as_flattened(),
            st.m.as_flattened_mut(),
            st.v.as_flattened_mut(),
        );
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
            surface: srf,
        };
        st.history.push(stats);
        st.step += 1;
        Ok(stats)
    }

    /// The sites for the crust: all sites (trainable then boundary) — the best iterate's
    /// trainable sites when [`TrainConfig::select_every`] is on, else the last — projected
    /// into [ε, 1 − ε]³ with ε = 1e-9 (the crust needs them strictly inside the unit
    /// cube), their labels, and how many sites the projection moved.
    pub fn final_sites(&self) -> (Vec<[f64; 3]>, Vec<bool>, usize) {
        let st = &self.state;
        match &st.best {
            Some(b) => {
                let mut sites = b.sites.clone();
                sites.extend_from_slice(&st.sites[b.sites.len()..]);
                project_sites(&sites, &st.labels)
            }
            None => project_sites(&st.sites, &st.labels),
        }
    }
}

/// One batch: labelled samples, and surface samples with normals (empty: no surface term).
struct Batch<'b> {
    points: &'b [[f64; 3]],
    occupancy: &'b [bool],
    surface: &'b [[f64; 3]],
    normals: &'b [[f64; 3]],
}

/// The loss terms of [`objective`] (unweighted, as [`StepStats`] reports them) and their
/// weighted sum.
struct Terms {
    total: f64,
    reconstruction: f64,
    bounds: f64,
    signed_distance: f64,
    centroidal: f64,
    surface: f64,
}

/// The training objective of `state`'s sites on `batch` at `kernel`, its gradient added into
/// `grad` (the trainable sites'): the one definition a training step and the best-iterate
/// selection share. The signed-distance and centroidal terms use the state's last refresh
/// (closest points, Delaunay graph).
fn objective(
    state: &TrainState,
    kernel: &Kernel,
    batch: &Batch,
    hints: &mut Hints,
    cell: f64,
    grad: &mut [[f64; 3]],
) -> Terms {
    let (sites, labels) = (&state.sites, &state.labels);
    let k = state.config.num_sites;
    let w = &state.config.weights;
    let wants_surface = w.surface > 0.0 && !batch.surface.is_empty();
    // The two grids are built side by side (each build is serial); the trees behind them
    // only when a query needs them.
    let (index, labelled) = rayon::join(
        || SiteIndex::with_cell(sites, cell),
        || wants_surface.then(|| losses::LabelledIndex::with_cell(sites, labels, cell)),
    );
    let rec = losses::reconstruction_hinted(
        kernel,
        &index,
        sites,
        labels,
        batch.points,
        batch.occupancy,
        &mut hints.points,
        w.reconstruction,
        grad,
    );
    let bnd = losses::bounds(&sites[..k], w.bounds, grad);
    let sdf = if w.signed_distance > 0.0 && state.located.len() == k {
        losses::signed_distance_cached(&state.located, &sites[..k], &labels[..k], w.signed_distance, grad)
    } else {
        0.0
    };
    let cen = if w.centroidal > 0.0 && state.graph.num_sites() == sites.len() {
        losses::centroidal(&state.graph, sites, w.centroidal, grad)
    } else {
        0.0
    };
    let srf = match &labelled {
        Some(labelled) => losses::surface_hinted(
            labelled,
            sites,
            batch.surface,
            batch.normals,
            &mut hints.surface,
            w.normal,
            0.0,
            w.surface,
            grad,
        ),
        None => 0.0,
    };
    Terms {
        total: w.reconstruction * rec + w.bounds * bnd + w.signed_distance * sdf + w.centroidal * cen + w.surface * srf,
        reconstruction: rec,
        bounds: bnd,
        signed_distance: sdf,
        centroidal: cen,
        surface: srf,
    }
}

/// The training grids' cell width: the 80th percentile, over surface samples (the training
/// samples when there are none), of the distance to the fourth-nearest site. The grids'
/// queries (the kernel's candidates, the nearest inside and outside site) then mostly end in
/// the 3 × 3 × 3 cells around a sample near the surface; samples far from every site are
/// left to the trees.
fn grid_cell(sites: &[[f64; 3]], data: &TrainingData) -> f64 {
    let points = if data.surface.is_empty() { &data.points } else { &data.surface };
    crate::grid::cell_for(sites, points, 4.min(sites.len()))
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
