//! Sizes and budgets of a study.

use serde::Serialize;

/// The budgets and sizes of a study.
#[derive(Clone, Debug, Serialize)]
pub struct Budget {
    /// Voronoi site counts K (3K parameters).
    pub voronoi_sites: Vec<usize>,
    /// Voronoi training steps (default preset otherwise: 16,384 samples per step).
    pub voronoi_steps: usize,
    /// MLP (width, depth = hidden layers) pairs, for both decoders.
    pub mlp_sizes: Vec<(usize, usize)>,
    /// MLP training steps.
    pub mlp_steps: usize,
    /// MLP batch size.
    pub mlp_batch: usize,
    /// MLP learning rate (cosine decay to 1% of it).
    pub mlp_lr: f64,
    /// Marching-cubes grid resolution (points per axis over the unit cube).
    pub mc_res: usize,
    /// Training points (half uniform in the cube, half near the sphere).
    pub samples: usize,
    /// Surface samples per side for the Chamfer distance.
    pub chamfer_samples: usize,
}

impl Budget {
    /// The full study (about 22 minutes on 2 cores).
    pub fn full() -> Self {
        Budget {
            voronoi_sites: vec![8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192],
            voronoi_steps: 600,
            mlp_sizes: vec![(4, 2), (8, 2), (16, 3), (32, 3), (64, 3), (128, 3), (256, 3), (512, 3), (512, 4)],
            mlp_steps: 1000,
            mlp_batch: 8192,
            mlp_lr: 1e-3,
            mc_res: 128,
            samples: 1_000_000,
            chamfer_samples: 100_000,
        }
    }

    /// Small sizes and budgets (under 2 minutes; what CI runs).
    pub fn quick() -> Self {
        Budget {
            voronoi_sites: vec![8, 64, 512],
            voronoi_steps: 100,
            mlp_sizes: vec![(16, 2), (32, 2)],
            mlp_steps: 400,
            mlp_batch: 4096,
            mlp_lr: 3e-3,
            mc_res: 48,
            samples: 200_000,
            chamfer_samples: 20_000,
        }
    }

    /// Number of runs (one per Voronoi size, two per MLP size).
    pub fn num_runs(&self) -> usize {
        self.voronoi_sites.len() + 2 * self.mlp_sizes.len()
    }
}
