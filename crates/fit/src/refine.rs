//! The accuracy target's initial sites: mirrored pairs twice as dense where a previous
//! fit's crust missed its tolerance ([`crate::config::Refine`]).

use mesh_io::UnitCubeTransform;
use occupancy::MeshOracle;
use soft_voronoi::init::pairs_init_refined;
use soft_voronoi::{SiteIndex, Solid, TrainingData};

use crate::config::{FitConfig, Refine};
use crate::error::FitError;

/// The refined pairs' sites and labels, and the share of candidates refined.
pub(crate) type RefinedPairs = (Vec<[f64; 3]>, Vec<bool>, f64);

/// Mirrored pairs for `config`'s K, twice as dense where `refine`'s crust was off: at the
/// candidate surface points farther than the tolerance from that crust (the input's side of
/// the Hausdorff distance), and within two pair spacings of the foot of every crust vertex
/// farther than the tolerance from the input (the crust's side: spikes). Returns the sites,
/// labels and the share of candidates refined.
pub(crate) fn refined_pairs(
    refine: &Refine,
    transform: &UnitCubeTransform,
    input_oracle: &MeshOracle,
    area: f64,
    data: &TrainingData,
    solid: &dyn Solid,
    config: &FitConfig,
) -> Result<RefinedPairs, FitError> {
    let k = config.train.num_sites;
    let previous = transform.mesh_to_unit(&refine.previous);
    let tolerance = refine.tolerance * transform.scale;
    let m = data.surface.len().min(12 * k);
    let candidates = &data.surface[..m];
    let fail = |source| FitError::Occupancy { during: "refining", source };
    let crust_oracle = MeshOracle::from_mesh(&previous, &occupancy::Config::default()).map_err(fail)?;
    let mut flags: Vec<bool> = crust_oracle
        .closest_points(candidates)
        .map_err(fail)?
        .iter()
        .map(|c| c.squared_distance > tolerance * tolerance)
        .collect();
    let feet: Vec<[f64; 3]> = input_oracle
        .closest_points(&previous.positions)
        .map_err(fail)?
        .into_iter()
        .filter(|c| c.squared_distance > tolerance * tolerance)
        .map(|c| c.point)
        .collect();
    if !feet.is_empty() {
        let radius = 2.0 * (area / (k / 2).max(1) as f64).sqrt();
        let index = SiteIndex::new(&feet);
        for (f, &p) in flags.iter_mut().zip(candidates) {
            *f = *f || index.nearest(&feet, p).1 <= radius;
        }
    }
    let share = flags.iter().filter(|&&f| f).count() as f64 / m.max(1) as f64;
    let t = &config.train;
    let (sites, labels, _) = pairs_init_refined(k, data, solid, t.surface_offset, t.density, t.seed, &flags)
        .map_err(FitError::TrainStart)?;
    Ok((sites, labels, share))
}
