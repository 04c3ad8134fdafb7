//! Generalized winding numbers: exact (hierarchical sum of solid angles) and fast
//! (Barill et al. 2018 order-2 expansion).

pub mod atan;
pub mod crossing;
pub mod exact;
pub mod fast;
pub mod solid_angle;

/// How to evaluate the winding number.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WindingMode {
    /// Sum of exact solid angles (Jacobson et al. 2013), matching `igl.winding_number` to
    /// rounding.
    Exact,
    /// Barill et al. 2018 expansion with accuracy `Config::beta`, recomputed exactly when
    /// within `Config::exact_fallback_margin` of `Config::occupancy_threshold`.
    #[default]
    Fast,
}
