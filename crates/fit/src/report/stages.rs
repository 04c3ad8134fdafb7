//! The stages' parts of the report: the solid chosen, the guard, carving and the accuracy
//! target's rounds. Each stage module re-exports its own.

use serde::Serialize;

use crate::config::SolidRule;

/// Which solid was fitted and why (report field `solid`).
#[derive(Clone, Debug, Serialize)]
pub struct SolidReport {
    /// `winding`, `shell` or `flood`.
    pub rule: SolidRule,
    /// `auto` (chosen from the share below) or `--solid` (asked for).
    pub chosen_by: &'static str,
    /// Share of the near-surface training samples inside the winding-number solid.
    pub near_surface_inside_share: f64,
    /// Share of near-surface samples with 0.25 < |w| < 0.75 (auto takes the shell for an
    /// open mesh at [`crate::config::SHELL_ABOVE`] or more).
    pub near_surface_ambiguous_share: f64,
    /// Half the shell's thickness in input units (shell only).
    pub half_thickness: Option<f64>,
    /// The same as a fraction of the input's bounding-box diagonal.
    pub half_thickness_of_diagonal: Option<f64>,
    /// How the shell's sites start (shell only; see `target::shell_sites`).
    pub init: Option<String>,
    /// Share of the input's surface that is not on the solid's boundary: area-uniform
    /// surface samples with the same label a hair's breadth (1e-5 of the diagonal) to
    /// either side, such as faces inside the solid where closed bodies overlap, doubled
    /// faces, or parts of a soup the solid encloses (winding solid only; estimated on the
    /// first 20,000 samples when too small to act on).
    pub interior_surface_share: Option<f64>,
    /// How many of the training surface samples were left out for it (they would pull
    /// faces of the diagram where the crust has none): the initialisation, the surface
    /// term and the polish use the rest. 0 when the share is below 5%.
    pub interior_surface_samples_dropped: usize,
    /// Points of the winding solid's boundary away from the input (caps across the holes
    /// of an open mesh: the |w| = 0.5 level set, found from the uniform pool, see
    /// `target::cap_samples`, and the rings where they meet the input's open edges, see
    /// `target::rim_samples`) added to the surface samples, as dense as the input's, so that the
    /// initialisation puts site pairs and the polish pulls bisectors there too (winding
    /// solid of an open mesh only).
    pub cap_samples: usize,
    /// The caps' estimated area as a share of the input's (winding solid of an open mesh,
    /// and the shell auto took instead of it; `target::cap_points`): at
    /// [`crate::config::CAPS_SHELL_ABOVE`] or more, `--solid auto` takes the thin shell.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cap_area_share: Option<f64>,
    /// The thinner bands tried before settling on the shell's half-thickness (shell with
    /// the default thickness and sites kept as constructed only; see `target::thinnest_band`).
    pub thickness_search: Option<Vec<BandTrial>>,
    /// The flood fill and what it made of the surface (flood solid, and the auto rule's
    /// look at it on an open mesh).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flood: Option<FloodReport>,
    /// Whether a band's two sides (the shell's, the flood solid's sheets') lie within the
    /// F-score's τ of the sheet, and if not, about how many sites would put them there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sheet_band: Option<SheetBand>,
    /// The open input's holes closed flat before the solid was built
    /// ([`mesh_io::fill_planar_holes`]; areas in input units squared): winding solid of an
    /// open input only, absent otherwise. The filled mesh is the solid's surface: the
    /// winding numbers, the surface samples and the caps (over the holes left open) are
    /// those of the input with its fills; the metrics stay against the input as given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes_filled: Option<mesh_io::HoleFilling>,
}

/// A sheet's band against the F-score's τ (report field `solid.sheet_band`): the band's
/// sides stand its half-thickness h off the sheet, so both lie within τ when h ≤ τ. h
/// scales as √(A/K) (`config::shell_half_thickness`), so about K·(h/τ)² sites bring it
/// there.
#[derive(Clone, Debug, Serialize)]
pub struct SheetBand {
    /// The band's half-thickness as a share of the diagonal.
    pub half_thickness_of_diagonal: f64,
    /// The F-score's τ as a share of the diagonal.
    pub tau_of_diagonal: f64,
    /// Whether both sides lie within τ of the sheet.
    pub within_tau: bool,
    /// About how many sites would bring them within τ (when they are not).
    pub sites_for_tau: Option<usize>,
}

impl SheetBand {
    /// The band of half-thickness `h_of_diagonal` fitted with `num_sites` sites.
    pub fn of(h_of_diagonal: f64, num_sites: usize) -> Self {
        let tau = SHEET_TAU;
        let within = h_of_diagonal <= tau;
        let sites = (num_sites as f64 * (h_of_diagonal / tau).powi(2)).ceil() as usize;
        SheetBand {
            half_thickness_of_diagonal: h_of_diagonal,
            tau_of_diagonal: tau,
            within_tau: within,
            sites_for_tau: (!within).then_some(sites),
        }
    }
}

/// The F-score's τ as a share of the diagonal (`metrics::SurfaceOptions`' default).
pub const SHEET_TAU: f64 = 0.003;

/// The flood solid's grid and which rule made which part of the surface (report field
/// `solid.flood`). Shares are of the area-uniform surface samples.
#[derive(Clone, Debug, Default, Serialize)]
pub struct FloodReport {
    /// Cells along each axis.
    pub cells: [usize; 3],
    /// Side of a cell, input units.
    pub cell: f64,
    /// The same as a share of the input's bounding-box diagonal.
    pub cell_of_diagonal: f64,
    /// Share of the uniform samples inside the flood solid without the sheets' bands.
    pub enclosed_share: f64,
    /// Share of the uniform samples inside the winding-number solid.
    pub winding_share: f64,
    /// Share of the near-surface samples the two solids label differently (the auto rule's
    /// second test, `config::FLOOD_DISAGREEMENT`).
    pub disagreement: f64,
    /// Surface with the flood's enclosed side on one side and outside on the other: the
    /// solid's boundary, where the input is (with `interior_share`, the auto rule's first
    /// test, `config::FLOOD_BOUNDARY_SHARE`).
    pub boundary_share: f64,
    /// Surface enclosed on both sides (doubled, buried or touching faces): left out (counted
    /// with `boundary_share` in the auto rule's first test, `config::FLOOD_ENCLOSED_SHARE`).
    pub interior_share: f64,
    /// Surface with the outside on both sides (single-sided panels, sheets, the walls of
    /// boxes open wider than the grid closes): thickened into bands.
    pub sheet_share: f64,
    /// Surface with walls too close to step out of on both sides (inside rods and crevices
    /// narrower than the grid resolves): enclosed, left out.
    pub crevice_share: f64,
    /// Half the sheets' band, input units.
    pub sheet_half_thickness: f64,
    /// The same as a share of the diagonal.
    pub sheet_half_thickness_of_diagonal: f64,
}

/// One band tried by `target::thinnest_band`: its half-thickness, the crust's topology and its
/// certified Hausdorff distance to the input, and whether it was taken.
#[derive(Clone, Debug, Serialize)]
pub struct BandTrial {
    /// Half-thickness as a share of the default (√(A/K)).
    pub factor: f64,
    /// Half-thickness as a fraction of the input's bounding-box diagonal.
    pub half_thickness_of_diagonal: f64,
    /// Connected components of the crust of the sites as constructed.
    pub components: usize,
    /// Its genus (summed over components; the crust is closed and manifold, so known).
    pub genus: Option<i64>,
    /// Upper end of its certified Hausdorff interval to the input, a fraction of the
    /// diagonal; `None` (null) for a thinner band whose components or genus already
    /// differ from the default's (its distance does not change the choice, and is not
    /// measured).
    pub hausdorff_of_diagonal: Option<f64>,
    /// Whether this band was kept (the default's own row is kept when no thinner one
    /// passed).
    pub kept: bool,
    /// Why this band's crust could not be made or measured (then it is not kept).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// `solid.chosen_by` of a thin shell fitted because the winding-number solid left no site
/// inside (`fit::fit`'s fallback under `--solid auto`).
pub const CHOSEN_AFTER_EMPTY_WINDING: &str = "auto: the winding-number solid left no site inside";

/// [`SolidReport::chosen_by`] when `--solid auto` took the shell because the winding solid's
/// caps would be [`crate::config::CAPS_SHELL_ABOVE`] of the input's area or more.
pub const CHOSEN_FOR_LARGE_CAPS: &str = "auto: the winding-number solid's caps would be a large part of it";

/// What `carve::carve` did (report field `carving`).
#[derive(Clone, Debug, Default, Serialize)]
pub struct CarveReport {
    /// The tolerance, unit-cube lengths (and as a share of the diagonal).
    pub tolerance: f64,
    /// The same as a share of the input's bounding-box diagonal.
    pub tolerance_of_diagonal: f64,
    /// Sites inserted, per round.
    pub inserted_per_round: Vec<usize>,
    /// Of those, the sites of pairs at input samples far from the crust (the rest are at
    /// the feet of crust vertices far from the input), per round.
    pub inserted_at_input_per_round: Vec<usize>,
    /// Of those, the mirror images of inserted sites across input faces near them
    /// (`carve::mirror_closure`), per round.
    pub inserted_as_mirrors_per_round: Vec<usize>,
    /// Of those, the sites at crust vertices far from the input (`carve::peel_sites`), per
    /// round.
    pub inserted_as_peels_per_round: Vec<usize>,
    /// Why carving was run again without the mirrors, if it was: the crust with them could
    /// not be written in the output's precision (the main job then carves again from the
    /// same sites without them).
    pub mirrors_dropped: Option<String>,
    /// Farthest crust vertex from the input before and after, unit-cube lengths.
    pub farthest_before: f64,
    /// After the last kept round.
    pub farthest_after: f64,
    /// The farthest crust vertex after each extraction: before any insertion, then after
    /// each round run (kept or undone).
    pub farthest_per_round: Vec<f64>,
    /// The input's farthest point from the crust after each extraction (the other side of
    /// the Hausdorff distance: dents; certified to 0.01% of the diagonal, upper end; where
    /// part of the input is buried inside its solid, the largest over 100,000 samples of
    /// the rest).
    pub input_farthest_per_round: Vec<f64>,
    /// The crust's F-score against the input at the tolerance after each extraction (from
    /// samples; a state more than `carve::f_slack` below the first is not kept: 0.002, or a
    /// twentieth of what the first lacks of 1 where that is more).
    pub fscore_per_round: Vec<f64>,
    /// Rounds run but undone: the best state (see `best_state`: least two-sided farthest
    /// distance, then least farthest vertex, then least summed excess of the stray
    /// vertices) came before them.
    pub undone_rounds: usize,
    /// Why the last round's insertions were taken back before they were measured, if they
    /// were: the crust of the sites with them could not be extracted (sites so nearly
    /// degenerate that rounding the Voronoi vertices breaks the crust). Carving then stops
    /// at the state before that round, which was extracted and checked.
    pub round_not_extracted: Option<String>,
    /// The uncarved crust's Chamfer L1 distance and normal consistency against the input
    /// (from the samples of the F-score; unit-cube lengths).
    pub first_surface: SurfaceBar,
    /// Whether carving stopped before its first round because the uncarved crust did not
    /// reach its gate (`carve::CarveOptions::gate`, or `carve::Start::first_surface`'s bar:
    /// the plain crust's figures, for the aligned attempt beside it).
    pub gated: bool,
}

/// Chamfer L1 distance (unit-cube lengths) and normal consistency of a crust against the
/// input, from the samples of carving's F-score.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SurfaceBar {
    /// Chamfer L1.
    pub chamfer_l1: f64,
    /// Normal consistency.
    pub normal_consistency: f64,
}

/// What `guard::guard` did (report field `guard`).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct GuardReport {
    /// The input's bounding box in unit-cube coordinates (the planes mirrored across).
    pub box_lo: [f64; 3],
    /// Upper corner of the box.
    pub box_hi: [f64; 3],
    /// Crust vertices farther than this beyond the box trigger mirrors (the carving
    /// tolerance), unit-cube lengths.
    pub threshold: f64,
    /// Mirror sites added, per round (before carving).
    pub inserted_per_round: Vec<usize>,
    /// Mirror sites added per round when the guard ran again after carving's kept rounds
    /// (empty when carving kept none).
    pub inserted_after_carving: Vec<usize>,
    /// Mirrors that would have left the unit cube (not added).
    pub skipped_outside_cube: usize,
    /// How far the crust reached beyond the box before and after, unit-cube lengths.
    pub beyond_before: f64,
    /// After the last round.
    pub beyond_after: f64,
    /// Flood solid and thin shell kept as constructed only: outside sites added per round
    /// by `guard::guard_solid`, mirrors of inside sites across the solid's tangent planes
    /// where the crust stood outside it farther than `threshold` (empty for the winding
    /// solid). On the shell, which has no box guard, the box fields are the box's and
    /// nothing was added across it.
    pub solid_mirrors_per_round: Vec<usize>,
    /// How far the crust stood outside the solid before and after those rounds, unit-cube
    /// lengths (0 when they did not run).
    pub solid_beyond_before: f64,
    /// After the last round.
    pub solid_beyond_after: f64,
    /// Why the solid's mirrors were taken back (the crust with them could not be written
    /// at the output's precision), or `None`.
    pub solid_mirrors_dropped: Option<String>,
}

impl GuardReport {
    /// Takes in the report of the guard's second pass, after carving.
    pub fn after_carving(&mut self, again: GuardReport) {
        self.inserted_after_carving = again.inserted_per_round;
        self.skipped_outside_cube += again.skipped_outside_cube;
        self.beyond_after = again.beyond_after;
    }

    /// Mirror sites added in both passes.
    pub fn inserted(&self) -> usize {
        self.inserted_per_round.iter().chain(&self.inserted_after_carving).sum()
    }
}

/// One round of the growth.
#[derive(Clone, Debug, Serialize)]
pub struct GrowthRow {
    /// Trainable sites.
    pub sites: usize,
    /// Certified Hausdorff interval to the input, fractions of the diagonal.
    pub hausdorff_lo_of_diagonal: f64,
    /// Upper end (the figure compared with the goal).
    pub hausdorff_hi_of_diagonal: f64,
    /// Misclassification on the fresh pool.
    pub misclassification: f64,
    /// Share of the pairs' candidate surface points refined (0 in the first round).
    pub refined_share: f64,
    /// Wall time of the round, seconds.
    pub seconds: f64,
    /// The crust's genus (when closed and manifold).
    pub genus: Option<i64>,
    /// Handles of the input the crust closed, where the report compares them (field
    /// `topology`).
    pub handles_closed: Option<i64>,
}

/// Report field `accuracy_target`.
#[derive(Clone, Debug, Serialize)]
pub struct AccuracyReport {
    /// The goal, fraction of the diagonal (`null`: none, the topology alone was asked for).
    pub goal_hausdorff_of_diagonal: Option<f64>,
    /// Whether the input's genus and components were asked for too (`--keep-topology`).
    pub keep_topology: bool,
    /// The budget of sites.
    pub max_sites: usize,
    /// Whether the last round met the goal.
    pub met: bool,
    /// Sites of the returned fit: the round that met the goal, or when none did, the one
    /// with the least Hausdorff distance (with `keep_topology`: of those whose topology is
    /// closest to the input's).
    pub sites_used: usize,
    /// Error against K, one row per round.
    pub trace: Vec<GrowthRow>,
}
