//! Sample-based surface metrics: Chamfer L1 and L2, F-score at τ, normal consistency.
//!
//! Both surfaces are sampled uniformly by area ([`occupancy::sample::SurfaceSampler`],
//! seeded and independent of the thread count), and every sample is matched to its exact
//! closest point on the other mesh (BVH query, not a nearest sample), as in the Occupancy
//! Networks evaluation (Mescheder et al. 2019) but with point-to-mesh distances:
//!
//! - accuracy = mean over prediction samples of the distance to the reference, completeness
//!   = mean over reference samples of the distance to the prediction;
//! - Chamfer L1 = (accuracy + completeness) / 2 (mean of Euclidean distances), Chamfer L2 =
//!   the same with squared distances;
//! - precision = share of prediction samples within τ of the reference, recall = share of
//!   reference samples within τ of the prediction, F-score = 2PR / (P + R) (0 when both are
//!   0);
//! - normal consistency = mean over both sample sets of `|n_sample · n_closest|`, the
//!   absolute cosine between the sampled triangle's normal and the normal of the closest
//!   triangle on the other mesh (a degenerate closest triangle counts 0).

use mesh_io::TriMesh;
use occupancy::sample::SurfaceSampler;
use occupancy::Workspace;
use rayon::prelude::*;
use serde::Serialize;

use crate::hausdorff::DistanceMesh;
use crate::MetricsError;

use vf_common::vec3::V3;

/// Options of [`surface_metrics`].
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceOptions {
    /// Samples per surface. Default 100,000.
    pub num_samples: usize,
    /// Seed of the samplers (the reference uses `seed`, the prediction `seed + 1`).
    pub seed: u64,
    /// F-score threshold τ as a fraction of the reference's bounding-box diagonal. Default
    /// 0.003 (0.3%).
    pub fscore_tau_rel: f64,
}

impl Default for SurfaceOptions {
    fn default() -> Self {
        SurfaceOptions { num_samples: 100_000, seed: 0, fscore_tau_rel: 0.003 }
    }
}

/// Sample-based metrics of a prediction against a reference, mesh units.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SurfaceMetrics {
    /// Samples per surface.
    pub num_samples: usize,
    /// Mean distance from prediction samples to the reference.
    pub accuracy: f64,
    /// Mean distance from reference samples to the prediction.
    pub completeness: f64,
    /// (accuracy + completeness) / 2.
    pub chamfer_l1: f64,
    /// Mean of squared distances, both directions averaged, mesh units².
    pub chamfer_l2: f64,
    /// F-score threshold, mesh units.
    pub fscore_tau: f64,
    /// Share of prediction samples within τ of the reference.
    pub precision: f64,
    /// Share of reference samples within τ of the prediction.
    pub recall: f64,
    /// 2PR / (P + R).
    pub fscore: f64,
    /// Mean absolute cosine between sample normals and closest-triangle normals.
    pub normal_consistency: f64,
    /// Largest sampled distance prediction → reference (a lower bound of that one-sided
    /// Hausdorff distance).
    pub max_prediction_to_reference: f64,
    /// Largest sampled distance reference → prediction.
    pub max_reference_to_prediction: f64,
}

fn unit_normals(mesh: &TriMesh) -> Vec<V3> {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let (u, w) = ([0, 1, 2].map(|k| b[k] - a[k]), [0, 1, 2].map(|k| c[k] - a[k]));
            let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                n.map(|x| x / len)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

/// Per-sample (distance, |cos|) of `points` (with `normals`) against `target`.
fn match_samples(target: &DistanceMesh, target_normals: &[V3], points: &[V3], normals: &[V3]) -> Vec<(f64, f64)> {
    let mut out = vec![(0.0, 0.0); points.len()];
    out.par_chunks_mut(1024).enumerate().for_each(|(c, o)| {
        let mut ws = Workspace::new();
        for (j, r) in o.iter_mut().enumerate() {
            let i = c * 1024 + j;
            let cp = target.bvh().closest_point(points[i], &mut ws);
            let n = target_normals[cp.triangle as usize];
            let m = normals[i];
            *r = (cp.squared_distance.sqrt(), (n[0] * m[0] + n[1] * m[1] + n[2] * m[2]).abs().min(1.0));
        }
    });
    out
}

/// Samples `mesh` by area.
fn samples(mesh: &TriMesh, name: &'static str, n: usize, seed: u64) -> Result<(Vec<V3>, Vec<V3>), MetricsError> {
    let sampler = SurfaceSampler::from_mesh(mesh).map_err(|_| {
        let area: f64 = mesh_io::TopologyReport::of(mesh).surface_area;
        MetricsError::ZeroArea { mesh: name, area }
    })?;
    let s = sampler.sample(n, seed);
    Ok((s.points, s.normals))
}

/// Chamfer, F-score and normal consistency of `prediction` against `reference`.
///
/// # Errors
/// [`MetricsError::BadOption`], the mesh checks of [`crate::check_mesh`], and
/// [`MetricsError::ZeroArea`] when a mesh has no area to sample.
pub fn surface_metrics(
    reference: &TriMesh,
    prediction: &TriMesh,
    opts: &SurfaceOptions,
) -> Result<SurfaceMetrics, MetricsError> {
    let r = DistanceMesh::new(reference, "reference")?;
    let p = DistanceMesh::new(prediction, "prediction")?;
    surface_metrics_of(&r, &p, opts)
}

/// [`surface_metrics`] on prepared meshes.
///
/// # Errors
/// As [`surface_metrics`].
pub fn surface_metrics_of(
    r: &DistanceMesh,
    p: &DistanceMesh,
    opts: &SurfaceOptions,
) -> Result<SurfaceMetrics, MetricsError> {
    if opts.num_samples == 0 {
        return Err(MetricsError::BadOption("num_samples must be > 0".into()));
    }
    if !(opts.fscore_tau_rel.is_finite() && opts.fscore_tau_rel > 0.0) {
        return Err(MetricsError::BadOption(format!(
            "fscore_tau_rel = {} must be a finite number > 0",
            opts.fscore_tau_rel
        )));
    }
    let n = opts.num_samples;
    let (rp, rn) = samples(r.mesh(), "reference", n, opts.seed)?;
    let (pp, pn) = samples(p.mesh(), "prediction", n, opts.seed.wrapping_add(1))?;
    let (r_normals, p_normals) = (unit_normals(r.mesh()), unit_normals(p.mesh()));
    let to_ref = match_samples(r, &r_normals, &pp, &pn);
    let to_pred = match_samples(p, &p_normals, &rp, &rn);
    let tau = opts.fscore_tau_rel * r.mesh().diagonal();
    let mean = |v: &[(f64, f64)], f: &dyn Fn(&(f64, f64)) -> f64| v.iter().map(f).sum::<f64>() / v.len() as f64;
    let accuracy = mean(&to_ref, &|x| x.0);
    let completeness = mean(&to_pred, &|x| x.0);
    let l2 = 0.5 * (mean(&to_ref, &|x| x.0 * x.0) + mean(&to_pred, &|x| x.0 * x.0));
    let precision = mean(&to_ref, &|x| (x.0 <= tau) as u8 as f64);
    let recall = mean(&to_pred, &|x| (x.0 <= tau) as u8 as f64);
    let fscore = if precision + recall > 0.0 { 2.0 * precision * recall / (precision + recall) } else { 0.0 };
    let nc = 0.5 * (mean(&to_ref, &|x| x.1) + mean(&to_pred, &|x| x.1));
    let max = |v: &[(f64, f64)]| v.iter().fold(0.0f64, |m, x| m.max(x.0));
    Ok(SurfaceMetrics {
        num_samples: n,
        accuracy,
        completeness,
        chamfer_l1: 0.5 * (accuracy + completeness),
        chamfer_l2: l2,
        fscore_tau: tau,
        precision,
        recall,
        fscore,
        normal_consistency: nc,
        max_prediction_to_reference: max(&to_ref),
        max_reference_to_prediction: max(&to_pred),
    })
}
