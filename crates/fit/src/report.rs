//! The fit's report (`OUT.report.json`, `format_version` 1; fields are only ever added).

use serde::Serialize;
use soft_voronoi::{StepStats, TrainConfig, TrainState};

/// The input as read.
#[derive(Clone, Debug, Serialize)]
pub struct InputReport {
    /// Name of the input (the CLI: its path).
    pub path: String,
    /// Vertices as read (before dropping unreferenced ones).
    pub num_vertices: usize,
    /// Triangles as read.
    pub num_triangles: usize,
    /// Every edge has exactly two triangles.
    pub is_closed: bool,
    /// Edge- and vertex-manifold.
    pub is_manifold: bool,
    /// Signed volume (input units³; origin-referenced for open meshes).
    pub signed_volume: f64,
}

/// Settings of the run.
#[derive(Clone, Debug, Serialize)]
pub struct SettingsReport {
    /// Every training setting.
    pub train: TrainConfig,
    /// The preset's name.
    pub preset: String,
    /// Size of the training pool.
    pub samples: usize,
    /// Near-surface spreads of the pool, fractions of the diagonal.
    pub near_surface_sigmas_of_diagonal: Vec<f64>,
    /// The same in unit-cube lengths.
    pub near_surface_sigmas: Vec<f64>,
    /// Empty space around the mesh in the unit cube.
    pub margin: f64,
    /// Size of the evaluation pool.
    pub eval_samples: usize,
    /// The checkpoint the run continued from.
    pub resumed_from: Option<String>,
    /// Worker threads.
    pub threads: usize,
}

/// The map from the unit cube back to the input: x = center + (u − 0.5)·scale… as
/// [`mesh_io::UnitCubeTransform`].
#[derive(Clone, Debug, Serialize)]
pub struct TransformReport {
    /// Centre of the input's bounding box.
    pub center: [f64; 3],
    /// Scale (input units per unit-cube length).
    pub scale: f64,
}

/// Wall time of each stage, seconds.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Timings {
    /// Normalisation.
    pub load: f64,
    /// Occupancy oracle.
    pub oracle: f64,
    /// Training pool.
    pub sample: f64,
    /// Training.
    pub train: f64,
    /// Crust.
    pub crust: f64,
    /// Misclassification.
    pub evaluate: f64,
    /// Metrics against the input.
    pub metrics: f64,
}

/// Per-step losses, subsampled to at most about 200 rows.
#[derive(Clone, Debug, Serialize)]
pub struct LossesReport {
    /// Column names of `rows` ([`StepStats::NAMES`]).
    pub columns: [&'static str; StepStats::COLUMNS],
    /// Every `every`-th step is kept (and the last).
    pub every: usize,
    /// The kept steps.
    pub rows: Vec<[f64; StepStats::COLUMNS]>,
    /// The last step.
    #[serde(rename = "final")]
    pub last: Option<StepStats>,
}

impl LossesReport {
    /// The losses of a training state's history.
    pub fn of(state: &TrainState) -> Self {
        let h = &state.history;
        let every = (h.len() / 200).max(1);
        let rows = h
            .iter()
            .enumerate()
            .filter(|(i, _)| i % every == 0 || *i + 1 == h.len())
            .map(|(_, s)| s.to_row())
            .collect();
        LossesReport { columns: StepStats::NAMES, every, rows, last: h.last().copied() }
    }
}

/// Misclassification of the hard Voronoi occupancy on the fresh evaluation pool.
#[derive(Clone, Debug, Serialize)]
pub struct QualityReport {
    /// Share of all evaluation points whose nearest site has the wrong label.
    pub misclassification: f64,
    /// The same among the uniform points.
    pub misclassification_uniform: f64,
    /// The same among the near-surface points.
    pub misclassification_near_surface: f64,
    /// Seed of the evaluation pool.
    pub eval_seed: u64,
    /// Its near-surface spreads, fractions of the diagonal.
    pub eval_near_surface_sigmas_of_diagonal: Vec<f64>,
    /// The same in unit-cube lengths.
    pub eval_near_surface_sigmas: Vec<f64>,
}

/// The crust as written (every figure is of the mesh in the output file).
#[derive(Clone, Debug, Serialize)]
pub struct CrustReport {
    /// Sites (trainable and boundary).
    pub num_sites: usize,
    /// Inside sites.
    pub num_inside: usize,
    /// Sites the projection into the cube moved.
    pub num_sites_projected_into_cube: usize,
    /// Voronoi vertices extraction merged (clusters f64 cannot tell apart).
    pub num_merged_vertices: usize,
    /// Vertices merged when rounding to the output precision.
    pub num_merged_in_output: usize,
    /// Split-vertex copies moved a few ulps apart in the output (so readers that weld
    /// coincident vertices keep the mesh manifold).
    pub num_separated_in_output: usize,
    /// Vertices.
    pub num_vertices: usize,
    /// Triangles.
    pub num_triangles: usize,
    /// Connected components.
    pub num_components: usize,
    /// Genus (when closed and manifold).
    pub genus: Option<i64>,
    /// Every edge has two triangles.
    pub is_closed: bool,
    /// Edge- and vertex-manifold.
    pub is_manifold: bool,
    /// Pairs of intersecting triangles (the exact check requires 0).
    pub self_intersections: usize,
    /// Volume, input units³.
    pub volume: f64,
}

/// Paths of the files written (filled in by the writer, e.g. the CLI).
#[derive(Clone, Debug, Default, Serialize)]
pub struct OutputsReport {
    /// The crust mesh.
    pub crust: String,
    /// The sites file.
    pub sites: String,
    /// The report.
    pub report: String,
}

/// Metrics against the input, or why they could not be computed.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum MetricsReport {
    /// The `voronoi-fit eval` report.
    Done(Box<metrics::EvalReport>),
    /// The metrics failed (the fit itself did not).
    Failed {
        /// The error.
        error: String,
    },
    /// Not asked for.
    Skipped {
        /// Why.
        skipped: String,
    },
}

/// The whole report.
#[derive(Clone, Debug, Serialize)]
pub struct FitReport {
    /// Version of this layout (1).
    pub format_version: u32,
    /// The input.
    pub input: InputReport,
    /// The settings.
    pub settings: SettingsReport,
    /// Unit cube → input frame.
    pub transform: TransformReport,
    /// Stage timings.
    pub timings_seconds: Timings,
    /// Losses.
    pub losses: LossesReport,
    /// Misclassification.
    pub quality: QualityReport,
    /// Metrics against the input.
    pub metrics: MetricsReport,
    /// The crust.
    pub crust: CrustReport,
    /// Files written (empty until a writer fills them in).
    pub outputs: OutputsReport,
    /// Wall time of the fit, seconds.
    pub total_seconds: f64,
}

impl FitReport {
    /// One paragraph for people: what was fitted, how well, and what the crust is.
    pub fn summary(&self) -> String {
        let q = &self.quality;
        let c = &self.crust;
        let t = &self.settings.train;
        let metrics = match &self.metrics {
            MetricsReport::Done(m) => format!(
                "Against the input: Hausdorff in [{:.4e}, {:.4e}] (certified; libigl's vertex-only value {:.4e}), \
                 Chamfer L1 {:.4e}, F-score {:.4}, IoU {}.",
                m.hausdorff.lo,
                m.hausdorff.hi,
                m.hausdorff_libigl,
                m.surface.chamfer_l1,
                m.surface.fscore,
                m.iou.as_ref().and_then(|i| i.iou).map_or("n/a".to_string(), |v| format!("{v:.5}"))
            ),
            MetricsReport::Failed { error } => format!("Metrics against the input failed: {error}."),
            MetricsReport::Skipped { .. } => String::new(),
        };
        let inside_trainable = c.num_inside;
        format!(
            "{}: fitted {} sites ({} inside, {} fixed on the boundary) in {} steps; on {} fresh samples {:.3}% are \
             misclassified ({:.3}% of uniform, {:.3}% of near-surface ones). Crust: {} triangles, {} component(s), \
             genus {}, closed, manifold and free of self-intersections (checked), volume {:.6e}. {}",
            self.input.path,
            t.num_sites,
            inside_trainable,
            c.num_sites - t.num_sites,
            t.steps,
            self.settings.eval_samples,
            100.0 * q.misclassification,
            100.0 * q.misclassification_uniform,
            100.0 * q.misclassification_near_surface,
            c.num_triangles,
            c.num_components,
            c.genus.map_or("n/a".to_string(), |g| g.to_string()),
            c.volume,
            metrics
        )
    }
}
