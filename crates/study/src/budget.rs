//! Sizes, budgets and convergence rules of a study.

use serde::Serialize;

use crate::plateau::PlateauRule;

/// The budgets and sizes of a study. The same sample rule holds for every method: one
/// pool of `samples` points (half uniform in the cube, half near the sphere) per seed,
/// drawn by the main job's sampler for the Voronoi fits (from the triangulated sphere) and
/// analytically for the decoders.
#[derive(Clone, Debug, Serialize)]
pub struct Budget {
    /// Seeds: every (method, size) runs once per seed.
    pub seeds: Vec<u64>,
    /// Voronoi site counts K (3K parameters; also the construction's).
    pub voronoi_sites: Vec<usize>,
    /// Whether to fit the Voronoi sites (off: only the construction at each K).
    pub voronoi: bool,
    /// Subdivisions of the icosphere the main job fits (vertices on the sphere; 6 gives
    /// 81,920 triangles, at most 1.2e-5 inside the sphere).
    pub icosphere_subdivisions: u32,
    /// Training steps of the main job's schedule (`None`: its default, `fit::FitConfig::new`'s
    /// `train.steps`, 200 today).
    pub voronoi_steps: Option<usize>,
    /// When a Voronoi fit's loss has not flattened (see [`crate::plateau::flattened`],
    /// windows of a tenth of the steps, 1%), it is run again with twice the steps, up to
    /// this many times.
    pub voronoi_max_doublings: usize,
    /// Fresh samples for the main job's misclassification figure.
    pub voronoi_eval_samples: usize,
    /// MLP (width, depth = hidden layers) pairs, for each decoder of `decoders`.
    pub mlp_sizes: Vec<(usize, usize)>,
    /// The decoders: `occnet` and `deepsdf`.
    pub decoders: Vec<String>,
    /// Whether to run the reference lines (the construction at every K of
    /// `voronoi_sites`, the marching-cubes floor).
    pub references: bool,
    /// MLP batch size.
    pub mlp_batch: usize,
    /// MLP initial learning rate (Adam), lowered at each plateau.
    pub mlp_lr: f64,
    /// When an MLP has converged.
    pub mlp_plateau: PlateauRule,
    /// Marching-cubes grid resolution (points per axis over the unit cube).
    pub mc_res: usize,
    /// Training points per seed (half uniform in the cube, half near the sphere).
    pub samples: usize,
    /// Surface samples per side for the Chamfer distance.
    pub chamfer_samples: usize,
    /// Offsets δ of the reference construction, as fractions of the pairs' spacing (the
    /// best is drawn).
    pub construction_offsets: Vec<f64>,
}

impl Budget {
    /// The full study (about 35 minutes on 2 cores; the committed run's time is in
    /// `assets/study/table.md`).
    pub fn full() -> Self {
        Budget {
            seeds: vec![0, 1, 2],
            voronoi_sites: vec![8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192],
            voronoi: true,
            icosphere_subdivisions: 6,
            voronoi_steps: None,
            // Measured at seed 0 (before the main job kept its best iterate): 4× the steps
            // left the Hausdorff distance where it was (K = 1,024: 3.77e-3 → 3.71e-3;
            // K = 8,192: 1.34e-3 → 1.38e-3) at 3–5× the time. With the best iterate kept,
            // doubling once left K ≥ 512 still "not flattened" (the loss keeps falling
            // slowly to the end of any cosine schedule) and K = 4,096 and 8,192 still
            // keeping their initialisation, at 2–3× the time.
            voronoi_max_doublings: 0,
            voronoi_eval_samples: 100_000,
            // 256×3 (132,865 parameters) trained to its plateau takes 5–10 minutes per seed
            // here (OccNet: 5,800 steps), which three seeds of both decoders cannot afford
            // within the study's 45 minutes.
            mlp_sizes: vec![(4, 2), (8, 2), (16, 3), (32, 3), (64, 3), (128, 3)],
            decoders: vec!["occnet".into(), "deepsdf".into()],
            references: true,
            mlp_batch: 4096,
            mlp_lr: 1e-3,
            mlp_plateau: PlateauRule {
                window: 200,
                min_improvement: 0.01,
                patience: 2,
                factor: 0.1,
                reductions: 2,
                min_steps: 1000,
                max_steps: 10_000,
            },
            mc_res: 128,
            samples: 500_000,
            chamfer_samples: 100_000,
            construction_offsets: vec![0.25, 0.5],
        }
    }

    /// Small sizes and budgets (under 2 minutes; what CI runs): every method, two seeds,
    /// the reference lines.
    pub fn quick() -> Self {
        Budget {
            seeds: vec![0, 1],
            voronoi_sites: vec![8, 64, 512],
            voronoi: true,
            icosphere_subdivisions: 4,
            voronoi_steps: Some(100),
            voronoi_max_doublings: 1,
            voronoi_eval_samples: 20_000,
            mlp_sizes: vec![(16, 2), (32, 2)],
            decoders: vec!["occnet".into(), "deepsdf".into()],
            references: true,
            mlp_batch: 2048,
            mlp_lr: 3e-3,
            mlp_plateau: PlateauRule {
                window: 50,
                min_improvement: 0.01,
                patience: 2,
                factor: 0.1,
                reductions: 1,
                min_steps: 100,
                max_steps: 400,
            },
            mc_res: 48,
            samples: 100_000,
            chamfer_samples: 20_000,
            construction_offsets: vec![0.5],
        }
    }

    /// Number of runs (per seed: one per Voronoi size, one per decoder and MLP size),
    /// without the reference lines.
    pub fn num_runs(&self) -> usize {
        let voronoi = if self.voronoi { self.voronoi_sites.len() } else { 0 };
        self.seeds.len() * (voronoi + self.decoders.len() * self.mlp_sizes.len())
    }
}
