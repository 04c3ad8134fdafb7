//! The reference's surface without its interior faces: how far the prediction is from the
//! part of the reference that bounds its solid.
//!
//! CAD unions and kit-bashed models carry faces inside their own solid (the bottom of a
//! fin sunk into a box, the overlap of two bodies). No closed surface of that solid comes
//! near them, so the two-sided Hausdorff distance to the whole reference has a floor set by
//! how deep those faces lie, whatever the method: on the quality benchmark's box_fin the
//! fin's bottom face lies 0.05 units (3.1% of the diagonal) under the box's top face, and
//! the certified Hausdorff distance of every method there is at least that.
//!
//! This module separates the two. A reference sample x with unit normal n is *interior*
//! when both x + εn and x − εn are inside the reference's solid (the workspace's one rule,
//! [`occupancy::MeshOracle::inside`]: signed crossings on closed meshes, |winding number|
//! ≥ 0.5 otherwise), ε = 10⁻⁶ × the diagonal; every other sample (the solid's boundary,
//! and sheets or open patches with outside on both sides) is a *boundary* sample. The
//! report gives the share of interior samples, the largest distance from a boundary sample
//! to the prediction and from an interior one, and an estimate of the Hausdorff distance to
//! the solid's boundary: the larger of the boundary samples' largest distance and the
//! certified run's witness for prediction → reference. Both are lower bounds (samples, and
//! a distance to the whole reference), so the estimate is one too; the certified interval
//! stays the headline number.

use mesh_io::TriMesh;
use occupancy::sample::SurfaceSampler;
use occupancy::{Config, MeshOracle, Workspace};
use rayon::prelude::*;
use serde::Serialize;

use crate::hausdorff::DistanceMesh;
use crate::MetricsError;

/// The offset ε of [`buried`]'s probes, as a share of the mesh's bounding-box diagonal.
pub const BURIED_OFFSET: f64 = 1e-6;

/// Whether each surface sample (`points`, unit `normals`) is buried: `inside` puts both
/// x + `eps`·n and x − `eps`·n inside the solid. `inside` gets all 2n probes in one call
/// (x + εn, x − εn for each sample, in order). Shared by [`solid_boundary`] and the fit's
/// carving, which asks its own solid.
///
/// # Errors
/// Whatever `inside` returns.
pub fn buried<E>(
    points: &[[f64; 3]],
    normals: &[[f64; 3]],
    eps: f64,
    inside: impl FnOnce(&[[f64; 3]]) -> Result<Vec<bool>, E>,
) -> Result<Vec<bool>, E> {
    let probes: Vec<[f64; 3]> = points
        .iter()
        .zip(normals)
        .flat_map(|(p, m)| [1.0, -1.0].map(|sign| [0, 1, 2].map(|k| p[k] + sign * eps * m[k])))
        .collect();
    let inside = inside(&probes)?;
    Ok(inside.chunks_exact(2).map(|pair| pair[0] && pair[1]).collect())
}

/// Result of [`solid_boundary`], mesh units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SolidBoundary {
    /// Reference samples drawn (area-uniform, seeded).
    pub num_samples: usize,
    /// The solid that told interior samples apart: the reference's own (`voronoi-fit
    /// eval`) or, in the main job's report, the solid the sites were fitted to.
    pub interior_by: String,
    /// Share of them with the reference's solid on both sides (interior faces).
    pub interior_share: f64,
    /// Largest distance from a boundary sample to the prediction.
    pub max_boundary_to_prediction: f64,
    /// Largest distance from an interior sample to the prediction (0 without any).
    pub max_interior_to_prediction: f64,
    /// A boundary sample at `max_boundary_to_prediction` (`None` without boundary samples).
    pub boundary_witness: Option<[f64; 3]>,
    /// max(`max_boundary_to_prediction`, the certified run's prediction → reference
    /// witness): a sampled estimate, and lower bound, of the Hausdorff distance between the
    /// prediction and the reference's solid boundary.
    pub hausdorff_estimate: f64,
}

/// What [`solid_boundary`] calls the reference's own solid.
pub const OWN_SOLID: &str =
    "the reference's own solid (signed crossings when closed, |winding number| >= 0.5 otherwise)";

/// Samples `reference`'s surface (`n` points, `seed`), splits the samples into interior and
/// boundary ones by the reference's own solid (module doc) and measures their distances to
/// `prediction`; `prediction_to_reference` is the certified run's witness of that direction.
///
/// # Errors
/// [`MetricsError::BadOption`] for `n == 0`, [`MetricsError::ZeroArea`] for a reference
/// without area, and the oracle's errors.
pub fn solid_boundary(
    reference: &DistanceMesh,
    prediction: &DistanceMesh,
    n: usize,
    seed: u64,
    prediction_to_reference: f64,
) -> Result<SolidBoundary, MetricsError> {
    let mesh: &TriMesh = reference.mesh();
    let eps = BURIED_OFFSET * mesh.diagonal();
    let own = |points: &[[f64; 3]], normals: &[[f64; 3]]| -> Result<Vec<bool>, MetricsError> {
        let oracle = MeshOracle::from_mesh(mesh, &Config::default())?;
        Ok(buried(points, normals, eps, |q| oracle.inside(q))?)
    };
    solid_boundary_with(reference, prediction, n, seed, prediction_to_reference, (OWN_SOLID, own))
}

/// [`solid_boundary`] with interior samples told apart by another solid: `interior` is its
/// name and a function from the samples (reference frame) and their unit normals to
/// whether each is buried in it (the main job passes the solid it fitted, which on a soup
/// is cheaper to ask than the raw input's winding number and is what the crust follows).
///
/// # Errors
/// As [`solid_boundary`], and whatever `interior` returns.
pub fn solid_boundary_with<F>(
    reference: &DistanceMesh,
    prediction: &DistanceMesh,
    n: usize,
    seed: u64,
    prediction_to_reference: f64,
    interior: (&str, F),
) -> Result<SolidBoundary, MetricsError>
where
    F: FnOnce(&[[f64; 3]], &[[f64; 3]]) -> Result<Vec<bool>, MetricsError>,
{
    if n == 0 {
        return Err(MetricsError::BadOption("the number of boundary samples must be > 0".into()));
    }
    let mesh: &TriMesh = reference.mesh();
    let sampler = SurfaceSampler::from_mesh(mesh).map_err(|_| MetricsError::ZeroArea {
        mesh: "reference",
        area: mesh_io::TopologyReport::of(mesh).surface_area,
    })?;
    let s = sampler.sample(n, seed);
    let (interior_by, is_buried) = interior;
    let is_buried = is_buried(&s.points, &s.normals)?;
    if is_buried.len() != n {
        return Err(MetricsError::BadOption(format!(
            "the interior test gave {} answers for {n} samples",
            is_buried.len()
        )));
    }
    let mut dist = vec![0.0; n];
    dist.par_chunks_mut(1024).enumerate().for_each(|(c, o)| {
        let mut ws = Workspace::new();
        for (j, d) in o.iter_mut().enumerate() {
            *d = prediction.bvh().closest_point(s.points[c * 1024 + j], &mut ws).squared_distance.sqrt();
        }
    });
    let (mut interior, mut max_b, mut max_i, mut witness) = (0usize, 0.0f64, 0.0f64, None);
    for (i, &d) in dist.iter().enumerate() {
        if is_buried[i] {
            interior += 1;
            max_i = max_i.max(d);
        } else if witness.is_none() || d > max_b {
            max_b = d;
            witness = Some(s.points[i]);
        }
    }
    Ok(SolidBoundary {
        num_samples: n,
        interior_by: interior_by.to_string(),
        interior_share: interior as f64 / n as f64,
        max_boundary_to_prediction: max_b,
        max_interior_to_prediction: max_i,
        boundary_witness: witness,
        hausdorff_estimate: max_b.max(prediction_to_reference),
    })
}
