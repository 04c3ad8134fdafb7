//! The fit's report (`OUT.report.json`, `format_version` 1; fields are only ever added).

use std::cmp::Ordering;

use serde::Serialize;
use soft_voronoi::{StepStats, TrainConfig, TrainState};

pub use crate::target::SolidReport;

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
    pub carving: Option<crate::carve::CarveReport>,
    /// Outside mirror sites that cut inside cells at the input's bounding box (with
    /// carving; absent when off).
    pub guard: Option<crate::guard::GuardReport>,
    /// Sites removed last because they change neither the crust nor the occupancy (absent
    /// when off).
    pub pruning: Option<PruneReport>,
    /// The accuracy target's goal and error-against-K trace, when one was asked for.
    pub accuracy_target: Option<crate::grow::AccuracyReport>,
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
    /// Wall time of the second polish, its crust and both measurements, seconds.
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

impl PolishChoice {
    /// For the summary: which crust was kept and why.
    fn sentence(&self) -> String {
        if let Some(b) = &self.before_carving {
            return format!(
                " The polish with the pairs turned along the normals was tried too and stopped before carving \
                 (normal consistency {:.4} against {:.4}, Chamfer {:.3e} against {:.3e} in the unit cube).",
                b.aligned.normal_consistency, b.plain.normal_consistency, b.aligned.chamfer_l1, b.plain.chamfer_l1
            );
        }
        match (&self.plain, &self.aligned, &self.aligned_error) {
            (_, _, Some(_)) => " The polish with the pairs turned along the normals was tried too; its crust could \
                 not be written in the output's precision, so the plain one was kept (report: polish_choice)."
                .into(),
            (Some(a), Some(b), None) if self.aligned_kept => format!(
                " Both polishes were run, plain and with the pairs turned along the normals; the aligned one's \
                 crust was kept, at least as good on all four metrics (normal consistency {:.4} → {:.4}, \
                 Hausdorff distance {:.3}% → {:.3}% of the diagonal{}).",
                a.normal_consistency,
                b.normal_consistency,
                100.0 * a.hausdorff / self.diagonal,
                100.0 * b.hausdorff / self.diagonal,
                if b.hausdorff <= a.hausdorff {
                    String::new()
                } else if b.hausdorff <= b.fscore_tau.max(a.fscore_tau) {
                    format!(
                        ", both within the F-score's τ of {:.2}%, which counts as equal",
                        100.0 * b.fscore_tau / self.diagonal
                    )
                } else {
                    ", certified intervals that overlap, which counts as equal".to_string()
                }
            ),
            (Some(a), Some(b), None) => {
                let worse: Vec<String> = [
                    (b.hausdorff_cmp(a) == Ordering::Greater).then(|| {
                        format!(
                            "Hausdorff distance {:.3}% against {:.3}% of the diagonal",
                            100.0 * b.hausdorff / self.diagonal,
                            100.0 * a.hausdorff / self.diagonal
                        )
                    }),
                    (b.chamfer_l1 > a.chamfer_l1)
                        .then(|| format!("Chamfer {:.3e} against {:.3e}", b.chamfer_l1, a.chamfer_l1)),
                    (b.fscore < a.fscore).then(|| format!("F-score {:.4} against {:.4}", b.fscore, a.fscore)),
                    (b.normal_consistency < a.normal_consistency).then(|| {
                        format!("normal consistency {:.4} against {:.4}", b.normal_consistency, a.normal_consistency)
                    }),
                ]
                .into_iter()
                .flatten()
                .collect();
                format!(
                    " The polish with the pairs turned along the normals was tried too and not kept ({}).",
                    if worse.is_empty() { "no metric better".to_string() } else { worse.join(", ") }
                )
            }
            _ => " The polish with the pairs turned along the normals was tried too; its metrics could not be \
                  compared, so the plain one was kept."
                .into(),
        }
    }
}

/// See [`PolishChoice::before_carving`].
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BeforeCarving {
    /// The plain polish's uncarved crust.
    pub plain: crate::carve::SurfaceBar,
    /// The aligned polish's.
    pub aligned: crate::carve::SurfaceBar,
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

/// Farthest crust point from the input, as a share of its diagonal, from which the summary
/// of a winding solid with caps suggests `--solid shell`. Whether a cap is wanted is the
/// user's call, not a threshold's: a cap over a wide opening lies far from the input by
/// nature. Measured at K = 8,192: an open pipe (radius 1, length 2) fitted as a volume has
/// its caps 29% of the diagonal from it, two crossing squares 16%; of libigl's tutorial
/// meshes, lion 15.6%, face (a mask) 15.0%, halftunnel 12.8% and camelhead 12.2% get the
/// hint, intersection_quads (4.9%) does not, nor do the benchmark's teapots and scanned
/// bunny, whose holes are small. The benchmark's soup (10.0%) gets it too, and is not a
/// single surface: as a shell it measures worse (Hausdorff 17.3% against 10.0%), hence the
/// hint's "if".
pub const SHELL_HINT_ABOVE: f64 = 0.1;

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
        let inserted: usize = self.carving.as_ref().map_or(0, |r| r.inserted_per_round.iter().sum());
        let carved = match &self.carving {
            Some(r) if inserted > 0 => {
                let pct = |d: f64| 100.0 * d * r.tolerance_of_diagonal / r.tolerance;
                let missed = |i: usize| pct(r.input_farthest_per_round.get(i).copied().unwrap_or(0.0));
                let at_input: usize = r.inserted_at_input_per_round.iter().sum();
                let mirrors: usize = r.inserted_as_mirrors_per_round.iter().sum();
                format!(
                    " Then {inserted} sites ({at_input} at input points far from the crust, {mirrors} mirror images \
                     across faces near them) were inserted in {} \
                     round(s) where the crust and the input lay more than {:.2}% of the diagonal apart (farthest \
                     crust vertex {:.3}% → {:.3}%; input point farthest from the crust {:.3}% → {:.3}%){}.",
                    r.inserted_per_round.len(),
                    100.0 * r.tolerance_of_diagonal,
                    pct(r.farthest_before),
                    pct(r.farthest_after),
                    missed(0),
                    missed(r.inserted_per_round.len()),
                    if r.mirrors_dropped.is_some() {
                        "; carving ran a second time without mirror images, as the crust with them could not be \
                         written in the output's precision (report: carving.mirrors_dropped)"
                    } else {
                        ""
                    }
                )
            }
            _ => String::new(),
        };
        let guarded = match &self.guard {
            Some(g) if g.inserted() > 0 => {
                // Unit-cube lengths to shares of the diagonal, by the carving's ratio.
                let of_diag = self
                    .carving
                    .as_ref()
                    .filter(|r| r.tolerance > 0.0)
                    .map_or(f64::NAN, |r| r.tolerance_of_diagonal / r.tolerance);
                format!(
                    " {} outside sites were added as mirror images of inside sites across the input's bounding box, \
                     where their cells ran past it (the crust reached {:.3}% of the diagonal beyond the box, now \
                     {:.3}%{}).",
                    g.inserted(),
                    100.0 * g.beyond_before * of_diag,
                    100.0 * g.beyond_after * of_diag,
                    if g.skipped_outside_cube > 0 {
                        format!("; {} mirrors would have left the unit cube and were not added", g.skipped_outside_cube)
                    } else {
                        String::new()
                    }
                )
            }
            _ => String::new(),
        };
        let carved = format!("{carved}{guarded}");
        let polished = match &self.polish {
            Some(p) => format!(
                " The sites were then polished onto the surface samples ({} steps of VoroMesh's bisector loss{}, \
                 {:.3e} → {:.3e}; sites moved {:.2e} rms).{}",
                p.steps,
                if p.aligned { " with the pairs turned along the surface normals over the first half" } else { "" },
                p.loss_first,
                p.loss_last,
                p.move_rms,
                self.polish_choice.as_ref().map_or(String::new(), PolishChoice::sentence)
            ),
            None => String::new(),
        };
        let shell = match (self.solid.half_thickness, self.solid.half_thickness_of_diagonal) {
            (Some(h), Some(f)) => {
                let search = match &self.solid.thickness_search {
                    Some(trials) => {
                        let kept = trials.iter().find(|t| t.kept).map_or(1.0, |t| t.factor);
                        let broken = trials.iter().filter(|t| t.factor < kept).count();
                        if kept < 1.0 {
                            let thinner = match broken {
                                0 => String::new(),
                                n => format!("; the {n} thinner one(s) tried did not"),
                            };
                            format!(
                                " That is the thinnest band tried whose crust keeps the default band's topology and \
                                 Hausdorff distance ({kept} of the default √(A/K){thinner})."
                            )
                        } else {
                            format!(
                                " No thinner band kept the default's topology and Hausdorff distance ({} tried), so \
                                 the default √(A/K) stays.",
                                trials.len() - 1
                            )
                        }
                    }
                    None => String::new(),
                };
                format!(
                    " The mesh is an open sheet ({:.0}% of near-surface samples have a winding number between 0.25 \
                     and 0.75 in magnitude), so the sites fit a thin shell: the surface thickened by {:.4e} on each side ({:.2}% of the diagonal); the \
                     crust is that shell's boundary.{search}",
                    100.0 * self.solid.near_surface_ambiguous_share,
                    h,
                    100.0 * f
                )
            }
            _ => String::new(),
        };
        let r = &self.input.reoriented;
        let reoriented = if r.flipped_triangles > 0 {
            format!(
                " {} of the input's triangles (in {} piece(s)) were turned around to agree with their neighbours \
                 before the solid was built: flipped against the rest of their body, they turn part of it inside out \
                 for the winding number.",
                r.flipped_triangles, r.pieces_changed
            )
        } else {
            String::new()
        };
        let interior = match (self.solid.interior_surface_share, self.solid.interior_surface_samples_dropped) {
            (Some(share), dropped) if dropped > 0 => format!(
                " {:.1}% of the input's surface is not on the solid's boundary (the same side of the solid on \
                 both sides: faces inside it where bodies overlap, doubled faces); its {dropped} surface samples were \
                 left out of the initialisation, the surface term and the polish.",
                100.0 * share
            ),
            _ => String::new(),
        };
        let interior = format!("{reoriented}{interior}");
        let interior = if self.solid.cap_samples > 0 {
            // Caps that leave the crust far from the input: the mesh may be a surface (a pipe,
            // crossing panels) rather than a volume's skin with holes. Say what to try.
            let far = match &self.metrics {
                MetricsReport::Done(m) if m.reference_diagonal > 0.0 => {
                    let share = m.hausdorff.directed_witness[1] / m.reference_diagonal;
                    if share >= SHELL_HINT_ABOVE {
                        format!(
                            " Part of the crust (those caps) lies {:.1}% of the diagonal from the input: if the mesh is \
                             one surface (a pipe, a mask, crossing panels) rather than the skin of a volume with holes, \
                             --solid shell fits a thin shell around it instead.",
                            100.0 * share
                        )
                    } else {
                        String::new()
                    }
                }
                _ => String::new(),
            };
            format!(
                "{interior} The solid closes the input's holes by the |winding number| = 0.5 surface; {} points of \
                 it beyond the input's edges were added to the surface samples (caps and their rims), so sites \
                 stand there too.{far}",
                self.solid.cap_samples
            )
        } else {
            interior
        };
        let pruned = match &self.pruning {
            Some(p) if p.sites_after < p.sites_before => format!(
                " Last, {} sites whose Delaunay neighbours all carry their label were removed (they change neither \
                 the crust nor the occupancy): the sites file holds {} sites.",
                p.sites_before - p.sites_after,
                p.sites_after
            ),
            _ => String::new(),
        };
        let target = match &self.accuracy_target {
            Some(a) => {
                let steps: Vec<String> = a
                    .trace
                    .iter()
                    .map(|r| format!("{} sites: {:.3}%", r.sites, 100.0 * r.hausdorff_hi_of_diagonal))
                    .collect();
                format!(
                    " Accuracy target: Hausdorff ≤ {:.3}% of the diagonal {} {} sites (budget {}; {}).",
                    100.0 * a.goal_hausdorff_of_diagonal,
                    if a.met { "met with" } else { "NOT met; the fit written is the closest one, with" },
                    a.sites_used,
                    a.max_sites,
                    steps.join(", ")
                )
            }
            None => String::new(),
        };
        format!(
            "{}: fitted {} sites ({} more fixed on the boundary) in {} steps{}; on {} fresh samples {:.3}% are \
             misclassified (95% interval {:.3}–{:.3}%; {:.3}% of uniform, {:.3}% of near-surface ones).{}{}{}{} Crust of \
             {} sites ({} inside): {} triangles, {} component(s), \
             genus {}, closed, manifold and free of self-intersections (checked), volume {:.6e}.{}{} {}{}",
            self.input.path,
            t.num_sites,
            self.settings.train.num_boundary(),
            t.steps,
            match &self.losses.selected {
                Some(b) if b.step < t.steps =>
                    format!(" (the best iterate by the evaluation batch's loss is kept: step {})", b.step),
                _ => String::new(),
            },
            self.settings.eval_samples,
            100.0 * q.misclassification,
            100.0 * q.misclassification_ci95[0][0],
            100.0 * q.misclassification_ci95[0][1],
            100.0 * q.misclassification_uniform,
            100.0 * q.misclassification_near_surface,
            interior,
            polished,
            carved,
            pruned,
            c.num_sites,
            c.num_inside,
            c.num_triangles,
            c.num_components,
            c.genus.map_or("n/a".to_string(), |g| g.to_string()),
            c.volume,
            crust::output::topology_note(c.topology_before_rounding).map_or(String::new(), |n| format!(" {n}")),
            shell,
            metrics,
            target
        )
    }
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
