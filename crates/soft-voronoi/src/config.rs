//! Training settings, the two presets and their schedules.

use serde::{Deserialize, Serialize};

use crate::error::TrainError;
use vf_common::AdamParams;

/// How the sites start.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Init {
    /// The paper's: K sites uniform in the unit cube, alternately labelled inside and
    /// outside (half each, whatever the shape).
    Paper,
    /// This crate's default: K distinct training samples drawn at random from the training
    /// pool (uniform and near-surface points), labelled with their ground truth; so about
    /// half the sites start next to the surface, on its correct side.
    Samples,
    /// Pairs of sites straddling the surface at random surface points, one on each side
    /// along the normal, labelled by the solid (see [`crate::init::surface_init`]).
    Surface,
    /// Mirrored pairs p ± δn at well-spread (Poisson-disk) surface points, δ half their
    /// spacing, shrunk where the part is thinner (see [`crate::init::pairs_init`]).
    Pairs,
}

/// How [`Init::Pairs`] spreads the K sites over the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Density {
    /// The default: closer pairs where the part is thinner, or the surface more folded, than
    /// the uniform spacing (each pair's spacing capped at the largest of r0, r0/2, …,
    /// r0/16 whose pair stays on its own sides of the solid), parts thinner than the pairs
    /// rescued, the rest of the surface at the uniform spacing that keeps K
    /// ([`crate::init::pairs_init`]).
    #[default]
    Adaptive,
    /// One Poisson-disk spacing over the whole surface (the ablation's baseline): thin
    /// parts and folds get no more pairs than flat faces.
    Uniform,
}

impl std::str::FromStr for Density {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "adaptive" => Ok(Density::Adaptive),
            "uniform" => Ok(Density::Uniform),
            _ => Err(format!("unknown density '{s}' (expected 'adaptive' or 'uniform')")),
        }
    }
}

impl std::str::FromStr for Init {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "paper" => Ok(Init::Paper),
            "samples" => Ok(Init::Samples),
            "surface" => Ok(Init::Surface),
            "pairs" => Ok(Init::Pairs),
            _ => Err(format!("unknown init '{s}' (expected 'pairs', 'surface', 'samples' or 'paper')")),
        }
    }
}

/// Weights of the four loss terms.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Weights {
    /// Reconstruction E|O − V|.
    pub reconstruction: f64,
    /// Bounds Σ max(−p, 0) + max(p − 1, 0).
    pub bounds: f64,
    /// Signed distance of each site to its side of the surface.
    pub signed_distance: f64,
    /// Centroidal ‖L p‖² on the Delaunay graph.
    pub centroidal: f64,
    /// Surface term: squared distance of surface samples to the bisector of their nearest
    /// inside and outside sites ([`crate::losses::surface`]).
    #[serde(default)]
    pub surface: f64,
    /// Within the surface term, the weight of the normal alignment 1 − (u·n)² relative to
    /// the squared distance.
    #[serde(default)]
    pub normal: f64,
}

/// Everything that determines a training run (with the training data and the seed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfig {
    /// Number of trainable sites K.
    pub num_sites: usize,
    /// Fixed outside sites on the faces of the unit cube; `None` = ⌈√K⌉ (the paper's).
    pub boundary_sites: Option<usize>,
    /// Optimisation steps.
    pub steps: usize,
    /// Training samples per step (drawn with replacement from the pool).
    pub batch: usize,
    /// Surface samples per step for the surface term (drawn with replacement from the
    /// data's surface points).
    #[serde(default = "default_surface_batch")]
    pub surface_batch: usize,
    /// Initial learning rate (unit-cube lengths; Adam's steps are about this long).
    pub lr: f64,
    /// Final learning rate of the cosine schedule (= `lr` for a constant rate).
    pub lr_final: f64,
    /// Final temperature β.
    pub beta: f64,
    /// Optional annealing: β rises geometrically from `beta_start` to `beta` over the
    /// first `anneal_fraction` of the steps.
    pub beta_start: Option<f64>,
    /// Fraction of the steps spent annealing β (when `beta_start` is set).
    pub anneal_fraction: f64,
    /// Candidate window τ (weights below e^−τ are dropped).
    pub tau: f64,
    /// Loss weights.
    pub weights: Weights,
    /// Recompute the Delaunay graph of the sites (centroidal term) and the sites' sides and
    /// closest surface points (signed-distance term) every this many steps. Default 10:
    /// for 8,192 sites the Delaunay graph costs about as much as one training step (~40
    /// ms) and the closest points of all sites a few steps' worth, so refreshing every step
    /// would double or triple the run; in 10 steps a site moves by at most ~10 learning
    /// rates (3e-4 of the cube at the default rate, against a site spacing of ~1e-2), too
    /// little to change more than a handful of Delaunay edges.
    pub refresh_every: usize,
    /// Keep the best iterate: every this many steps, and after the last, the total loss
    /// (at the final β) is measured on a fixed evaluation batch (`selection_batch` samples
    /// and as many surface samples, drawn once from the data with their own random
    /// streams), and the sites with the lowest one are the run's result
    /// ([`crate::Trainer::final_sites`]). 0 = off: the last iterate is the result.
    ///
    /// Why: the per-step batches make the gradients noisy, and Adam normalises that noise
    /// into steps about a learning rate long for every site, so late in a run the loss can
    /// wander above where it was. On the study's sphere the default schedule ends at twice
    /// the total loss it started from (0.0135 against 0.0076 at K = 8,192) and at twice the
    /// Hausdorff distance of its own initialisation.
    #[serde(default)]
    pub select_every: usize,
    /// Samples in the fixed evaluation batch of `select_every` (and as many surface
    /// samples).
    #[serde(default = "default_selection_batch")]
    pub selection_batch: usize,
    /// Initialisation.
    pub init: Init,
    /// [`Init::Surface`] and [`Init::Pairs`]: distance of each site from the surface, as a
    /// fraction of the (local) spacing of the pairs.
    pub surface_offset: f64,
    /// [`Init::Pairs`]: how the pairs' density follows the shape ([`Density`]).
    #[serde(default)]
    pub density: Density,
    /// Adam's constants.
    pub adam: AdamParams,
    /// Seed of the initialisation and the batches.
    pub seed: u64,
}

fn default_surface_batch() -> usize {
    16384
}

fn default_selection_batch() -> usize {
    65536
}

impl TrainConfig {
    /// The default, measured on the bundled bunny, spot, featuretype and the quality
    /// benchmark (the ablation in CHANGELOG.md): mirrored pairs at well-spread surface
    /// points ([`Init::Pairs`], δ = the local spacing), the seed's reconstruction and bounds
    /// losses with the surface term (surface samples pulled onto the bisector of their
    /// nearest inside and outside sites, with normal alignment of weight 1: measured against
    /// 0.1 with relabelling and carving on the bunny, spot, featuretype and box_fin, better
    /// on 19 of the 20 mesh × metric pairs, all but featuretype's Hausdorff), a small
    /// learning rate with cosine decay. The signed-distance and centroidal terms changed the misclassification
    /// by less than 0.02 percentage points and cost 30–60% more time, so their weight is 0
    /// (the paper preset keeps 1).
    pub fn default_for(num_sites: usize) -> Self {
        TrainConfig {
            num_sites,
            boundary_sites: None,
            steps: 200,
            batch: 16384,
            surface_batch: default_surface_batch(),
            lr: Self::default_lr(num_sites),
            lr_final: 0.01 * Self::default_lr(num_sites),
            beta: 10_000.0,
            beta_start: None,
            anneal_fraction: 0.5,
            tau: crate::kernel::DEFAULT_TAU,
            weights: Weights {
                reconstruction: 1.0,
                bounds: 1.0,
                signed_distance: 0.0,
                centroidal: 0.0,
                surface: 1.0,
                normal: 1.0,
            },
            refresh_every: 10,
            select_every: 25,
            selection_batch: default_selection_batch(),
            init: Init::Pairs,
            surface_offset: 1.0,
            density: Density::Adaptive,
            adam: AdamParams::default(),
            seed: 0,
        }
    }

    /// The default learning rate: 3e-4 at 8,192 sites (about 3% of the pairs' spacing on
    /// the bunny), scaled with the sites' expected spacing on a surface (∝ K^−1/2), so
    /// fewer sites may move proportionally farther.
    ///
    /// With the surface polish after it, 200 steps from 3e-4 measured as well as 600 from
    /// 1e-4 on the 16 meshes of the quality benchmark (some metrics better, some worse, by
    /// about as much as a change of seed moves them; docs/quality.md) in a third
    /// of the training time; 200 from 1e-4 and 100 from 6e-4 were worse on more of the eight
    /// meshes they were tried on.
    pub fn default_lr(num_sites: usize) -> f64 {
        3e-4 * (8192.0 / num_sites.max(1) as f64).sqrt()
    }

    /// The seed paper's setting as this project reads it: uniform half-inside/half-outside
    /// initialisation, β = 10,000 throughout, a constant learning rate, all four losses
    /// with unit weight.
    pub fn paper(num_sites: usize) -> Self {
        TrainConfig {
            init: Init::Paper,
            surface_offset: 0.25,
            steps: 1000,
            lr: 1e-3,
            lr_final: 1e-3,
            select_every: 0,
            weights: Weights {
                reconstruction: 1.0,
                bounds: 1.0,
                signed_distance: 1.0,
                centroidal: 1.0,
                surface: 0.0,
                normal: 0.0,
            },
            ..TrainConfig::default_for(num_sites)
        }
    }

    /// Number of boundary sites: at least `boundary_sites` (default ⌈√K⌉), rounded up to
    /// a full m×m grid on each of the 6 faces.
    pub fn num_boundary(&self) -> usize {
        crate::init::boundary_grid_size(self.boundary_request()).map_or(0, |m| 6 * m * m)
    }

    /// The fixed outside sites on the cube's faces that training adds after the K
    /// trainable ones ([`crate::init::boundary_sites`] of `boundary_sites`, default ⌈√K⌉).
    pub fn boundary_positions(&self) -> Vec<[f64; 3]> {
        crate::init::boundary_sites(self.boundary_request())
    }

    /// The boundary sites asked for: `boundary_sites`, default ⌈√K⌉.
    fn boundary_request(&self) -> usize {
        self.boundary_sites.unwrap_or_else(|| (self.num_sites as f64).sqrt().ceil() as usize)
    }

    /// Learning rate at 0-based step `t`: cosine from `lr` to `lr_final`.
    pub fn lr_at(&self, t: usize) -> f64 {
        let x = t as f64 / self.steps.max(1) as f64;
        self.lr_final + 0.5 * (self.lr - self.lr_final) * (1.0 + (std::f64::consts::PI * x).cos())
    }

    /// β at 0-based step `t`.
    pub fn beta_at(&self, t: usize) -> f64 {
        match self.beta_start {
            None => self.beta,
            Some(b0) => {
                let span = (self.anneal_fraction * self.steps as f64).max(1.0);
                let x = (t as f64 / span).min(1.0);
                b0 * (self.beta / b0).powf(x)
            }
        }
    }

    /// Checks every setting.
    ///
    /// # Errors
    /// [`TrainError::Config`] naming the setting and its accepted range.
    pub fn validate(&self) -> Result<(), TrainError> {
        let bad = |m: String| Err(TrainError::Config(m));
        let pos = |x: f64| x.is_finite() && x > 0.0;
        let nonneg = |x: f64| x.is_finite() && x >= 0.0;
        if self.num_sites < 2 || self.num_sites > 4_000_000 {
            return bad(format!("sites = {} must be in 2..=4000000", self.num_sites));
        }
        if self.surface_batch == 0 || self.surface_batch > 50_000_000 {
            return bad(format!("surface_batch = {} must be in 1..=50000000", self.surface_batch));
        }
        if self.select_every > 0 && (self.selection_batch == 0 || self.selection_batch > 50_000_000) {
            return bad(format!("selection_batch = {} must be in 1..=50000000", self.selection_batch));
        }
        if self.batch == 0 || self.batch > 50_000_000 {
            return bad(format!("batch = {} must be in 1..=50000000", self.batch));
        }
        if !pos(self.lr) || !nonneg(self.lr_final) {
            return bad(format!(
                "learning rates {} → {} must be finite, lr > 0, lr_final >= 0",
                self.lr, self.lr_final
            ));
        }
        if !pos(self.beta) || self.beta_start.is_some_and(|b| !pos(b)) {
            return bad(format!("beta = {} (start {:?}) must be finite and > 0", self.beta, self.beta_start));
        }
        if !(self.anneal_fraction.is_finite() && self.anneal_fraction > 0.0 && self.anneal_fraction <= 1.0) {
            return bad(format!("anneal_fraction = {} must be in (0, 1]", self.anneal_fraction));
        }
        if !pos(self.tau) {
            return bad(format!("tau = {} must be finite and > 0", self.tau));
        }
        let w = &self.weights;
        for (name, x) in [
            ("reconstruction", w.reconstruction),
            ("bounds", w.bounds),
            ("signed_distance", w.signed_distance),
            ("centroidal", w.centroidal),
            ("surface", w.surface),
            ("normal", w.normal),
        ] {
            if !nonneg(x) {
                return bad(format!("weight {name} = {x} must be finite and >= 0"));
            }
        }
        if !(self.surface_offset.is_finite() && self.surface_offset > 0.0 && self.surface_offset < 10.0) {
            return bad(format!("surface_offset = {} must be in (0, 10)", self.surface_offset));
        }
        if self.refresh_every == 0 {
            return bad("refresh_every must be >= 1".into());
        }
        self.adam.validate().map_err(TrainError::Config)?;
        Ok(())
    }
}
