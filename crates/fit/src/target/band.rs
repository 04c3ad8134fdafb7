//! The thin shell's thickness: the thinnest band whose crust keeps the default band's
//! topology and Hausdorff distance.

use crust::output::{FrameMap, Precision};
use mesh_io::TriMesh;

use super::*;
use crate::error::FitError;

/// Half-thicknesses tried below the default h0 = √(A/K), thinnest first, as shares of h0.
///
/// The band's sides are exact on a flat part whatever its thickness, and a thinner band
/// lies closer to the sheet: on libigl's flat `grid.off` at K = 8,192, half the default
/// (0.39% of the diagonal) took Chamfer from 0.79% to 0.40% and normal consistency from
/// 0.979 to 0.989. But where the sheet curves, the cells of neighbouring triplets meet in
/// steps about s²κ/2 high (spacing s, curvature κ), and a band thinner than its steps
/// breaks into holes: at 0.25% of the diagonal the lilium came out of genus 260 and the
/// beetle's body of genus 206 (from 0 and 10). So each band's crust is checked.
pub const BAND_FACTORS: [f64; 6] = [0.15, 0.2, 0.3, 0.4, 0.5, 0.7];

/// The thinnest band of [`BAND_FACTORS`]·`h0` whose crust (of the sites `place` puts for
/// it, as constructed) has the same components and genus as the default band's, and a
/// certified Hausdorff distance to `unit` no larger: a thinner band only where the sites
/// carry it without a hole. The thickest thinner band is tried first, and where it breaks
/// the thinner ones are not tried (a sheet rougher than the triplets' spacing); a band whose
/// topology already differs is not measured. Returns the half-thickness and every band tried
/// (the default's first, then the thickest thinner one).
///
/// # Errors
/// [`FitError::Crust`] or [`FitError::Metrics`] when a crust or its distance cannot be computed.
pub(super) fn thinnest_band(
    h0: f64,
    unit: &TriMesh,
    diagonal: f64,
    boundary: &[[f64; 3]],
    mut place: impl FnMut(f64) -> (Vec<[f64; 3]>, Vec<bool>),
) -> Result<(f64, Vec<BandTrial>), FitError> {
    // A band's crust, its topology, and (`measure`) its certified distance to the input.
    let mut trial = |factor: f64, measure: &dyn Fn(&BandTrial) -> bool| -> Result<BandTrial, FitError> {
        let (mut sites, mut labels) = place(factor * h0);
        // The fixed outside sites on the cube's faces, as training adds them: without them
        // the outer cells are unbounded.
        labels.extend(std::iter::repeat_n(false, boundary.len()));
        sites.extend_from_slice(boundary);
        // Welded by position as it would be written (the extracted crust may split a
        // vertex where Voronoi vertices coincide, which its own genus counts).
        let crust = crate::crust_step::crust_of(&sites, &labels, FrameMap::Identity, Precision::F64)?;
        let (report, mesh) = (&crust.check().report, &crust.written.mesh);
        let mut t = BandTrial {
            factor,
            half_thickness_of_diagonal: factor * h0 / diagonal,
            components: report.num_components,
            genus: report.genus,
            hausdorff_of_diagonal: None,
            kept: false,
            error: None,
        };
        if measure(&t) {
            let opts = metrics::hausdorff::CertifiedOptions { rel_tolerance: 1e-4, ..Default::default() };
            let hausdorff = if mesh.triangles.is_empty() {
                f64::INFINITY
            } else {
                metrics::hausdorff::hausdorff_certified(unit, mesh, &opts)
                    .map_err(|source| FitError::Metrics { during: "distance of a thin shell's crust", source })?
                    .hi
            };
            t.hausdorff_of_diagonal = Some(hausdorff / diagonal);
        }
        Ok(t)
    };
    // The genus a thin band of the sheet has: its boundary is a double cover of the sheet
    // (χ twice the sheet's), so 1 − χ per component, when every edge has at most two
    // triangles. The default band can miss it (libigl's beetle, a genus-1 sheet with 11
    // holes: 12 expected, 10 at the default band, whose thickness closes two small windows),
    // so a thinner band nearer it is taken; otherwise the default's genus is the reference.
    let topology = mesh_io::topology::TopologyReport::of(unit);
    let expected_genus =
        (topology.num_non_manifold_edges == 0).then(|| topology.num_components as i64 - topology.euler_characteristic);
    let mut trials = vec![trial(1.0, &|_| true)?];
    let reference = trials[0].clone();
    // A thinner band must keep the reference's components and genus (below) before its
    // distance is worth measuring: on a rough sheet every thinner band breaks into holes,
    // and the certified distances of their crusts were most of the search's time (libigl-
    // style terrain: seven bands).
    let topology_holds = |t: &BandTrial| {
        let genus_holds = match (expected_genus, t.genus, reference.genus) {
            (Some(g), Some(a), Some(b)) => (a - g).abs() <= (b - g).abs(),
            _ => t.genus == reference.genus,
        };
        t.components == reference.components && genus_holds
    };
    // One band: its trial, or the record of why it could not be made or measured (then it
    // is not taken, and the fit goes on: the search must never fail a fit the default band
    // would finish), and whether it holds.
    let mut try_band = |factor: f64, trials: &mut Vec<BandTrial>| -> bool {
        let t = match trial(factor, &topology_holds) {
            Ok(t) => t,
            Err(e) => {
                trials.push(BandTrial {
                    factor,
                    half_thickness_of_diagonal: factor * h0 / diagonal,
                    components: 0,
                    genus: None,
                    hausdorff_of_diagonal: None,
                    kept: false,
                    error: Some(e.to_string()),
                });
                return false;
            }
        };
        let holds = topology_holds(&t)
            && matches!((t.hausdorff_of_diagonal, reference.hausdorff_of_diagonal), (Some(a), Some(b)) if a <= b);
        trials.push(t);
        holds
    };
    // First the thickest of the thinner bands: where even it breaks into holes, the sheet
    // bends faster than the triplets follow and the thinner ones break too (on the
    // real-world benchmark's terrain and soup of slivers every band broke), so the default
    // stays after two bands instead of seven. Otherwise thinnest first, as before, and the
    // thickest is kept if it holds and no thinner one does.
    let (&thickest, thinner) = BAND_FACTORS.split_last().expect("bands to try");
    let mut kept = 0;
    if try_band(thickest, &mut trials) {
        kept = trials.len() - 1;
    }
    // Thinner bands only when the thickest kept the topology (its distance may still have
    // been too large).
    if topology_holds(&trials[trials.len() - 1]) {
        for &factor in thinner {
            if try_band(factor, &mut trials) {
                kept = trials.len() - 1;
                break;
            }
        }
    }
    trials[kept].kept = true;
    Ok((trials[kept].factor * h0, trials))
}
