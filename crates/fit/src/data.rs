//! The mesh in the unit cube and the labelled sample pools.

use mesh_io::TriMesh;
use occupancy::sample::{near_surface, uniform_in_box, SurfaceSampler};
use soft_voronoi::{Solid, TrainingData};

use crate::error::FitError;

/// The mesh without unreferenced vertices (they must not move the normalisation).
///
/// - `mesh`: any triangle mesh; returns the same triangles over the referenced vertices,
///   in order of first use.
pub fn compact(mesh: &TriMesh) -> TriMesh {
    let mut map = vec![u32::MAX; mesh.positions.len()];
    let mut positions = Vec::new();
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| {
            t.map(|v| {
                if map[v as usize] == u32::MAX {
                    map[v as usize] = positions.len() as u32;
                    positions.push(mesh.positions[v as usize]);
                }
                map[v as usize]
            })
        })
        .collect();
    TriMesh { positions, triangles }
}

/// A labelled pool in the unit cube: `n/2` points uniform in the cube, `n − n/2` near the
/// surface (`sigmas`: unit-cube lengths, split evenly), labelled by the solid's inside
/// rule (left empty when `solid` is `None`: the caller labels the pool once it has chosen
/// its solid); plus up to 2²⁰ area-uniform surface points with normals (seed XOR
/// [`vf_common::rng::seed_tweak::TRAIN_SURFACE`]) for the surface initialisation. Returns
/// the pool and the number of uniform points (they come first).
///
/// # Errors
/// [`FitError::Occupancy`] from the samplers (invalid sizes).
pub fn labelled_samples(
    sampler: &SurfaceSampler,
    solid: Option<&dyn Solid>,
    n: usize,
    sigmas: &[f64],
    seed: u64,
) -> Result<(TrainingData, usize), FitError> {
    let fail = |source| FitError::Occupancy { during: "sampling", source };
    let mut points = uniform_in_box([0.0; 3], [1.0; 3], n / 2, seed).map_err(fail)?;
    let num_uniform = points.len();
    points.extend(near_surface(sampler, n - n / 2, sigmas, seed).map_err(fail)?);
    let occupancy = solid.map_or_else(Vec::new, |s| s.inside(&points));
    let surface = sampler.sample(n.min(1 << 20), seed ^ vf_common::rng::seed_tweak::TRAIN_SURFACE);
    Ok((TrainingData { points, occupancy, surface: surface.points, normals: surface.normals }, num_uniform))
}
