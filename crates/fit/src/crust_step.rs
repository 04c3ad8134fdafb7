//! The crust of trained sites, checked exactly, and the mesh that will be written: mapped
//! to the input's frame and rounded as the output format stores it, checked again.

use crust::check::CrustCheck;
use crust::output::{finalize, Finalized, FrameMap, Precision};
use crust::{Crust, CrustConfig};

use crate::error::FitError;

/// A crust that passed the exact check, and its written form.
pub struct CheckedCrust {
    /// The crust in the unit cube (its `check` is the exact check of extraction).
    pub crust: Crust,
    /// The crust mapped to the input's frame and rounded to the output precision, checked
    /// exactly again after rounding (repaired or refused where rounding broke it).
    pub written: Finalized,
}

impl CheckedCrust {
    /// The exact check of the mesh as written.
    pub fn check(&self) -> &CrustCheck {
        &self.written.check
    }
}

/// The checked crust of `sites` (K×3, unit cube) with `labels`, and its form in the
/// frame `map` takes it to (the input's: its `UnitCubeTransform`) at `precision` (f32 for
/// glTF, f64 for OBJ/PLY).
///
/// Extraction checks its own result exactly and resolves clusters of Voronoi vertices that
/// f64 cannot tell apart (mirrored pairs make many); no site is moved.
///
/// # Errors
/// [`FitError::Crust`] when the crust cannot be extracted; [`FitError::OutputPrecision`]
/// when the rounded output cannot be made valid (coordinates beyond float32, for example).
pub fn crust_of(
    sites: &[[f64; 3]],
    labels: &[bool],
    map: impl Into<FrameMap>,
    precision: Precision,
) -> Result<CheckedCrust, FitError> {
    let crust = Crust::extract(sites, labels, &CrustConfig::default())
        .map_err(|source| FitError::Crust { during: "crust of the trained sites", source })?;
    let written = finalize(&crust, map, precision).map_err(|e| match e {
        crust::CrustError::Internal(_) => FitError::Crust { during: "the crust as written", source: e },
        e => FitError::OutputPrecision(e),
    })?;
    Ok(CheckedCrust { crust, written })
}
