//! Everything at once: the report of `voronoi-fit eval` and of the main job.

use std::time::Instant;

use mesh_io::TriMesh;
use serde::Serialize;

use crate::boundary::{solid_boundary, solid_boundary_with, SolidBoundary};
use crate::hausdorff::{certify, CertifiedOptions, DistanceMesh, HausdorffInterval, Sides};
use crate::iou::{volumetric_iou, IouResult};
use crate::surface::{surface_metrics_of, SurfaceMetrics, SurfaceOptions};
use crate::validity::{validity, Validity};
use crate::MetricsError;

/// Options of [`evaluate`].
#[derive(Clone, Debug, PartialEq, Default)]
pub struct EvalOptions {
    /// Certified Hausdorff options (`all_vertices` is always set: the report includes the
    /// libigl-compatible value).
    pub hausdorff: CertifiedOptions,
    /// Surface sampling options (Chamfer, F-score, normal consistency).
    pub surface: SurfaceOptions,
    /// Uniform samples for the volumetric IoU (default 100,000; 0 skips the IoU).
    pub iou_samples: Option<usize>,
    /// Skip the exact self-intersection test of the prediction (for huge meshes).
    pub skip_validity: bool,
}

/// The report (JSON layout `format_version` 1; fields are only ever added).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EvalReport {
    /// Version of this report's JSON layout.
    pub format_version: u32,
    /// libigl-compatible Hausdorff distance (vertices only; a lower bound), mesh units.
    pub hausdorff_libigl: f64,
    /// Certified interval of the Hausdorff distance between the surfaces.
    pub hausdorff: HausdorffInterval,
    /// Chamfer, F-score, normal consistency.
    pub surface: SurfaceMetrics,
    /// Volumetric IoU (`None` when skipped).
    pub iou: Option<IouResult>,
    /// Validity of the prediction (`None` when skipped).
    pub prediction_validity: Option<Validity>,
    /// Distances to the part of the reference that bounds its solid, interior faces left
    /// out ([`crate::boundary`]): what a closed surface can reach on CAD unions.
    pub solid_boundary: SolidBoundary,
    /// Bounding-box diagonal of the reference, mesh units.
    pub reference_diagonal: f64,
    /// Wall time, seconds.
    pub seconds: f64,
}

/// Evaluates `prediction` against `reference`: libigl-compatible and certified Hausdorff,
/// Chamfer L1/L2, F-score, normal consistency, volumetric IoU, the prediction's validity
/// and the distances to the reference's solid boundary.
///
/// # Errors
/// [`MetricsError`] for an empty, non-finite or out-of-range mesh (named "reference" or
/// "prediction"), a mesh without area, or an invalid option.
pub fn evaluate(reference: &TriMesh, prediction: &TriMesh, opts: &EvalOptions) -> Result<EvalReport, MetricsError> {
    evaluate_inner(reference, prediction, opts, None::<(&str, fn(&[[f64; 3]], &[[f64; 3]]) -> _)>)
}

/// [`evaluate`] with the reference's interior faces told apart by another solid
/// ([`solid_boundary_with`]'s `interior`: a name, and whether each surface sample with its
/// unit normal is buried in it).
///
/// # Errors
/// As [`evaluate`], and whatever `interior` returns.
pub fn evaluate_with<F>(
    reference: &TriMesh,
    prediction: &TriMesh,
    opts: &EvalOptions,
    interior: (&str, F),
) -> Result<EvalReport, MetricsError>
where
    F: FnOnce(&[[f64; 3]], &[[f64; 3]]) -> Result<Vec<bool>, MetricsError>,
{
    evaluate_inner(reference, prediction, opts, Some(interior))
}

fn evaluate_inner<F>(
    reference: &TriMesh,
    prediction: &TriMesh,
    opts: &EvalOptions,
    interior: Option<(&str, F)>,
) -> Result<EvalReport, MetricsError>
where
    F: FnOnce(&[[f64; 3]], &[[f64; 3]]) -> Result<Vec<bool>, MetricsError>,
{
    let t0 = Instant::now();
    let (r, p) =
        rayon::join(|| DistanceMesh::new(reference, "reference"), || DistanceMesh::new(prediction, "prediction"));
    let (r, p) = (r?, p?);
    let t_h = Instant::now();
    // Every vertex exactly: the report carries the libigl value, and the certified lower
    // bound is then at least it.
    let hopts = CertifiedOptions { all_vertices: true, ..opts.hausdorff.clone() };
    let mut hausdorff = certify(&r, &p, Sides::Both, &hopts)?;
    hausdorff.seconds = t_h.elapsed().as_secs_f64();
    let surface = surface_metrics_of(&r, &p, &opts.surface)?;
    let n_iou = opts.iou_samples.unwrap_or(100_000);
    let iou = if n_iou > 0 {
        Some(volumetric_iou(reference, prediction, n_iou, opts.surface.seed.wrapping_add(2))?)
    } else {
        None
    };
    let (n, seed, witness) =
        (opts.surface.num_samples, opts.surface.seed.wrapping_add(3), hausdorff.directed_witness[1]);
    let boundary = match interior {
        Some(interior) => solid_boundary_with(&r, &p, n, seed, witness, interior)?,
        None => solid_boundary(&r, &p, n, seed, witness)?,
    };
    let prediction_validity = (!opts.skip_validity).then(|| validity(prediction));
    Ok(EvalReport {
        format_version: 1,
        hausdorff_libigl: hausdorff.libigl.unwrap_or(f64::NAN),
        hausdorff,
        surface,
        iou,
        prediction_validity,
        solid_boundary: boundary,
        reference_diagonal: reference.diagonal(),
        seconds: t0.elapsed().as_secs_f64(),
    })
}
