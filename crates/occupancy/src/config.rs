//! Thresholds and build choices, in one documented place.

use crate::OccupancyError;

/// Largest accepted magnitude of any vertex or query coordinate.
///
/// Solid angles multiply three coordinate differences (a determinant), so coordinates up to
/// 1e100 keep every intermediate product below 1e301 < `f64::MAX`.
pub const MAX_COORDINATE: f64 = 1e100;

/// Which obvhs build preset to use for the triangle BVH.
///
/// All presets are built *without* spatial splits (obvhs' `slow` and `very_slow` presets
/// split triangles, which would count a triangle in two leaves and break winding sums).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BvhPreset {
    /// `BvhBuildParams::very_fast_build()`.
    VeryFast,
    /// `BvhBuildParams::fast_build()`.
    Fast,
    /// `BvhBuildParams::medium_build()` (default: best trees without splits).
    #[default]
    Medium,
}

/// Thresholds of the oracle. Every field has a unit and a meaning; [`Config::default`] holds
/// the measured choices.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// Accuracy parameter β of the fast winding number (Barill et al. 2018, §4): a BVH node
    /// whose bounding ball has radius `R` (around its area-weighted centroid) is replaced by
    /// its order-2 Taylor expansion when the query is farther than `β·R` from that centroid.
    /// Unitless, must be > 1. libigl's default is 2; measured here on the query
    /// sets (bunny, teapot, 20,480-face icosphere), 2 gives max errors up to 7e-3, 3 about
    /// 1.2e-3 and 3.5 about 6e-4 (see the crate README), so the default is 3.5.
    pub beta: f64,
    /// Exact fallback band of the fast winding number, in winding units (unitless). A query
    /// whose fast value `w` satisfies `||w| − occupancy_threshold| < exact_fallback_margin`
    /// (either side of either threshold ±`occupancy_threshold`) is recomputed exactly, so that the inside/outside decision never depends on the
    /// approximation as long as its error is below this margin (measured errors are below
    /// 1e-3; the margin leaves a factor of 20). Such points are rare (closed meshes have
    /// winding numbers near 0 or 1 almost everywhere) so this costs little. 0 disables it.
    pub exact_fallback_margin: f64,
    /// |Winding number| at or above which a point counts as inside (unitless), the one rule
    /// of the workspace ([`Config::is_inside_winding`]). 0.5 is the usual choice for
    /// generalized winding numbers (Jacobson et al. 2013); the absolute value makes a
    /// closed body whose triangles all face inward (mirrored exports) count as solid, like
    /// one facing outward. Must be in (0, 1].
    pub occupancy_threshold: f64,
    /// Relative padding of node boxes for the exact hierarchical winding number, as a
    /// fraction of the mesh bounding-box diagonal (unitless). The boundary-cap shortcut is
    /// only taken when the query lies outside the node box grown by this amount, keeping
    /// the query well away from the cap triangles.
    pub cap_box_padding: f64,
    /// obvhs build preset for the BVH.
    pub bvh_preset: BvhPreset,
    /// Largest number of triangles in one leaf of the closest-point and crossing-count
    /// traversals (1..=255; obvhs' preset default is 8). They stop at the first node of
    /// the tree with at most this many triangles.
    pub max_leaf_size: u32,
    /// Largest number of triangles in one leaf of the tree the winding numbers walk
    /// (obvhs' `max_prims_per_leaf`, 1..=255; the tree is built with the smaller of this
    /// and `max_leaf_size`). Smaller leaves let the fast winding number expand more and
    /// sum fewer exact solid angles near the query: one thread, 400k issue queries, AVX-512,
    /// 8 → 2 takes the icosphere from 1.33 to 1.16 µs/query and the bunny from 1.33 to 1.14
    /// (`--example profile`), with the exact winding number unchanged (12.4 / 12.2 µs)
    /// and the closest points unaffected (they keep `max_leaf_size` leaves). 1 is slower
    /// than 2. Costs memory: about 1.2 nodes per triangle instead of 0.4 (232 bytes of
    /// expansion each).
    pub winding_leaf_size: u32,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            beta: 3.5,
            exact_fallback_margin: 0.02,
            occupancy_threshold: 0.5,
            cap_box_padding: 1e-9,
            bvh_preset: BvhPreset::Medium,
            max_leaf_size: 8,
            winding_leaf_size: 2,
        }
    }
}

impl Config {
    /// The workspace's one inside/outside rule: a point with generalized winding number
    /// `w` is inside when |w| ≥ `occupancy_threshold`. Sampling, training labels,
    /// evaluation, IoU and `voronoi-fit query` all decide through this function (with
    /// [`crate::MeshOracle::is_inside`] guarding the fast path on both sides of ±threshold).
    #[inline]
    pub fn is_inside_winding(&self, w: f64) -> bool {
        w.abs() >= self.occupancy_threshold
    }

    /// Whether a fast winding number `w` is too close to ±`occupancy_threshold` to decide
    /// inside/outside from the approximation: then it is recomputed exactly.
    #[inline]
    pub fn needs_exact_fallback(&self, w: f64) -> bool {
        (w.abs() - self.occupancy_threshold).abs() < self.exact_fallback_margin
    }

    /// Checks every field is in its documented range.
    ///
    /// # Errors
    /// [`OccupancyError::BadConfig`] naming the field.
    pub fn validate(&self) -> Result<(), OccupancyError> {
        if !(self.beta.is_finite() && self.beta > 1.0) {
            return Err(OccupancyError::BadConfig(format!(
                "beta = {} must be a finite number > 1 (2 is libigl's default, 3 this crate's)",
                self.beta
            )));
        }
        if !(self.exact_fallback_margin.is_finite() && self.exact_fallback_margin >= 0.0) {
            return Err(OccupancyError::BadConfig(format!(
                "exact_fallback_margin = {} must be finite and >= 0",
                self.exact_fallback_margin
            )));
        }
        if !(self.occupancy_threshold > 0.0 && self.occupancy_threshold <= 1.0) {
            return Err(OccupancyError::BadConfig(format!(
                "occupancy_threshold = {} must be in (0, 1]",
                self.occupancy_threshold
            )));
        }
        if !(self.cap_box_padding.is_finite() && self.cap_box_padding >= 0.0) {
            return Err(OccupancyError::BadConfig(format!(
                "cap_box_padding = {} must be finite and >= 0",
                self.cap_box_padding
            )));
        }
        if !(1..=255).contains(&self.max_leaf_size) {
            return Err(OccupancyError::BadConfig(format!(
                "max_leaf_size = {} must be in 1..=255",
                self.max_leaf_size
            )));
        }
        if !(1..=255).contains(&self.winding_leaf_size) {
            return Err(OccupancyError::BadConfig(format!(
                "winding_leaf_size = {} must be in 1..=255",
                self.winding_leaf_size
            )));
        }
        Ok(())
    }
}
