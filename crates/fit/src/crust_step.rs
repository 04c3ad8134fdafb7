//! The crust of trained sites, checked, with the retry policy shared by the main job and
//! the sphere study.

use crust::check::{check_crust, CrustCheck};
use crust::{Crust, CrustConfig};
use mesh_io::{TriMesh, UnitCubeTransform};
use vf_common::rng::{ChunkRng, Stream};

use crate::error::FitError;

/// A crust that passed the exact check.
pub struct CheckedCrust {
    /// The crust in the unit cube.
    pub crust: Crust,
    /// The exact check's report (closed, manifold, no self-intersections).
    pub check: CrustCheck,
    /// Jittered retries needed (0 almost always).
    pub retries: usize,
}

impl CheckedCrust {
    /// The crust mapped to the input's frame (orientation kept when the transform
    /// mirrors).
    pub fn in_frame(&self, transform: &UnitCubeTransform) -> TriMesh {
        transform.mesh_from_unit(&self.crust.mesh)
    }
}

/// The checked crust of `sites` (K×3, unit cube) with `labels`.
///
/// The crust is exact for the sites, but its Voronoi vertices are rounded to f64 in the
/// output; where trained sites are nearly cospherical, distinct vertices can round onto
/// each other and the exact checker rejects the mesh. Then the sites are moved by a seeded
/// jitter far below their spacing (1e-9, then 1e-7 of the unit cube, stream
/// [`Stream::CrustJitter`]) and the crust is extracted again; `sites` is updated, so a
/// sites file written from it reproduces the crust.
///
/// # Errors
/// [`FitError::Failure`] with the crust's error, or the check's after two retries.
pub fn crust_of(sites: &mut [[f64; 3]], labels: &[bool], seed: u64) -> Result<CheckedCrust, FitError> {
    let mut retries = 0;
    loop {
        let attempt = Crust::extract(sites, labels, &CrustConfig::default())
            .map_err(|e| FitError::Failure(format!("crust of the trained sites: {e}")))
            .and_then(|c| match check_crust(&c.mesh) {
                Ok(check) => Ok((c, check)),
                Err(e) => Err(FitError::Failure(format!("the crust failed its check ({e}); please report this"))),
            });
        match attempt {
            Ok((crust, check)) => return Ok(CheckedCrust { crust, check, retries }),
            Err(e) if retries >= 2 => return Err(e),
            Err(_) => {
                retries += 1;
                let amplitude = if retries == 1 { 1e-9 } else { 1e-7 };
                let mut rng = ChunkRng::for_chunk(seed, Stream::CrustJitter, retries as u64);
                for p in sites.iter_mut() {
                    for x in p.iter_mut() {
                        *x = (*x + amplitude * (2.0 * rng.uniform() - 1.0)).clamp(1e-9, 1.0 - 1e-9);
                    }
                }
            }
        }
    }
}
