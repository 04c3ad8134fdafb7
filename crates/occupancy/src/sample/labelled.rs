//! A labelled training set in one call: points uniform in the mesh's padded bounding box
//! and near its surface, each with the generalized winding number, the occupancy by the
//! workspace's one inside rule and the signed distance (what `voronoi-fit sample` writes).

use super::{near_surface, uniform_in_box, SurfaceSampler};
use crate::{MeshOracle, OccupancyError, WindingMode};
use vf_common::vec3::V3;

/// Queries labelled per progress report.
pub const LABEL_CHUNK: usize = 1 << 16;

/// What to draw: `num_samples` points, `uniform_fraction` of them uniform in the bounding
/// box grown by `padding` × its extent on each side, the rest near the surface with
/// Gaussian offsets of `near_sigma` × the box's diagonal (split evenly between them).
#[derive(Clone, Debug, PartialEq)]
pub struct SampleSpec {
    /// Points in all (≥ 1).
    pub num_samples: usize,
    /// Share drawn uniformly in the padded box, in [0, 1].
    pub uniform_fraction: f64,
    /// Growth of the uniform box on each side, as a fraction of its extent per axis (≥ 0).
    pub padding: f64,
    /// Standard deviations of the near-surface offsets, as fractions of the diagonal (≥ 0).
    pub near_sigma: Vec<f64>,
    /// Seed of both samplers; the output depends only on the spec, not on the threads.
    pub seed: u64,
    /// Exact winding numbers instead of the fast approximation (with its exact fallback
    /// near the threshold).
    pub exact: bool,
}

impl SampleSpec {
    /// Checks the ranges above; the message names the field as the CLI's flag does.
    ///
    /// # Errors
    /// [`OccupancyError::BadSampler`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), OccupancyError> {
        let bad = |m: String| Err(OccupancyError::BadSampler(m));
        if self.num_samples == 0 {
            return bad("-n must be at least 1.".into());
        }
        if !(0.0..=1.0).contains(&self.uniform_fraction) {
            return bad(format!("--uniform-fraction {} is outside [0, 1].", self.uniform_fraction));
        }
        if !(self.padding.is_finite() && self.padding >= 0.0) {
            return bad(format!("--padding {} must be finite and >= 0.", self.padding));
        }
        if let Some(s) = self.near_sigma.iter().find(|s| !(s.is_finite() && **s >= 0.0)) {
            return bad(format!("--near-sigma {s} must be finite and >= 0."));
        }
        Ok(())
    }
}

/// The labelled points, in the mesh's frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LabelledSamples {
    /// #N×3 points: the uniform ones first, then the near-surface ones.
    pub points: Vec<V3>,
    /// #N generalized winding numbers.
    pub winding: Vec<f64>,
    /// #N occupancies (1 inside by |w| ≥ the threshold, else 0).
    pub occupancy: Vec<u8>,
    /// #N signed distances, mesh units, negative inside.
    pub sdf: Vec<f64>,
}

/// Draws and labels the points of `spec` for the mesh behind `oracle` (`sampler` samples
/// the same mesh's surface). `progress` is called with the number of points labelled so
/// far, every [`LABEL_CHUNK`] points.
///
/// # Errors
/// [`OccupancyError::BadSampler`] for a spec out of range or a mesh without area to sample
/// near (when near-surface points are asked for); the oracle's errors otherwise.
pub fn labelled_samples(
    oracle: &MeshOracle,
    sampler: impl FnOnce() -> Result<SurfaceSampler, OccupancyError>,
    spec: &SampleSpec,
    progress: &mut dyn FnMut(usize),
) -> Result<LabelledSamples, OccupancyError> {
    spec.validate()?;
    let n = spec.num_samples;
    let num_uniform = ((n as f64) * spec.uniform_fraction).round() as usize;
    let num_near = n - num_uniform;
    let (lo, hi) = oracle.bounding_box();
    let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let mut glo = lo;
    let mut ghi = hi;
    for k in 0..3 {
        let pad = spec.padding * (hi[k] - lo[k]);
        glo[k] -= pad;
        ghi[k] += pad;
    }
    let mut points = uniform_in_box(glo, ghi, num_uniform, spec.seed)?;
    if num_near > 0 {
        let sampler = sampler()?;
        let sigmas: Vec<f64> = spec.near_sigma.iter().map(|s| s * diag).collect();
        points.extend(near_surface(&sampler, num_near, &sigmas, spec.seed)?);
    }
    let mode = if spec.exact { WindingMode::Exact } else { WindingMode::Fast };
    let mut out = LabelledSamples {
        winding: Vec::with_capacity(n),
        occupancy: Vec::with_capacity(n),
        sdf: Vec::with_capacity(n),
        points: Vec::new(),
    };
    for chunk in points.chunks(LABEL_CHUNK) {
        let batch = oracle.query(chunk, mode)?;
        out.winding.extend(batch.winding);
        out.occupancy.extend(batch.occupancy);
        out.sdf.extend(batch.sdf);
        progress(out.winding.len());
    }
    out.points = points;
    Ok(out)
}
