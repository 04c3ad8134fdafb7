//! Distances of a surface to the study's sphere.

use mesh_io::TriMesh;
use occupancy::sample::SurfaceSampler;
use occupancy::MeshOracle;
use rayon::prelude::*;
use vf_common::rng::{ChunkRng, Stream};

use crate::data::unit_dir;
use crate::{StudyError, SPHERE};

/// What [`measure`] finds for one surface.
#[derive(Clone, Copy, Debug)]
pub struct Measured {
    /// Certified Hausdorff interval to the sphere (NaN for an empty surface).
    pub hausdorff_lo: f64,
    /// Its upper end.
    pub hausdorff_hi: f64,
    /// Chamfer L1 distance to the sphere (NaN for an empty surface).
    pub chamfer: f64,
    /// Triangles.
    pub triangles: usize,
    /// Closed and manifold.
    pub watertight: bool,
}

/// Chamfer L1: ½ (mean over mesh samples of the distance to the sphere + mean over sphere
/// samples of the distance to the mesh), `n` seeded samples per side.
///
/// # Errors
/// [`StudyError::Run`] for a mesh without area.
pub fn sphere_chamfer(mesh: &TriMesh, oracle: &MeshOracle, n: usize, seed: u64) -> Result<f64, StudyError> {
    let fail = |e: occupancy::OccupancyError| StudyError::Run(format!("Chamfer distance: {e}"));
    let sampler = SurfaceSampler::from_mesh(mesh).map_err(fail)?;
    let on_mesh = sampler.sample(n, seed);
    let d1: f64 = on_mesh.points.par_iter().map(|&p| SPHERE.distance(p).abs()).sum::<f64>() / n as f64;
    let mut rng = ChunkRng::for_chunk(seed, Stream::StudyChamfer, 0);
    let on_sphere: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            let d = unit_dir(&mut rng);
            [0, 1, 2].map(|k| SPHERE.center[k] + SPHERE.radius * d[k])
        })
        .collect();
    let d2: f64 =
        oracle.closest_points(&on_sphere).map_err(fail)?.iter().map(|c| c.squared_distance.sqrt()).sum::<f64>()
            / n as f64;
    Ok(0.5 * (d1 + d2))
}

/// The certified Hausdorff tolerance of the runs (unit cube).
pub const TOLERANCE: f64 = 1e-6 * 1.732_050_807_568_877_2;

/// The metrics crate's own limit of sphere patches (the runs' intervals converge well before).
pub const EVALUATIONS: usize = 20_000_000;

/// Certified Hausdorff interval (tolerance `tol`, at most `max_evaluations` patches of the
/// sphere; the runs use [`TOLERANCE`] and [`EVALUATIONS`]), Chamfer, triangle count and
/// closedness of a surface; NaN distances for an empty surface.
///
/// # Errors
/// [`StudyError::Run`] when a distance cannot be computed.
pub fn measure(
    mesh: &TriMesh,
    chamfer_samples: usize,
    seed: u64,
    tol: f64,
    max_evaluations: usize,
) -> Result<Measured, StudyError> {
    if mesh.triangles.is_empty() {
        let nan = f64::NAN;
        return Ok(Measured { hausdorff_lo: nan, hausdorff_hi: nan, chamfer: nan, triangles: 0, watertight: false });
    }
    let oracle = MeshOracle::from_mesh(mesh, &occupancy::Config::default())
        .map_err(|e| StudyError::Run(format!("distance oracle: {e}")))?;
    let h = metrics::hausdorff_sphere_certified_limited(mesh, &SPHERE, tol, max_evaluations)
        .map_err(|e| StudyError::Run(format!("Hausdorff distance: {e}")))?;
    let chamfer = sphere_chamfer(mesh, &oracle, chamfer_samples, seed)?;
    let report = mesh_io::TopologyReport::of(mesh);
    Ok(Measured {
        hausdorff_lo: h.lo,
        hausdorff_hi: h.hi,
        chamfer,
        triangles: mesh.triangles.len(),
        watertight: report.is_closed && report.is_manifold,
    })
}
