//! The solid the sites fit: the mesh's winding-number solid; for a soup whose winding
//! number is not decisive (flipped, open or single-sided parts) what a flood fill from
//! outside leaves enclosed, with sheets as bands ([`FloodSolid`], `flood.rs`); or, when
//! the winding solid holds (almost) nothing — a zero-thickness sheet, a lone open patch —
//! the surface thickened into a thin shell ([`ShellSolid`]). Said in the report and the
//! summary.

mod band;
mod caps;
mod flood;
mod interior;
mod rim;
mod shell;

use mesh_io::TriMesh;
use occupancy::sample::SurfaceSampler;
use occupancy::MeshOracle;
use soft_voronoi::{FloodSolid, MeshSolid, ShellSolid, Solid, TrainingData};

use crate::config::{
    flood_sheet_half_thickness, shell_half_thickness, FitConfig, SolidRule, AMBIGUITY_SAMPLES, CAPS_SHELL_ABOVE,
    SHELL_ABOVE,
};
use crate::error::{FitError, MeshFault};
pub use crate::report::{BandTrial, FloodReport, SheetBand, SolidReport, CHOSEN_FOR_LARGE_CAPS};

/// The flood solid's report has a `sheet_band` when more than this share of the surface
/// is sheets.
const SHEET_BAND_MIN_SHARE: f64 = 0.01;
pub use band::BAND_FACTORS;
use band::*;
pub use caps::cap_samples;
use caps::*;
use flood::*;
use interior::*;
use rim::*;
use shell::*;

/// The solid in use; the shell comes with its own initial sites ([`shell_sites`]).
pub(crate) enum Target<'a> {
    Winding(MeshSolid<'a>),
    Flood(FloodSolid<'a>),
    Shell(ShellSolid<'a>, Vec<[f64; 3]>, Vec<bool>),
}

impl Target<'_> {
    pub(crate) fn solid(&self) -> &dyn Solid {
        match self {
            Target::Winding(s) => s,
            Target::Flood(s) => s,
            Target::Shell(s, ..) => s,
        }
    }

    /// Initial sites and labels when the target places them itself (the shell).
    pub(crate) fn initial_sites(&self) -> Option<(Vec<[f64; 3]>, Vec<bool>)> {
        match self {
            Target::Winding(_) | Target::Flood(_) => None,
            Target::Shell(_, sites, labels) => Some((sites.clone(), labels.clone())),
        }
    }

    /// What the report's IoU is measured against (`FitReport::iou_reference`).
    pub(crate) fn iou_reference(&self) -> String {
        match self {
            Target::Winding(_) => {
                "the solid fitted: the winding-number solid of the input, its pieces consistently oriented".into()
            }
            Target::Flood(_) => "the solid fitted: the flood solid (enclosed parts, sheets' bands)".into(),
            Target::Shell(s, ..) => format!(
                "the solid fitted: the thin shell of half-thickness {:.3e} (unit-cube lengths)",
                s.half_thickness
            ),
        }
    }

    /// Whether each surface point (unit cube, with the unit normal of its face) lies on a
    /// face the solid buries — the solid on both of its sides — for the report's
    /// `solid_boundary`: for the winding solid, inside at ±`eps` along the normal (as
    /// `voronoi-fit eval` asks the input's own solid); for the flood solid, enclosed on both
    /// sides or in a crevice (the surface the fit leaves out; a sheet has the outside on both
    /// sides and is not buried, though its band holds both probes); the shell buries
    /// nothing. A point without a normal is not buried.
    pub(crate) fn buried(&self, points: &[[f64; 3]], normals: &[[f64; 3]], eps: f64) -> Vec<bool> {
        use rayon::prelude::*;
        match self {
            Target::Winding(s) => {
                let Ok(b) = metrics::buried(points, normals, eps, |q| Ok::<_, std::convert::Infallible>(s.inside(q)));
                b.into_iter().zip(normals).map(|(b, n)| b && *n != [0.0; 3]).collect()
            }
            Target::Flood(s) => points
                .par_iter()
                .zip(normals)
                .map(|(&x, &n)| {
                    n != [0.0; 3]
                        && matches!(
                            s.surface_side(x, n),
                            soft_voronoi::SurfaceSide::Interior | soft_voronoi::SurfaceSide::Crevice
                        )
                })
                .collect(),
            Target::Shell(..) => vec![false; points.len()],
        }
    }

    /// What told the report's `solid_boundary` interior faces apart.
    pub(crate) fn interior_by(&self) -> &'static str {
        match self {
            Target::Winding(_) => {
                "the solid fitted: the winding-number solid of the input, its pieces consistently oriented"
            }
            Target::Flood(_) => "the solid fitted: the flood solid (faces enclosed on both sides and crevices)",
            Target::Shell(..) => "the solid fitted: the thin shell (no face is buried in it)",
        }
    }

    /// Whether the target places its own sites (then they are not trained by default).
    pub(crate) fn places_sites(&self) -> bool {
        matches!(self, Target::Shell(..))
    }
}

/// Chooses the solid for `data` (near-surface samples from `num_uniform` on; labelled by
/// the winding number, or not yet labelled where the flood solid may be chosen: then it is
/// labelled here by the solid chosen; `is_closed`: the mesh's topology) and, for the
/// flood solid and the shell, relabels the pool and moves its sheets' surface points onto
/// the band's two sides (alternately). `scale`: input units per unit-cube length.
///
/// # Errors
/// [`FitError::Mesh`] when the winding-number solid is asked for and holds nothing.
#[allow(clippy::too_many_arguments)]
pub(crate) fn choose<'a>(
    oracle: &'a MeshOracle,
    unit: &TriMesh,
    sampler: &SurfaceSampler,
    data: &mut TrainingData,
    num_uniform: usize,
    config: &FitConfig,
    diagonal: f64,
    scale: f64,
    is_closed: bool,
) -> Result<(Target<'a>, SolidReport), FitError> {
    let s = &config.sampling;
    let probe = &data.points[num_uniform..data.points.len().min(num_uniform + AMBIGUITY_SAMPLES)];
    let w = oracle
        .winding_numbers(probe, occupancy::WindingMode::Fast)
        .map_err(|source| FitError::Occupancy { during: "winding numbers", source })?;
    let ambiguous = ambiguous_share(&w);
    let winding_probe: Vec<bool> = w.iter().map(|&w| oracle.config().is_inside_winding(w)).collect();
    let h_sheet = shell_half_thickness(s.shell_thickness, sampler.total_area(), config.train.num_sites, diagonal);
    // The flood solid is looked at for every open mesh under auto (a closed mesh's
    // winding number is decisive).
    let flood_sheet = |followed: f64| {
        let area = followed * sampler.total_area();
        flood_sheet_half_thickness(s.shell_thickness, area, config.train.num_sites, diagonal)
    };
    let flood = match s.solid {
        SolidRule::Flood => {
            Some(flood_look(oracle, unit, data, num_uniform, s.flood_cells, flood_sheet, &winding_probe)?)
        }
        SolidRule::Auto if !is_closed => {
            Some(flood_look(oracle, unit, data, num_uniform, s.flood_cells, flood_sheet, &winding_probe)?)
        }
        _ => None,
    };
    let flood_report = |f: &FloodLook| f.report(scale, diagonal);
    let by_flood = match s.solid {
        SolidRule::Flood => Some("--solid"),
        SolidRule::Auto if flood.as_ref().is_some_and(|f| f.wanted()) => Some("auto"),
        _ => None,
    };
    if let (Some(chosen_by), Some(f)) = (by_flood, flood.as_ref()) {
        let probe_share = winding_probe.iter().filter(|&&o| o).count() as f64 / winding_probe.len().max(1) as f64;
        let report = SolidReport {
            rule: SolidRule::Flood,
            chosen_by,
            near_surface_inside_share: probe_share,
            near_surface_ambiguous_share: ambiguous,
            half_thickness: None,
            half_thickness_of_diagonal: None,
            init: None,
            interior_surface_share: None,
            interior_surface_samples_dropped: 0,
            cap_samples: 0,
            cap_area_share: None,
            thickness_search: None,
            holes_filled: None,
            flood: Some(flood_report(f)),
            sheet_band: (f.sheet_share() > SHEET_BAND_MIN_SHARE)
                .then(|| SheetBand::of(f.sheet_half_thickness() / diagonal, config.train.num_sites)),
        };
        let solid = flood.ok_or(FitError::Internal("the flood solid was not built"))?.apply(data);
        if !data.occupancy.iter().any(|&o| o) {
            return Err(FitError::Mesh { mesh: s.mesh.clone(), fault: MeshFault::NothingInside });
        }
        return Ok((Target::Flood(solid), report));
    }
    // The pool was left unlabelled where the flood solid might have been chosen.
    if data.occupancy.len() != data.points.len() {
        data.occupancy = MeshSolid { oracle }.inside(&data.points);
    }
    let near = &data.occupancy[num_uniform..];
    let share = near.iter().filter(|&&o| o).count() as f64 / near.len().max(1) as f64;
    let nothing_inside = !data.occupancy.iter().any(|&o| o);
    let (mut rule, mut chosen_by) = match s.solid {
        SolidRule::Auto if !is_closed && (ambiguous >= SHELL_ABOVE || nothing_inside) => (SolidRule::Shell, "auto"),
        SolidRule::Auto => (SolidRule::Winding, "auto"),
        r => (r, "--solid"),
    };
    // The winding solid of an open mesh is closed across its holes by |w| = 0.5 caps; where
    // they would be a large part of the solid's surface, auto takes the shell
    // ([`CAPS_SHELL_ABOVE`]).
    let (caps, cap_area_share) = if rule == SolidRule::Winding && !is_closed && !nothing_inside {
        let caps = pool_cap_points(oracle, data, num_uniform, sampler.total_area(), config.train.num_sites)?;
        let share = caps.area() / sampler.total_area();
        if s.solid == SolidRule::Auto && share >= CAPS_SHELL_ABOVE {
            (rule, chosen_by) = (SolidRule::Shell, CHOSEN_FOR_LARGE_CAPS);
        }
        (Some(caps), share.is_finite().then_some(share))
    } else {
        (None, None)
    };
    if rule == SolidRule::Winding {
        if nothing_inside {
            return Err(FitError::Mesh { mesh: s.mesh.clone(), fault: MeshFault::NothingInside });
        }
        let solid = MeshSolid { oracle };
        let (interior, dropped) = drop_interior_surface(&solid, data, diagonal);
        let caps = match caps {
            Some(caps) => add_cap_samples(
                oracle,
                unit,
                data,
                caps,
                sampler.total_area(),
                config.train.num_sites,
                config.train.seed,
            )?,
            None => 0,
        };
        let report = SolidReport {
            rule: SolidRule::Winding,
            chosen_by,
            near_surface_inside_share: share,
            near_surface_ambiguous_share: ambiguous,
            half_thickness: None,
            half_thickness_of_diagonal: None,
            init: None,
            interior_surface_share: Some(interior),
            interior_surface_samples_dropped: dropped,
            cap_samples: caps,
            cap_area_share,
            thickness_search: None,
            holes_filled: None,
            flood: flood.as_ref().map(flood_report),
            sheet_band: None,
        };
        return Ok((Target::Winding(solid), report));
    }
    let h0 = h_sheet;
    let k = config.train.num_sites;
    let m = data.surface.len().min(12 * k);
    let plan = ShellPlan::new(unit, sampler.total_area(), &data.surface[..m], &data.normals[..m], k);
    let place = |h: f64, data: &TrainingData| {
        let solid = ShellSolid::new(oracle, unit, h);
        let (sites, labels, counts) =
            shell_sites(&plan, &data.surface[..m], &data.normals[..m], &solid, k, data, config.train.seed);
        (solid, sites, labels, counts)
    };
    let (h, thickness_search) = if s.shell_thickness.is_none() && !config.train_shell {
        let boundary = config.train.boundary_positions();
        let (h, trials) = thinnest_band(h0, unit, diagonal, &boundary, |h| {
            let (_, sites, labels, _) = place(h, data);
            (sites, labels)
        })?;
        (h, Some(trials))
    } else {
        (h0, None)
    };
    let (solid, sites, labels, (triplets, rims)) = place(h, data);
    data.occupancy = solid.inside(&data.points);
    for (i, (p, n)) in data.surface.iter_mut().zip(&data.normals).enumerate() {
        let side = if i % 2 == 0 { h } else { -h };
        *p = [0, 1, 2].map(|c| p[c] + side * n[c]);
    }
    let report = SolidReport {
        rule: SolidRule::Shell,
        chosen_by,
        near_surface_inside_share: share,
        near_surface_ambiguous_share: ambiguous,
        half_thickness: Some(h / scale),
        half_thickness_of_diagonal: Some(h / diagonal),
        init: Some(format!(
            "{triplets} triplets (inside on the surface, outside at ±2h along the normal; spaced by how far the \
             sheet bends, and more where the band had a hole) and {rims} rim quadruplets (one more outside site 2h \
             beyond the open boundary, two at a corner){}",
            if config.train_shell {
                ", then trained"
            } else {
                ", kept as constructed (no training unless --steps is given)"
            }
        )),
        interior_surface_share: None,
        interior_surface_samples_dropped: 0,
        cap_samples: 0,
        cap_area_share,
        thickness_search,
        holes_filled: None,
        flood: flood.as_ref().map(flood_report),
        sheet_band: Some(SheetBand::of(h / diagonal, config.train.num_sites)),
    };
    Ok((Target::Shell(solid, sites, labels), report))
}

/// Share of winding numbers with 0.25 < |w| < 0.75 ([`SHELL_ABOVE`]).
pub(crate) fn ambiguous_share(w: &[f64]) -> f64 {
    w.iter().filter(|w| (0.25..0.75).contains(&w.abs())).count() as f64 / w.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use vf_common::rng::{ChunkRng, Stream};

    /// The square [0.3, 0.7]² at z = 0.5 (two triangles).
    fn square() -> TriMesh {
        TriMesh {
            positions: vec![[0.3, 0.3, 0.5], [0.7, 0.3, 0.5], [0.7, 0.7, 0.5], [0.3, 0.7, 0.5]],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    /// Triplets (inside on the square, outside at ±2h) every 0.04 and an outside site 2h
    /// beyond the rim every 0.02, as `shell_sites` places them; when `puncture`, the middle
    /// triplet's inside site is labelled outside, a hole through the band.
    fn band(h: f64, puncture: bool) -> (Vec<[f64; 3]>, Vec<bool>) {
        let (mut sites, mut labels) = (Vec::new(), Vec::new());
        for i in 0..=20 {
            for j in 0..=20 {
                let (x, y) = (0.3 + 0.02 * i as f64, 0.3 + 0.02 * j as f64);
                let rim = i == 0 || j == 0 || i == 20 || j == 20;
                if i % 2 == 0 && j % 2 == 0 || rim {
                    let middle = i == 10 && j == 10;
                    sites.extend([[x, y, 0.5], [x, y, 0.5 + 2.0 * h], [x, y, 0.5 - 2.0 * h]]);
                    labels.extend([!(puncture && middle), false, false]);
                }
                if rim {
                    // Outward across the square's edge (both edges' at a corner).
                    let out = |k: i32| f64::from(i32::from(k == 20) - i32::from(k == 0));
                    let d = [out(i), out(j)];
                    let l = d[0] * d[0] + d[1] * d[1];
                    sites.push([x + 2.0 * h * d[0] / l.sqrt(), y + 2.0 * h * d[1] / l.sqrt(), 0.5]);
                    labels.push(false);
                }
            }
        }
        (sites, labels)
    }

    /// The slots the triplets and rim points leave are filled outside the band, at least 2h
    /// from it, whatever the pool holds (here, a pool of points inside the band only but
    /// for a few far ones).
    #[test]
    fn leftover_slots_are_filled_away_from_the_band() {
        let unit = square();
        let oracle = MeshOracle::from_mesh(&unit, &occupancy::Config::default()).unwrap();
        let h = 0.01;
        let solid = ShellSolid::new(&oracle, &unit, h);
        let mut rng = ChunkRng::for_chunk(7, Stream::SitesInit, 9);
        let surface: Vec<[f64; 3]> =
            (0..4000).map(|_| [0.3 + 0.4 * rng.uniform(), 0.3 + 0.4 * rng.uniform(), 0.5]).collect();
        let normals = vec![[0.0, 0.0, 1.0]; surface.len()];
        // Most of the pool inside the band (0.5 ± h/2), a few points far above it.
        let mut points: Vec<[f64; 3]> = (0..2000)
            .map(|_| [0.3 + 0.4 * rng.uniform(), 0.3 + 0.4 * rng.uniform(), 0.5 + h * (rng.uniform() - 0.5)])
            .collect();
        // (As many far points as a shell's repair reserve can leave unused.)
        points.extend((0..400).map(|i| [0.31 + 0.00095 * i as f64, 0.5, 0.8 + 0.1 * (i % 2) as f64]));
        let occupancy = vec![true; points.len()];
        let data = TrainingData { points, occupancy, surface: surface.clone(), normals: normals.clone() };
        let mut filled = 0;
        for k in 300..310 {
            let plan = ShellPlan::new(&unit, 0.16, &surface, &normals, k);
            let (sites, labels, (triplets, rims)) = shell_sites(&plan, &surface, &normals, &solid, k, &data, 0);
            assert_eq!(sites.len(), k);
            let placed = 3 * triplets + 4 * rims + 2 * 4;
            filled += k - placed;
            for (p, &inside) in sites[placed..].iter().zip(&labels[placed..]) {
                assert!(!inside, "a fill site inside the band: {p:?}");
                assert!((p[2] - 0.5).abs() >= 3.0 * h - 1e-12, "a fill site {p:?} within 2h of the band");
            }
        }
        assert!(filled > 0, "no K left a slot to fill");
    }

    #[test]
    fn the_thinnest_band_that_keeps_the_topology_is_taken() {
        let unit = square();
        let (h0, diagonal) = (0.02, unit.diagonal());
        // Whole at every thickness: the thinnest is taken at once.
        let (h, trials) =
            thinnest_band(h0, &unit, diagonal, &soft_voronoi::init::boundary_sites(32), |h| band(h, false)).unwrap();
        assert_eq!(h, BAND_FACTORS[0] * h0, "{trials:?}");
        // The default, the thickest thinner band, then the thinnest.
        let factors: Vec<f64> = trials.iter().map(|t| t.factor).collect();
        assert_eq!(factors, [1.0, BAND_FACTORS[BAND_FACTORS.len() - 1], BAND_FACTORS[0]], "{trials:?}");
        assert_eq!((trials[0].components, trials[0].genus), (1, Some(0)), "{trials:?}");
        assert!(trials[2].kept && !trials[0].kept && !trials[1].kept);
        assert!(trials[2].hausdorff_of_diagonal.unwrap() < trials[0].hausdorff_of_diagonal.unwrap(), "{trials:?}");
        // Bands thinner than half the default break (a hole through the middle): the first
        // whole one is taken, and the broken ones are listed with their genus.
        let (h, trials) =
            thinnest_band(h0, &unit, diagonal, &soft_voronoi::init::boundary_sites(32), |h| band(h, h < 0.45 * h0))
                .unwrap();
        assert_eq!(h, 0.5 * h0, "{trials:?}");
        let genus: Vec<Option<i64>> = trials.iter().map(|t| t.genus).collect();
        assert_eq!(genus, [Some(0), Some(0), Some(1), Some(1), Some(1), Some(1), Some(0)], "{trials:?}");
        assert_eq!(trials.iter().filter(|t| t.kept).count(), 1);
        // Only the bands whose topology holds had their distance measured.
        let measured: Vec<bool> = trials.iter().map(|t| t.hausdorff_of_diagonal.is_some()).collect();
        assert_eq!(measured, [true, true, false, false, false, false, true], "{trials:?}");
        // Broken at every thinner band: the default stays.
        let (h, trials) =
            thinnest_band(h0, &unit, diagonal, &soft_voronoi::init::boundary_sites(32), |h| band(h, h < h0)).unwrap();
        assert_eq!(h, h0);
        // The thickest thinner band broke: no thinner one was tried.
        assert_eq!(trials.len(), 2, "{trials:?}");
        assert!(trials[0].kept);
    }

    /// An icosphere of radius 0.3 about the cube's centre, without the triangles whose
    /// centroid is above `cut` (z, unit frame), and when `shrink` < 1 every triangle shrunk
    /// about its centroid by that factor on vertices of its own (a soup).
    fn sphere(subdivisions: u32, cut: f64, shrink: f64) -> TriMesh {
        let s = mesh_io::shapes::icosphere(subdivisions);
        let (mut positions, mut triangles) = (Vec::new(), Vec::new());
        for t in &s.triangles {
            let p = t.map(|v| s.positions[v as usize].map(|x| 0.5 + 0.3 * x));
            let c = [0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0);
            if c[2] > cut {
                continue;
            }
            let n = positions.len() as u32;
            positions.extend(p.map(|q| [0, 1, 2].map(|k| c[k] + shrink * (q[k] - c[k]))));
            triangles.push([n, n + 1, n + 2]);
        }
        TriMesh { positions, triangles }
    }

    /// The ring beyond a hole's edge gets points on the |w| = 0.5 level set, beside the edge.
    #[test]
    fn a_holes_rim_gets_points_on_the_level_set() {
        let bowl = sphere(3, 0.6, 1.0);
        let oracle = MeshOracle::from_mesh(&bowl, &occupancy::Config::default()).unwrap();
        let spacing = 0.05;
        let (points, normals) = rim_samples(&oracle, &bowl, spacing, 1e-5, 3).unwrap();
        assert!(points.len() > 100, "{} rim points", points.len());
        assert_eq!(points.len(), normals.len());
        let w = oracle.winding_numbers(&points, occupancy::WindingMode::Exact).unwrap();
        let near = oracle.closest_points(&points).unwrap();
        for ((p, w), c) in points.iter().zip(w).zip(near) {
            let r = c.squared_distance.sqrt();
            assert!(r <= 1.2 * CAP_CLEARANCE * spacing, "{p:?} is {r} from the input");
            assert!(2.0 * std::f64::consts::PI * r * (w.abs() - 0.5).abs() <= RIM_PRECISION * spacing, "{p:?}: w {w}");
        }
    }

    /// A soup (every triangle on vertices of its own, so every edge is open) has a face
    /// beside each edge: no rim points, searched (1,280 triangles) or over the search
    /// budget (5,120).
    #[test]
    fn a_soups_edges_get_no_rim_points() {
        for subdivisions in [3, 4] {
            let soup = sphere(subdivisions, 1.0, 0.97);
            assert_eq!(boundary_edges(&soup).len(), 3 * soup.triangles.len());
            let oracle = MeshOracle::from_mesh(&soup, &occupancy::Config::default()).unwrap();
            let (points, _) = rim_samples(&oracle, &soup, 0.05, 1e-5, 3).unwrap();
            assert!(points.is_empty(), "{} rim points", points.len());
        }
    }
}
