//! The main job's options as users give them: one definition for `voronoi-fit fit`'s flags
//! and the Python package's keyword arguments, turned into a [`FitConfig`] by one function,
//! so the two front ends cannot drift apart.

use serde::{Deserialize, Serialize};
use soft_voronoi::{Density, Init, TrainConfig};

use crate::config::{FitConfig, SolidRule, DEFAULT_SITES};
use crate::error::FitError;

/// `--preset fast`: training steps (the default's 200 halved).
pub const FAST_STEPS: usize = 100;
/// `--preset fast`: polish steps, one plain polish (the default runs a plain and an aligned
/// one of 600 at K > 4,096 and keeps the better crust).
pub const FAST_POLISH_STEPS: usize = 300;
/// `--preset fast`: the training pool (the default's 1,000,000 quartered: its winding
/// numbers are most of the sampling stage).
pub const FAST_SAMPLES: usize = 250_000;

/// What a user may set (every field optional: `None` or `false` keeps the default of
/// [`FitConfig::new`] and [`TrainConfig::default_for`]). File paths, checkpoints and the
/// output precision are the front end's business.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FitOptions {
    /// Trainable sites K (default 8,192).
    pub sites: Option<usize>,
    /// Optimisation steps.
    pub steps: Option<usize>,
    /// Seed of the samples, the initialisation and the batches.
    pub seed: u64,
    /// `default`, `fast` (about half the time for a rougher crust: [`FAST_STEPS`],
    /// [`FAST_POLISH_STEPS`] of one plain polish, [`FAST_SAMPLES`]; docs/performance.md)
    /// or `paper` (the seed paper's setting: no polish, no relabelling, no insertion, no
    /// pruning).
    pub preset: Option<String>,
    /// Initialisation.
    pub init: Option<Init>,
    /// How the pairs' density follows the shape (`adaptive`, the default, or `uniform`).
    pub density: Option<Density>,
    /// Training samples per step.
    pub batch: Option<usize>,
    /// Initial learning rate (the cosine schedule keeps its final/initial ratio).
    pub lr: Option<f64>,
    /// β annealing start.
    pub beta_start: Option<f64>,
    /// Pairs' distance from the surface, as a fraction of their spacing.
    pub surface_offset: Option<f64>,
    /// Signed-distance weight.
    pub w_sdf: Option<f64>,
    /// Centroidal weight.
    pub w_centroidal: Option<f64>,
    /// Normal-alignment weight inside the surface term.
    pub w_normal: Option<f64>,
    /// Reconstruction weight.
    pub w_reconstruction: Option<f64>,
    /// Surface-term weight.
    pub w_surface: Option<f64>,
    /// Training sample pool (default 1,000,000).
    pub samples: Option<usize>,
    /// Fresh samples for the misclassification figure (default [`crate::DEFAULT_EVAL_SAMPLES`]).
    pub eval_samples: Option<usize>,
    /// The solid to fit.
    pub solid: SolidRule,
    /// Shell thickness as a fraction of the diagonal.
    pub shell_thickness: Option<f64>,
    /// Cells of the flood fill's grid along the longest side (default
    /// [`crate::config::DEFAULT_FLOOD_CELLS`]).
    pub flood_cells: Option<usize>,
    /// Keep an open mesh's planar holes open (default: closed flat before the
    /// winding-number solid is built, `mesh_io::fill_planar_holes`).
    pub no_fill_holes: bool,
    /// Train a thin shell's sites too, and polish and carve them (default: kept as
    /// constructed; [`FitConfig::train_shell`]).
    pub train_shell: bool,
    /// Keep the training labels.
    pub no_relabel: bool,
    /// Carving tolerance as a fraction of the diagonal (default 0.3%).
    pub carve: Option<f64>,
    /// No carving.
    pub no_carve: bool,
    /// Keep the sites that change neither the crust nor the occupancy.
    pub no_prune: bool,
    /// Skip the metrics against the input (faster; the report says so).
    pub skip_metrics: bool,
    /// No surface polish after training (the paper preset has none either).
    pub no_polish: bool,
    /// Polish steps (default 400; 0 = none).
    pub polish_steps: Option<usize>,
    /// Polish learning rate (default 1e-3 at K = 8,192, scaled by √(8192/K)).
    pub polish_lr: Option<f64>,
    /// Surface samples per polish step (default 20,000).
    pub polish_batch: Option<usize>,
    /// Weight of the polish's alignment term (`soft_voronoi::polish::Alignment`): `None`
    /// (default), on a closed input the aligned polish (weight [`crate::TRY_ALIGNMENT_WEIGHT`]) is tried beside the plain
    /// one and its crust kept only where it is at least as good on all four metrics
    /// ([`FitConfig::try_alignment`]); 0: the plain polish only (VoroLoss alone); W > 0:
    /// always that weight.
    pub polish_align: Option<f64>,
}

impl FitOptions {
    /// The validated settings for a mesh called `name` (used in messages and the report).
    ///
    /// # Errors
    /// [`FitError::Settings`] or [`FitError::TrainSettings`] naming the bad option.
    pub fn to_config(&self, name: &str) -> Result<FitConfig, FitError> {
        let preset = self.preset.as_deref().unwrap_or("default");
        let (paper, fast) = match preset {
            "default" => (false, false),
            "paper" => (true, false),
            "fast" => (false, true),
            other => return Err(FitError::Settings(format!("preset `{other}`: use `default`, `fast` or `paper`"))),
        };
        let mut c = FitConfig::new(name, self.sites.unwrap_or(DEFAULT_SITES));
        let fast_samples = fast.then_some(FAST_SAMPLES);
        let by = |given: bool, preset_sets: bool, default: &str| {
            if given {
                None
            } else if preset_sets {
                Some(format!("preset {preset}"))
            } else {
                Some(default.to_string())
            }
        };
        let defaults = crate::config::WorkSetBy::defaults(c.train.num_sites);
        c.work_set_by = crate::config::WorkSetBy {
            samples: by(self.samples.is_some(), fast, &defaults.samples).unwrap_or("--samples".into()),
            train_steps: by(self.steps.is_some(), fast || paper, &defaults.train_steps).unwrap_or("--steps".into()),
            polish_steps: by(self.polish_steps.is_some(), fast, &defaults.polish_steps)
                .unwrap_or("--polish-steps".into()),
            polish_batch: by(self.polish_batch.is_some(), false, &defaults.polish_batch)
                .unwrap_or("--polish-batch".into()),
        };
        c.sampling.samples = self.samples.or(fast_samples).unwrap_or(c.sampling.samples);
        c.sampling.solid = self.solid;
        c.sampling.shell_thickness = self.shell_thickness;
        if let Some(n) = self.flood_cells {
            if !(16..=500).contains(&n) {
                return Err(FitError::Settings(format!("--flood-cells {n}: use 16 to 500")));
            }
            c.sampling.flood_cells = n;
        }
        c.sampling.fill_holes = !self.no_fill_holes;
        c.train_shell = self.train_shell;
        // The paper preset is the paper's method: no polish, no relabelling, no insertion.
        c.relabel = !self.no_relabel && !paper;
        c.carve = if self.no_carve || (paper && self.carve.is_none()) { None } else { self.carve.or(c.carve) };
        c.prune = !self.no_prune && !paper;
        c.eval.samples = self.eval_samples.unwrap_or(c.eval.samples);
        c.preset = preset.to_string();
        c.skip_metrics = self.skip_metrics;
        let k = c.train.num_sites;
        let mut t = if paper { TrainConfig::paper(k) } else { TrainConfig::default_for(k) };
        if fast {
            t.steps = FAST_STEPS;
        }
        t.steps = self.steps.unwrap_or(t.steps);
        t.init = self.init.unwrap_or(t.init);
        t.density = self.density.unwrap_or(t.density);
        t.batch = self.batch.unwrap_or(t.batch);
        if let Some(lr) = self.lr {
            t.lr_final = if paper { lr } else { lr * (t.lr_final / t.lr) };
            t.lr = lr;
        }
        t.beta_start = self.beta_start.or(t.beta_start);
        t.surface_offset = self.surface_offset.unwrap_or(t.surface_offset);
        t.weights.signed_distance = self.w_sdf.unwrap_or(t.weights.signed_distance);
        t.weights.centroidal = self.w_centroidal.unwrap_or(t.weights.centroidal);
        t.weights.surface = self.w_surface.unwrap_or(t.weights.surface);
        t.weights.reconstruction = self.w_reconstruction.unwrap_or(t.weights.reconstruction);
        t.weights.normal = self.w_normal.unwrap_or(t.weights.normal);
        c.train = t;
        c.polish = if self.no_polish || (paper && self.polish_steps.is_none() && self.polish_lr.is_none()) {
            None
        } else {
            let mut p = soft_voronoi::PolishConfig::default_for(k, self.seed);
            if fast {
                p.steps = FAST_POLISH_STEPS;
                c.try_alignment = None;
            }
            p.steps = self.polish_steps.unwrap_or(p.steps);
            p.lr = self.polish_lr.unwrap_or(p.lr);
            p.batch = self.polish_batch.unwrap_or(p.batch);
            if let Some(w) = self.polish_align {
                p.alignment =
                    (w > 0.0).then(|| soft_voronoi::polish::Alignment { normal_weight: w, ..Default::default() });
                c.try_alignment = None;
            }
            (p.steps > 0).then_some(p)
        };
        if c.polish.is_none() {
            let none = if paper && !self.no_polish { "preset paper: no polish" } else { "no polish" };
            (c.work_set_by.polish_steps, c.work_set_by.polish_batch) = (none.into(), none.into());
        }
        if c.polish.is_some() && self.no_relabel {
            return Err(FitError::Settings(
                "--no-relabel needs --no-polish: the polish moves sites without looking at their labels, so after it \
                 every site takes the solid's label where it stands"
                    .into(),
            ));
        }
        let c = c.with_seed(self.seed);
        c.validate()?;
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(o: FitOptions) -> FitConfig {
        o.to_config("m").unwrap()
    }

    /// `fast` halves the training, polishes once (plain, shorter) and draws a smaller pool;
    /// everything else is the default's, and a flag given beside it wins.
    #[test]
    fn the_fast_preset_and_flags_beside_it() {
        let default = config(FitOptions::default());
        let fast = config(FitOptions { preset: Some("fast".into()), ..Default::default() });
        assert_eq!((default.train.steps, fast.train.steps), (200, FAST_STEPS));
        assert_eq!(fast.sampling.samples, FAST_SAMPLES);
        assert!(default.sampling.samples > FAST_SAMPLES);
        let (dp, fp) = (default.polish.as_ref().unwrap(), fast.polish.as_ref().unwrap());
        assert_eq!((dp.steps, fp.steps), (600, FAST_POLISH_STEPS));
        assert!(default.try_alignment.is_some() && fast.try_alignment.is_none());
        assert_eq!(fp.alignment, None);
        assert_eq!((fast.carve, fast.relabel, fast.prune), (default.carve, default.relabel, default.prune));
        assert_eq!(fast.preset, "fast");
        let given = config(FitOptions {
            preset: Some("fast".into()),
            steps: Some(150),
            samples: Some(500_000),
            polish_steps: Some(450),
            polish_align: Some(0.1),
            ..Default::default()
        });
        assert_eq!((given.train.steps, given.sampling.samples), (150, 500_000));
        let gp = given.polish.as_ref().unwrap();
        assert_eq!(gp.steps, 450);
        assert!(gp.alignment.is_some());
        let bad = FitOptions { preset: Some("quick".into()), ..Default::default() }.to_config("m");
        assert!(bad.unwrap_err().to_string().contains("`default`, `fast` or `paper`"));
        // What set the work, as the report says.
        let w = |c: &FitConfig| {
            let w = &c.work_set_by;
            [w.samples.clone(), w.train_steps.clone(), w.polish_steps.clone(), w.polish_batch.clone()]
        };
        assert_eq!(w(&default), ["default", "default", "default: K > 4096", "default"]);
        assert_eq!(w(&fast), ["preset fast", "preset fast", "preset fast", "default"]);
        assert_eq!(w(&given), ["--samples", "--steps", "--polish-steps", "default"]);
        let small = config(FitOptions { sites: Some(1024), polish_batch: Some(5000), ..Default::default() });
        assert_eq!(w(&small), ["default", "default", "default: K <= 4096", "--polish-batch"]);
        let paper = config(FitOptions { preset: Some("paper".into()), ..Default::default() });
        assert_eq!(w(&paper), ["default", "preset paper", "preset paper: no polish", "preset paper: no polish"]);
        let none = config(FitOptions { no_polish: true, ..Default::default() });
        assert_eq!(w(&none)[2], "no polish");
    }
}
