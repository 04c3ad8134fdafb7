//! Volumetric IoU by generalized winding numbers.
//!
//! `n` points uniform in the union of the two meshes' bounding boxes (seeded,
//! [`occupancy::sample::uniform_in_box`]); a point is inside a mesh when its fast winding
//! number (Barill et al. 2018 with the exact fallback near ±0.5, [`occupancy::MeshOracle`])
//! has magnitude at least 0.5 (the workspace's one rule,
//! [`occupancy::Config::is_inside_winding`]), which is meaningful for open meshes, soups
//! and inward-facing closed bodies too. IoU = |inside
//! both| / |inside either|; `None` when no sample is inside either mesh.
//!
//! The labels come from [`MeshOracle::inside`], which needs no winding number's value: on
//! a closed mesh it counts the signed crossings of a segment to the outside (every decision
//! an exact `orient3d`), elsewhere it is the fast winding number with the exact band. A
//! crust is always closed, and so are most inputs, so both meshes usually take the
//! crossing path (the Menger sponge's labels 6.5× faster; docs/performance.md, *Inside/outside labels*).

use mesh_io::TriMesh;
use occupancy::{Config, MeshOracle};
use serde::Serialize;

use crate::MetricsError;

/// Result of [`volumetric_iou`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct IouResult {
    /// Intersection over union, `None` if no sample is inside either mesh.
    pub iou: Option<f64>,
    /// Samples drawn.
    pub num_samples: usize,
    /// Samples inside the reference.
    pub inside_reference: usize,
    /// Samples inside the prediction.
    pub inside_prediction: usize,
    /// Samples inside both.
    pub inside_both: usize,
}

/// Volumetric IoU of two meshes (see the module doc).
///
/// # Errors
/// The mesh checks of [`crate::check_mesh`]; [`MetricsError::BadOption`] for `n == 0`.
pub fn volumetric_iou(
    reference: &TriMesh,
    prediction: &TriMesh,
    n: usize,
    seed: u64,
) -> Result<IouResult, MetricsError> {
    crate::check_mesh(reference, "reference")?;
    crate::check_mesh(prediction, "prediction")?;
    if n == 0 {
        return Err(MetricsError::BadOption("the number of IoU samples must be > 0".into()));
    }
    let (ra, pa) = rayon::join(
        || MeshOracle::from_mesh(reference, &Config::default()),
        || MeshOracle::from_mesh(prediction, &Config::default()),
    );
    let (ra, pa) = (ra?, pa?);
    let (l1, h1) = ra.bounding_box();
    let (l2, h2) = pa.bounding_box();
    let lo = [0, 1, 2].map(|k| l1[k].min(l2[k]));
    let hi = [0, 1, 2].map(|k| h1[k].max(h2[k]));
    let pts = occupancy::sample::uniform_in_box(lo, hi, n, seed)?;
    let (lr, lp) = rayon::join(|| ra.inside(&pts), || pa.inside(&pts));
    let (lr, lp) = (lr?, lp?);
    Ok(iou_of_labels(&lr, &lp))
}

/// IoU of two labellings of the same samples (`reference[i]`, `prediction[i]`: whether
/// sample i is inside each solid), for solids other than a mesh's winding-number solid.
pub fn iou_of_labels(reference: &[bool], prediction: &[bool]) -> IouResult {
    let (mut a, mut b, mut both) = (0, 0, 0);
    for (&ia, &ib) in reference.iter().zip(prediction) {
        a += ia as usize;
        b += ib as usize;
        both += (ia && ib) as usize;
    }
    let union = a + b - both;
    IouResult {
        iou: if union > 0 { Some(both as f64 / union as f64) } else { None },
        num_samples: reference.len().min(prediction.len()),
        inside_reference: a,
        inside_prediction: b,
        inside_both: both,
    }
}
