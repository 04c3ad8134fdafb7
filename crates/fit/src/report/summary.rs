//! The report as text: [`FitReport::summary`], a few lines for the terminal after a fit,
//! and [`FitReport::details`], the whole story of the fit in one paragraph (the CLI's
//! `--verbose`).

use std::cmp::Ordering;

use super::{FitReport, MetricsReport, PolishChoice};
use crate::config::SolidRule;

/// Farthest crust point from the input, as a share of its diagonal, from which the details
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

/// Most lines of [`FitReport::summary`].
pub const SUMMARY_LINES: usize = 5;

impl FitReport {
    /// At most [`SUMMARY_LINES`] short lines for people: what was fitted (mesh, K, steps),
    /// the solid rule, quality in four numbers against the input (certified Hausdorff
    /// distance as a share of the diagonal, Chamfer L1, F-score, normal consistency), the
    /// crust's validity, and the files and the time. The rest is in [`FitReport::details`]
    /// and the JSON report.
    pub fn summary(&self) -> String {
        [self.fitted_line(), self.solid_line(), self.quality_line(), self.validity_line(), self.time_line()].join("\n")
    }

    /// The summary's first four lines (what was fitted, the solid, quality, validity), for
    /// a writer that prints its own line of files and time.
    pub fn summary_lines(&self) -> impl Iterator<Item = String> {
        [self.fitted_line(), self.solid_line(), self.quality_line(), self.validity_line()].into_iter()
    }

    /// Everything the summary leaves out, in one paragraph: the misclassification, the
    /// interior surface, caps, the polish and its choice, carving, the guard, pruning, the
    /// shell's thickness search, every metric against the input and the accuracy target.
    pub fn details(&self) -> String {
        let t = &self.settings.train;
        let c = &self.crust;
        let q = &self.quality;
        let interior = format!(
            "{}{}{}{}",
            self.reoriented_sentence(),
            self.holes_sentence(),
            self.interior_sentence(),
            self.caps_sentence()
        );
        let polished = self.polish_sentence();
        let carved = format!("{}{}", self.carving_sentence(), self.guard_sentence());
        let pruned = self.pruning_sentence();
        let shell = format!("{}{}{}", self.shell_sentence(), self.flood_sentence(), self.sheet_band_sentence());
        let metrics = self.metrics_sentence();
        let target = self.accuracy_sentence();
        format!(
            "{}: fitted {} sites ({} more fixed on the boundary) in {} steps{}; on {} fresh samples {:.3}% are \
             misclassified (95% interval {:.3}–{:.3}%; {:.3}% of uniform, {:.3}% of near-surface ones).{}{}{}{} Crust of \
             {} sites ({} inside): {} triangles, {} component(s), \
             genus {}, closed, manifold and free of self-intersections (checked), volume {:.6e}.{}{}{} {}{}",
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
            self.topology.as_ref().filter(|t| !t.kept()).map_or(String::new(), |t| t.difference()),
            shell,
            metrics,
            target
        )
    }

    /// Line 1: the mesh, K and the steps.
    fn fitted_line(&self) -> String {
        let t = &self.settings.train;
        let p = &self.pruning;
        let kept = match p {
            Some(p) if p.sites_after < p.sites_before => format!(" ({} in the sites file)", p.sites_after),
            _ => String::new(),
        };
        format!("{}: {} sites{kept}, {} steps, preset {}", self.input.path, t.num_sites, t.steps, self.settings.preset)
    }

    /// The sites a sheet's band would need to lie within the F-score's τ, when it does not
    /// (a sentence of `details()`).
    fn sheet_band_sentence(&self) -> String {
        match &self.solid.sheet_band {
            Some(b) if !b.within_tau => format!(
                " The band's sides stand {:.2}% of the diagonal off the sheet, beyond the F-score's τ = {:.1}%; its \
                 half-thickness scales as 1/√K, so about {} sites would bring them within τ.",
                100.0 * b.half_thickness_of_diagonal,
                100.0 * b.tau_of_diagonal,
                vf_common::text::group(b.sites_for_tau.unwrap_or(0))
            ),
            _ => String::new(),
        }
    }

    /// Line 2: the solid the sites fit.
    fn solid_line(&self) -> String {
        let s = &self.solid;
        let by = match s.chosen_by {
            "auto" => "chosen automatically",
            super::CHOSEN_AFTER_EMPTY_WINDING => "chosen automatically: the winding solid left no site inside",
            super::CHOSEN_FOR_LARGE_CAPS => "",
            _ => "asked for",
        };
        let by = if s.chosen_by == super::CHOSEN_FOR_LARGE_CAPS {
            format!(
                "chosen automatically: the holes' |w| = 0.5 caps would add {:.0}% to its area, so it is taken as a \
                 thin-walled part",
                100.0 * s.cap_area_share.unwrap_or(f64::NAN)
            )
        } else {
            by.to_owned()
        };
        if let (SolidRule::Flood, Some(f)) = (s.rule, &s.flood) {
            return format!(
                "Solid: flood fill, {by}: {:.0}% closed parts, {:.0}% sheets ±{:.2}%, {:.0}% inner faces dropped",
                100.0 * f.boundary_share,
                100.0 * f.sheet_share,
                100.0 * f.sheet_half_thickness_of_diagonal,
                100.0 * (f.interior_share + f.crevice_share)
            );
        }
        let flat = match &s.holes_filled {
            Some(h) if h.loops_filled > 0 => {
                format!(", {} planar hole{} closed flat", h.loops_filled, if h.loops_filled == 1 { "" } else { "s" })
            }
            _ => String::new(),
        };
        match s.half_thickness_of_diagonal {
            Some(f) => format!("Solid: a thin shell around the surface, ±{:.3}% of the diagonal ({by})", 100.0 * f),
            None if s.cap_samples > 0 => {
                let other = if flat.is_empty() { "" } else { "other " };
                format!("Solid: the winding-number volume |w| ≥ 0.5{flat}, {other}holes capped ({by})")
            }
            None => {
                // Where the crust's topology differs from the input's, the crust line's genus
                // is read against this one (the details say how).
                let genus = match self.topology.as_ref().filter(|t| !t.kept()) {
                    Some(t) if t.input_genus != t.crust_genus => format!("; input genus {}", t.input_genus),
                    Some(t) => format!("; input: {} component(s)", t.input_components),
                    None => String::new(),
                };
                format!("Solid: the winding-number volume |w| ≥ 0.5{flat} ({by}){genus}")
            }
        }
    }

    /// Line 3: the four numbers against the input.
    fn quality_line(&self) -> String {
        match &self.metrics {
            MetricsReport::Done(m) => {
                let d = if m.reference_diagonal > 0.0 { m.reference_diagonal } else { f64::NAN };
                format!(
                    "Quality: Hausdorff ≤ {:.3}% of diagonal, Chamfer {:.3}%, F-score {:.4}, normal consistency {:.4}",
                    100.0 * m.hausdorff.hi / d,
                    100.0 * m.surface.chamfer_l1 / d,
                    m.surface.fscore,
                    m.surface.normal_consistency
                )
            }
            MetricsReport::Failed { .. } => format!(
                "Quality: misclassified {:.3}%; the metrics against the input failed (--verbose)",
                100.0 * self.quality.misclassification
            ),
            MetricsReport::Skipped { .. } => format!(
                "Quality: misclassified {:.3}% (no metrics against the input)",
                100.0 * self.quality.misclassification
            ),
        }
    }

    /// Line 4: the crust's validity and size.
    fn validity_line(&self) -> String {
        let c = &self.crust;
        let genus = c.genus.map_or("n/a".to_string(), |g| g.to_string());
        let yes = |b: bool, what: &str| if b { what.to_string() } else { format!("NOT {what}") };
        format!(
            "Crust: {} triangles, {} component(s), genus {genus}; {}, {}, no self-intersections",
            c.num_triangles,
            c.num_components,
            yes(c.is_closed, "closed"),
            yes(c.is_manifold, "manifold")
        )
    }

    /// Line 5: the files (when the writer named them) and the time.
    fn time_line(&self) -> String {
        let o = &self.outputs;
        if o.crust.is_empty() {
            format!("Time: {:.1} s", self.total_seconds)
        } else {
            format!("Wrote {} and {} in {:.1} s", o.crust, o.sites, self.total_seconds)
        }
    }

    /// The metrics against the input, or why there are none.
    fn metrics_sentence(&self) -> String {
        match &self.metrics {
            MetricsReport::Done(m) => format!(
                "Against the input: Hausdorff in [{:.4e}, {:.4e}] (certified; libigl's vertex-only value {:.4e}), \
                 Chamfer L1 {:.4e}, F-score {:.4}, IoU {}{}.",
                m.hausdorff.lo,
                m.hausdorff.hi,
                m.hausdorff_libigl,
                m.surface.chamfer_l1,
                m.surface.fscore,
                m.iou.as_ref().and_then(|i| i.iou).map_or("n/a".to_string(), |v| format!("{v:.5}")),
                self.iou_reference.as_ref().map_or(String::new(), |r| format!(" against {r}"))
            ),
            MetricsReport::Failed { error } => format!("Metrics against the input failed: {error}."),
            MetricsReport::Skipped { .. } => String::new(),
        }
    }

    /// What carving inserted, when it inserted anything.
    fn carving_sentence(&self) -> String {
        let inserted: usize = self.carving.as_ref().map_or(0, |r| r.inserted_per_round.iter().sum());
        match &self.carving {
            Some(r) if inserted > 0 => {
                let pct = |d: f64| 100.0 * d * r.tolerance_of_diagonal / r.tolerance;
                let missed = |i: usize| pct(r.input_farthest_per_round.get(i).copied().unwrap_or(0.0));
                let at_input: usize = r.inserted_at_input_per_round.iter().sum();
                let mirrors: usize = r.inserted_as_mirrors_per_round.iter().sum();
                let peels: usize = r.inserted_as_peels_per_round.iter().sum();
                format!(
                    " Then {inserted} sites ({at_input} at input points far from the crust, {mirrors} mirror images \
                     across faces near them, {peels} at crust vertices far from the input) were inserted in {} \
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
                ) + &taken_back(r)
            }
            Some(r) => taken_back(r),
            _ => String::new(),
        }
    }

    /// What the bounding-box guard and the solid guard added, when they added anything.
    fn guard_sentence(&self) -> String {
        // Unit-cube lengths to shares of the diagonal, by the carving's ratio (or, on a thin
        // shell kept as constructed, which is not carved, by its band's).
        let by_band = match (self.solid.half_thickness, self.solid.half_thickness_of_diagonal) {
            (Some(h), Some(f)) if h > 0.0 && self.transform.scale > 0.0 => f / (h * self.transform.scale),
            _ => f64::NAN,
        };
        let of_diag = self
            .carving
            .as_ref()
            .filter(|r| r.tolerance > 0.0)
            .map_or(by_band, |r| r.tolerance_of_diagonal / r.tolerance);
        let solid = match &self.guard {
            Some(g) if g.solid_mirrors_dropped.is_some() => {
                " The solid guard's mirrors were taken back: the crust with them did not survive rounding to the \
                 output's precision."
                    .to_string()
            }
            Some(g) if g.solid_mirrors_per_round.iter().sum::<usize>() > 0 => {
                format!(
                    " {} outside sites were added as mirror images of inside sites across the solid's tangent planes, \
                     where their cells ran out of the solid (the crust stood {:.3}% of the diagonal outside it, then \
                     {:.3}%).",
                    g.solid_mirrors_per_round.iter().sum::<usize>(),
                    100.0 * g.solid_beyond_before * of_diag,
                    100.0 * g.solid_beyond_after * of_diag,
                )
            }
            _ => String::new(),
        };
        let boxed = match &self.guard {
            Some(g) if g.inserted() > 0 => {
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
        format!("{solid}{boxed}")
    }

    /// The polish and, on a closed input, the choice of the aligned one.
    fn polish_sentence(&self) -> String {
        match &self.polish {
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
        }
    }

    /// The flood solid: its grid and which rule made which part of the surface.
    fn flood_sentence(&self) -> String {
        let Some(f) = self.solid.flood.as_ref().filter(|_| self.solid.rule == SolidRule::Flood) else {
            return String::new();
        };
        format!(
            " The solid is what a flood fill from outside cannot reach ({}×{}×{} cells of {:.4e}, {:.2}% of the \
             diagonal; gaps narrower than about 2.7 cells are closed); it encloses {:.1}% of the uniform samples, the \
             winding-number solid {:.1}%, and the two disagree on {:.1}% of the near-surface samples. Of the input's \
             surface, {:.1}% bounds the enclosed parts (the crust lies on it), {:.1}% has the outside on both sides \
             (single-sided panels, sheets, walls of open boxes) and is thickened by {:.4e} on each side ({:.2}% of the \
             diagonal), {:.1}% is enclosed on both sides (doubled, buried or touching faces) and left out, and {:.1}% \
             lies in crevices narrower than the grid, taken as enclosed and left out too.",
            f.cells[0],
            f.cells[1],
            f.cells[2],
            f.cell,
            100.0 * f.cell_of_diagonal,
            100.0 * f.enclosed_share,
            100.0 * f.winding_share,
            100.0 * f.disagreement,
            100.0 * f.boundary_share,
            100.0 * f.sheet_share,
            f.sheet_half_thickness,
            100.0 * f.sheet_half_thickness_of_diagonal,
            100.0 * f.interior_share,
            100.0 * f.crevice_share
        )
    }

    /// The thin shell and its thickness search (shell only).
    fn shell_sentence(&self) -> String {
        match (self.solid.half_thickness, self.solid.half_thickness_of_diagonal) {
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
                let why = match (self.solid.chosen_by, self.solid.cap_area_share) {
                    (super::CHOSEN_FOR_LARGE_CAPS, Some(share)) => format!(
                        "The mesh is a thin-walled part with large openings (the |w| = 0.5 caps that would close its \
                         winding-number solid would add {:.0}% to its area)",
                        100.0 * share
                    ),
                    _ => format!(
                        "The mesh is an open sheet ({:.0}% of near-surface samples have a winding number between 0.25 \
                         and 0.75 in magnitude)",
                        100.0 * self.solid.near_surface_ambiguous_share
                    ),
                };
                format!(
                    " {why}, so the sites fit a thin shell: the surface thickened by {h:.4e} on each side ({:.2}% of the \
                     diagonal); the crust is that shell's boundary.{search}",
                    100.0 * f
                )
            }
            _ => String::new(),
        }
    }

    /// The input's triangles turned around, when any were.
    fn reoriented_sentence(&self) -> String {
        let r = &self.input.reoriented;
        if r.flipped_triangles > 0 {
            format!(
                " {} of the input's triangles (in {} piece(s)) were turned around to agree with their neighbours \
                 before the solid was built: flipped against the rest of their body, they turn part of it inside out \
                 for the winding number.",
                r.flipped_triangles, r.pieces_changed
            )
        } else {
            String::new()
        }
    }

    /// The holes closed flat before the solid was built, and those left open, when the
    /// input had any.
    fn holes_sentence(&self) -> String {
        let Some(h) = &self.solid.holes_filled else { return String::new() };
        if h.loops_found == 0 {
            return String::new();
        }
        let mut open = Vec::new();
        for (n, why) in [
            (h.open_not_planar, "rim not planar"),
            (h.open_not_simple, "rim crossing itself in its plane"),
            (h.open_shallow, "the fill would enclose no real volume, as a sheet's outline"),
            (h.open_degenerate, "no area"),
            (h.open_not_on_boundary, "the lid would lie inside or outside the solid, not on its boundary"),
            (h.open_in_tangled_piece, "on a piece whose other open edges form no loop"),
        ] {
            if n > 0 {
                open.push(format!("{n} {why}"));
            }
        }
        let open = if open.is_empty() { String::new() } else { format!("; left open: {}", open.join(", ")) };
        format!(
            " Of the input's {} boundary loop(s), {} had a planar rim and were closed flat before the solid was built \
             ({} triangles on the rims' own vertices, area {:.6e} in input units²), as the input's own faces{open}.",
            h.loops_found, h.loops_filled, h.triangles_added, h.filled_area
        )
    }

    /// The interior surface left out of the samples, when any was.
    fn interior_sentence(&self) -> String {
        match (self.solid.interior_surface_share, self.solid.interior_surface_samples_dropped) {
            (Some(share), dropped) if dropped > 0 => format!(
                " {:.1}% of the input's surface is not on the solid's boundary (the same side of the solid on \
                 both sides: faces inside it where bodies overlap, doubled faces); its {dropped} surface samples were \
                 left out of the initialisation, the surface term and the polish.",
                100.0 * share
            ),
            _ => String::new(),
        }
    }

    /// The caps across an open mesh's holes, with the hint to try a thin shell where they lie
    /// far from the input (winding solid of an open mesh only).
    fn caps_sentence(&self) -> String {
        let filled = self.solid.holes_filled.as_ref().is_some_and(|h| h.loops_filled > 0);
        // Caps or lids that leave the crust far from the input: the mesh may be a surface (a
        // pipe, crossing panels) rather than a volume's skin with holes. Say what to try.
        let far = match &self.metrics {
            MetricsReport::Done(m) if m.reference_diagonal > 0.0 && (self.solid.cap_samples > 0 || filled) => {
                let share = m.hausdorff.directed_witness[1] / m.reference_diagonal;
                let those = match (self.solid.cap_samples > 0, filled) {
                    (true, true) => "those caps and flat fills",
                    (true, false) => "those caps",
                    _ => "those flat fills",
                };
                if share >= SHELL_HINT_ABOVE {
                    format!(
                        " Part of the crust ({those}) lies {:.1}% of the diagonal from the input: if the mesh is \
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
        if self.solid.cap_samples > 0 {
            let other = if filled { "other " } else { "" };
            format!(
                " The solid closes the input's {other}holes by the |winding number| = 0.5 surface; {} points of \
                 it beyond the input's edges were added to the surface samples (caps and their rims), so sites \
                 stand there too.{far}",
                self.solid.cap_samples
            )
        } else {
            far
        }
    }

    /// The sites removed last, when any were.
    fn pruning_sentence(&self) -> String {
        match &self.pruning {
            Some(p) if p.sites_after < p.sites_before => format!(
                " Last, {} sites whose Delaunay neighbours all carry their label were removed (they change neither \
                 the crust nor the occupancy): the sites file holds {} sites.",
                p.sites_before - p.sites_after,
                p.sites_after
            ),
            _ => String::new(),
        }
    }

    /// The accuracy target's goal and rounds, when one was asked for.
    fn accuracy_sentence(&self) -> String {
        match &self.accuracy_target {
            Some(a) => {
                let steps: Vec<String> = a
                    .trace
                    .iter()
                    .map(|r| {
                        let genus = match (a.keep_topology, r.genus) {
                            (true, Some(g)) => format!(", genus {g}"),
                            _ => String::new(),
                        };
                        format!("{} sites: {:.3}%{genus}", r.sites, 100.0 * r.hausdorff_hi_of_diagonal)
                    })
                    .collect();
                let goal = match (a.goal_hausdorff_of_diagonal, a.keep_topology) {
                    (Some(g), false) => format!("Hausdorff ≤ {:.3}% of the diagonal", 100.0 * g),
                    (Some(g), true) => {
                        format!("Hausdorff ≤ {:.3}% of the diagonal and the input's topology", 100.0 * g)
                    }
                    (None, _) => "the input's topology".to_string(),
                };
                format!(
                    " Accuracy target: {goal} {} {} sites (budget {}; {}).",
                    if a.met { "met with" } else { "NOT met; the fit written is the closest one, with" },
                    a.sites_used,
                    a.max_sites,
                    steps.join(", ")
                )
            }
            None => String::new(),
        }
    }
}

impl PolishChoice {
    /// For the details: which crust was kept and why.
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

/// The sentence on a carving round taken back because its crust could not be extracted.
fn taken_back(r: &super::CarveReport) -> String {
    if r.round_not_extracted.is_some() {
        " A carving round was taken back: the crust of the sites with its insertions could not be extracted \
         (report: carving.round_not_extracted)."
            .into()
    } else {
        String::new()
    }
}

impl super::TopologyCheck {
    /// For the details: how the crust's topology differs from the input's.
    fn difference(&self) -> String {
        let mut parts = Vec::new();
        if self.handles_closed > 0 {
            parts.push(format!(
                "it closed {} of the input's {} handles (holes narrower than about two site spacings close; more \
                 sites keep them)",
                self.handles_closed, self.input_genus
            ));
        }
        if self.handles_added > 0 {
            parts.push(format!(
                "it has {} handle(s) the input has not (parts closer than about two site spacings are bridged)",
                self.handles_added
            ));
        }
        if self.input_components != self.crust_components {
            parts.push(format!(
                "it has {} component(s) against the input's {}",
                self.crust_components, self.input_components
            ));
        }
        format!(" The crust's topology differs from the input's (genus {}): {}.", self.input_genus, parts.join("; "))
    }
}
