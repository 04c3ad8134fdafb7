//! The fit's report (`OUT.report.json`, `format_version` 1; fields are only ever added).

use std::cmp::Ordering;

use serde::Serialize;
use soft_voronoi::{StepStats, TrainConfig, TrainState};

mod stages;
mod summary;

pub use stages::{
    AccuracyReport, BandTrial, CarveReport, FloodReport, GrowthRow, GuardReport, SheetBand, SolidReport, SurfaceBar,
    CHOSEN_AFTER_EMPTY_WINDING, CHOSEN_FOR_LARGE_CAPS,
};
pub use summary::{SHELL_HINT_ABOVE, SUMMARY_LINES};

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
    /// Genus of the input surface (the sum over its components), when it is closed,
    /// manifold and orientable; `null` otherwise.
    pub genus: Option<i64>,
    /// Triangles turned to agree with their neighbours before the solid was built
    /// ([`mesh_io::orient_consistently`]): the winding-number solid is that of the
    /// consistently oriented mesh.
    pub reoriented: mesh_io::Reorientation,
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
    /// What set the pool's size and the steps ([`crate::config::WorkSetBy`]).
    pub work_set_by: crate::config::WorkSetBy,
}

/// The map from the input to the unit cube: u = (x − center)·scale + 0.5, as
/// [`mesh_io::UnitCubeTransform`].
#[derive(Clone, Debug, Serialize)]
pub struct TransformReport {
    /// Centre of the input's bounding box.
    pub center: [f64; 3],
    /// Scale (unit-cube lengths per input length, as [`mesh_io::UnitCubeTransform`]).
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
    /// Surface polish.
    #[serde(default)]
    pub polish: f64,
    /// Crust.
    pub crust: f64,
    /// Misclassification.
    pub evaluate: f64,
    /// Metrics against the input.
    pub metrics: f64,
    /// Where the crust stage's time went (summed over both attempts on a closed input; the
    /// rest of `crust` is relabelling and bookkeeping).
    ///
    /// On a closed input `polish`, `crust`, `metrics` and these parts are the two attempts'
    /// own seconds summed; the attempts run side by side, so the stages add up to more
    /// than the report's `total_seconds`.
    pub crust_parts: CrustParts,
}

/// Parts of the crust stage, seconds ([`Timings::crust_parts`]).
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct CrustParts {
    /// The guard against crust outside the input's box, before and after carving.
    pub guard: f64,
    /// Carving: its rounds' crust extractions, their distances to the input and the sites
    /// they insert.
    pub carve: f64,
    /// Pruning sites that change no crust face.
    pub prune: f64,
    /// The crust as written: extraction, rounding to the output's precision, the repair
    /// of what rounding breaks, and the exact checks.
    pub write: f64,
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
    /// The iterate the crust was built from when the best one was kept
    /// (`TrainConfig::select_every` > 0): steps done when it was measured (0 = the
    /// initialisation) and its total loss on the fixed evaluation batch; absent when the
    /// last iterate is used.
    pub selected: Option<SelectedIterate>,
}

/// See [`LossesReport::selected`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SelectedIterate {
    /// Steps done when it was measured.
    pub step: usize,
    /// Its total loss on the evaluation batch.
    pub loss: f64,
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
        let selected = state.best.as_ref().map(|b| SelectedIterate { step: b.step, loss: b.loss });
        LossesReport { columns: StepStats::NAMES, every, rows, last: h.last().copied(), selected }
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
    /// Number of misclassified evaluation points (all, uniform, near-surface).
    pub misclassified_counts: [usize; 3],
    /// Number of evaluation points (all, uniform, near-surface).
    pub eval_counts: [usize; 3],
    /// 95% Wilson score intervals of the three shares above, in the same order: the
    /// evaluation is a sample, and this is how far its figure can be from the share over
    /// the whole sampling distribution.
    pub misclassification_ci95: [[f64; 2]; 3],
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
    /// Sites in the sites file: trainable, boundary and inserted, less the pruned ones.
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
    /// Components and genus of the exact crust when rounding to the output's floats
    /// changed them (a handle or gap thinner than a few units in the last place closed);
    /// `null` when the file has the exact crust's topology.
    pub topology_before_rounding: Option<(usize, i64)>,
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

/// Report field `topology`: the crust's handles against the input's. Made where the
/// input's genus is the solid's: a closed, manifold, orientable input fitted as its
/// winding-number solid with none of its surface inside the solid (no overlapping bodies or
/// doubled faces, `solid.interior_surface_share` = 0; where bodies overlap the solid's
/// genus is not the sum of theirs).
///
/// A handle closes where the hole through it is narrower than the sites can resolve (about
/// two site spacings at this K); a handle is added where two parts closer than that are
/// bridged.
#[derive(Clone, Debug, Serialize)]
pub struct TopologyCheck {
    /// The input's genus.
    pub input_genus: i64,
    /// The crust's genus.
    pub crust_genus: i64,
    /// The input's connected components.
    pub input_components: usize,
    /// The crust's connected components.
    pub crust_components: usize,
    /// Handles of the input the crust does not have (input genus − crust genus, or 0).
    pub handles_closed: i64,
    /// Handles of the crust the input does not have (crust genus − input genus, or 0).
    pub handles_added: i64,
}

impl TopologyCheck {
    /// The check of a crust of genus `crust_genus` with `crust_components` components
    /// against an input of `input_genus` and `input_components`.
    pub fn new(input_genus: i64, input_components: usize, crust_genus: i64, crust_components: usize) -> Self {
        TopologyCheck {
            input_genus,
            crust_genus,
            input_components,
            crust_components,
            handles_closed: (input_genus - crust_genus).max(0),
            handles_added: (crust_genus - input_genus).max(0),
        }
    }

    /// Handles and components the crust differs by from the input (0: kept).
    pub fn off_by(&self) -> i64 {
        self.handles_closed + self.handles_added + (self.input_components as i64 - self.crust_components as i64).abs()
    }

    /// Whether the crust has the input's genus and components.
    pub fn kept(&self) -> bool {
        self.off_by() == 0
    }
}

/// Report field `pruning`: the sites removed last because every Delaunay neighbour
/// carries their label, so neither the crust nor the nearest-site occupancy changes
/// ([`crust::prune`]).
#[derive(Clone, Debug, Serialize)]
pub struct PruneReport {
    /// Sites removed in each round (an independent set each).
    pub removed_per_round: Vec<usize>,
    /// Sites before: trainable, boundary and inserted.
    pub sites_before: usize,
    /// Sites after: what the sites file holds.
    pub sites_after: usize,
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
    /// The normals a glTF crust carries (`flat`, `smooth` or `crease:DEG`; empty when the
    /// writer did not say).
    pub crust_normals: String,
    /// The occupancy samples of the fitted solid (`OUT.points.npz`), when asked for.
    pub occupancy: Option<String>,
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
    /// The solid fitted: the winding-number solid, or a thin shell around a surface without
    /// volume.
    pub solid: SolidReport,
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
    /// Share of the pairs' candidate points refined from a previous fit (accuracy target
    /// rounds after the first), else absent.
    pub refined_share: Option<f64>,
    /// The surface polish after training (absent when off or on a thin shell).
    pub polish: Option<soft_voronoi::PolishReport>,
    /// The default's choice between the plain and the aligned polish on a closed input
    /// (absent when it was not made: open input, thin shell, no polish, `--polish-align`).
    pub polish_choice: Option<PolishChoice>,
    /// Trainable sites whose label was changed to the solid's at their final position
    /// (absent when relabelling was off).
    pub relabelled_sites: Option<usize>,
    /// Sites inserted where the crust strayed from the input (absent when off).
    pub carving: Option<CarveReport>,
    /// Outside mirror sites that cut inside cells at the input's bounding box (with
    /// carving; absent when off).
    pub guard: Option<GuardReport>,
    /// Sites removed last because they change neither the crust nor the occupancy (absent
    /// when off).
    pub pruning: Option<PruneReport>,
    /// The accuracy target's goal and error-against-K trace, when one was asked for.
    pub accuracy_target: Option<AccuracyReport>,
    /// What `metrics.iou` is measured against: the solid the sites were fitted to (the
    /// reoriented winding-number solid, the flood solid or the thin shell), not the raw
    /// input's winding number (`voronoi-fit eval` measures that one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iou_reference: Option<String>,
    /// The crust's genus against the input's, where the input's says what the solid's
    /// should be (see [`TopologyCheck`]); absent otherwise.
    pub topology: Option<TopologyCheck>,
    /// Files written (empty until a writer fills them in).
    pub outputs: OutputsReport,
    /// Wall time of the fit, seconds.
    pub total_seconds: f64,
}

/// The default's choice between the plain polish and the aligned one on a closed input
/// (`run::choose_alignment`): both crusts, measured against the input as written.
#[derive(Clone, Debug, Serialize)]
pub struct PolishChoice {
    /// The crust of the plain polish (VoroLoss alone); `None` when its metrics failed.
    pub plain: Option<PolishScores>,
    /// The crust of the aligned polish; `None` when it could not be built or measured.
    pub aligned: Option<PolishScores>,
    /// Why the aligned polish's crust could not be built (rounding to the output's
    /// precision), when it could not.
    pub aligned_error: Option<String>,
    /// When the aligned attempt stopped before carving: both uncarved crusts' Chamfer
    /// distance and normal consistency (unit-cube lengths), the aligned one short of the
    /// plain one's on one of them.
    pub before_carving: Option<BeforeCarving>,
    /// Whether the aligned crust was kept: at least as good on all four and better on one
    /// (Hausdorff distances both within the F-score's τ, or whose certified intervals
    /// overlap, count as equal; [`PolishScores::no_worse_and_better_than`]).
    pub aligned_kept: bool,
    /// The input's bounding-box diagonal (mesh units), for shares of it.
    pub diagonal: f64,
    /// Wall time of the aligned attempt (its polish, crust and measurement), which runs
    /// beside the plain one, seconds.
    pub seconds: f64,
}

impl PolishScores {
    /// At least as good as `other` on all four metrics and better on one, the Hausdorff
    /// distances compared by [`PolishScores::hausdorff_cmp`]. Any value not finite: false.
    pub fn no_worse_and_better_than(&self, other: &PolishScores) -> bool {
        let (a, b) = (other, self);
        let finite = |s: &PolishScores| {
            [s.hausdorff, s.hausdorff_lo, s.chamfer_l1, s.fscore, s.normal_consistency, s.fscore_tau]
                .iter()
                .all(|v| v.is_finite())
        };
        if !(finite(a) && finite(b)) {
            return false;
        }
        let h = b.hausdorff_cmp(a);
        let no_worse = h != Ordering::Greater
            && b.chamfer_l1 <= a.chamfer_l1
            && b.fscore >= a.fscore
            && b.normal_consistency >= a.normal_consistency;
        let better = h == Ordering::Less
            || b.chamfer_l1 < a.chamfer_l1
            || b.fscore > a.fscore
            || b.normal_consistency > a.normal_consistency;
        no_worse && better
    }

    /// How this crust's Hausdorff distance compares with `other`'s. Equal in two cases:
    /// - both upper ends within the F-score's τ (0.3% of the diagonal; the larger of the
    ///   two τ, which are the same input's): both crusts then lie within the accuracy the
    ///   fit is measured at, everywhere and both ways, and the difference is not one a user
    ///   can see, while a better normal consistency is (libigl's 3holes: 0.166% against
    ///   0.187%, normal consistency 0.9899 against 0.9943; README, *Lined-up pairs*);
    /// - certified intervals that overlap: the certificate cannot tell them apart (where a
    ///   part of the input buried in its solid sets both at the same floor: trimesh's
    ///   rabbit.obj, 7.8536% of the diagonal for both, upper ends 7e-7 of the diagonal
    ///   apart with intervals under 1e-6 wide).
    ///
    /// Otherwise greater only when this interval lies wholly above the other's, less only
    /// when wholly below.
    pub fn hausdorff_cmp(&self, other: &PolishScores) -> Ordering {
        let tau = self.fscore_tau.max(other.fscore_tau);
        if self.hausdorff <= tau && other.hausdorff <= tau {
            Ordering::Equal
        } else if self.hausdorff_lo > other.hausdorff {
            Ordering::Greater
        } else if self.hausdorff < other.hausdorff_lo {
            Ordering::Less
        } else {
            Ordering::Equal
        }
    }
}

/// See [`PolishChoice::before_carving`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BeforeCarving {
    /// The plain polish's uncarved crust.
    pub plain: SurfaceBar,
    /// The aligned polish's.
    pub aligned: SurfaceBar,
}

/// The four metrics the choice compares (mesh units; F-score at 0.3% of the diagonal).
#[derive(Clone, Copy, Debug, Serialize)]
pub struct PolishScores {
    /// Certified Hausdorff distance, upper end of the interval.
    pub hausdorff: f64,
    /// Its lower end.
    pub hausdorff_lo: f64,
    /// Chamfer L1.
    pub chamfer_l1: f64,
    /// F-score.
    pub fscore: f64,
    /// Normal consistency.
    pub normal_consistency: f64,
    /// The F-score's distance τ (mesh units): Hausdorff distances both within it count as
    /// equal.
    pub fscore_tau: f64,
}

/// The 95% Wilson score interval of a proportion: `wrong` of `n` draws (z = 1.959964; no
/// continuity correction, as scipy's `binomtest(...).proportion_ci(method="wilson")`).
/// n = 0 gives [0, 1].
pub fn wilson_interval(wrong: usize, n: usize) -> [f64; 2] {
    if n == 0 {
        return [0.0, 1.0];
    }
    const Z: f64 = 1.959_963_984_540_054;
    let (k, n) = (wrong as f64, n as f64);
    let p = k / n;
    let z2 = Z * Z;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = Z / denom * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt();
    [(centre - half).max(0.0), (centre + half).min(1.0)]
}

#[cfg(test)]
mod tests {
    use super::{wilson_interval, PolishScores};

    #[test]
    fn the_aligned_crust_must_be_no_worse_on_all_four_and_better_on_one() {
        let a = PolishScores {
            hausdorff: 0.01,
            chamfer_l1: 1e-4,
            fscore: 0.999,
            normal_consistency: 0.99,
            fscore_tau: 0.003,
            hausdorff_lo: 0.01,
        };
        assert!(!a.no_worse_and_better_than(&a), "equal is not better");
        let better_nc = PolishScores { normal_consistency: 0.995, ..a };
        assert!(better_nc.no_worse_and_better_than(&a) && !a.no_worse_and_better_than(&better_nc));
        // Better normals do not buy a worse value of any other metric.
        for worse in [
            PolishScores { hausdorff: 0.0101, hausdorff_lo: 0.0101, ..better_nc },
            PolishScores { chamfer_l1: 1.01e-4, ..better_nc },
            PolishScores { fscore: 0.9989, ..better_nc },
        ] {
            assert!(!worse.no_worse_and_better_than(&a), "{worse:?}");
        }
        let all_better = PolishScores { hausdorff: 0.009, hausdorff_lo: 0.009, chamfer_l1: 0.9e-4, fscore: 1.0, ..a };
        let all_better = PolishScores { normal_consistency: 0.991, ..all_better };
        assert!(all_better.no_worse_and_better_than(&a));
        // A NaN never wins.
        assert!(!PolishScores { hausdorff: f64::NAN, ..all_better }.no_worse_and_better_than(&a));
        // Hausdorff distances both within τ count as equal: a larger one there does not
        // lose, and a smaller one does not win by itself; past τ, larger loses.
        let within = PolishScores { hausdorff: 0.002, hausdorff_lo: 0.002, ..a };
        let nearer = PolishScores { hausdorff: 0.001, hausdorff_lo: 0.001, ..within };
        assert!(PolishScores { normal_consistency: 0.995, ..within }.no_worse_and_better_than(&nearer));
        assert!(!nearer.no_worse_and_better_than(&within), "a Hausdorff distance within τ is no gain");
        let past = PolishScores { hausdorff: 0.0031, hausdorff_lo: 0.0031, normal_consistency: 0.995, ..within };
        assert!(!past.no_worse_and_better_than(&within), "past τ the larger distance loses");
        assert!(PolishScores { hausdorff: 0.003, ..past }.no_worse_and_better_than(&within), "τ itself is within");
        assert!(!PolishScores { fscore_tau: f64::NAN, ..past }.no_worse_and_better_than(&within));
        // Past τ, certified intervals that overlap count as equal; apart, the upper one loses
        // and the lower one wins.
        let floor = PolishScores { hausdorff: 0.0501, hausdorff_lo: 0.0500, ..a };
        let smoother = PolishScores { hausdorff: 0.05015, hausdorff_lo: 0.05005, normal_consistency: 0.995, ..a };
        assert_eq!(smoother.hausdorff_cmp(&floor), std::cmp::Ordering::Equal);
        assert!(smoother.no_worse_and_better_than(&floor), "overlapping intervals do not lose");
        assert!(!floor.no_worse_and_better_than(&smoother), "nor win");
        let above = PolishScores { hausdorff_lo: 0.05011, hausdorff: 0.0502, ..smoother };
        assert_eq!(above.hausdorff_cmp(&floor), std::cmp::Ordering::Greater);
        assert!(!above.no_worse_and_better_than(&floor));
        let below = PolishScores { hausdorff_lo: 0.0498, hausdorff: 0.04999, normal_consistency: 0.99, ..floor };
        assert_eq!(below.hausdorff_cmp(&floor), std::cmp::Ordering::Less);
        assert!(below.no_worse_and_better_than(&floor), "a certainly smaller distance alone wins");
        assert!(!PolishScores { hausdorff_lo: f64::NAN, ..smoother }.no_worse_and_better_than(&floor));
    }

    #[test]
    fn wilson_interval_known_values() {
        // 0 of 10: [0, z²/(n + z²)]; 10 of 10 mirrors it; 0 of 0 says nothing.
        let z2 = 1.959_963_984_540_054f64.powi(2);
        let [lo, hi] = wilson_interval(0, 10);
        assert_eq!(lo, 0.0);
        assert!((hi - z2 / (10.0 + z2)).abs() < 1e-15);
        let [lo2, hi2] = wilson_interval(10, 10);
        assert!((lo2 - (1.0 - hi)).abs() < 1e-15 && (hi2 - 1.0).abs() < 1e-15);
        assert_eq!(wilson_interval(0, 0), [0.0, 1.0]);
        // 4,000 of 1,000,000 (0.4%): about ±0.0124 points, around 0.4%.
        let [a, b] = wilson_interval(4_000, 1_000_000);
        assert!(a < 0.004 && b > 0.004 && (b - a - 2.0 * 1.2374e-4).abs() < 2e-6, "{a} {b}");
    }
}
