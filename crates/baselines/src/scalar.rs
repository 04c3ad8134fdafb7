//! The float types the decoders run in: `f32` for training and evaluation (what PyTorch
//! uses, and twice the GEMM throughput), `f64` for the finite-difference gradient checks.

use ndarray::LinalgScalar;
use num_traits::Float;

/// `f32` or `f64`.
pub trait Real: Float + LinalgScalar + Send + Sync + std::fmt::Debug + std::fmt::Display + 'static {
    /// Round an `f64` to this type.
    fn of(x: f64) -> Self;
    /// Widen to `f64`.
    fn wide(self) -> f64;
}

impl Real for f32 {
    #[inline]
    fn of(x: f64) -> Self {
        x as f32
    }
    #[inline]
    fn wide(self) -> f64 {
        self as f64
    }
}

impl Real for f64 {
    #[inline]
    fn of(x: f64) -> Self {
        x
    }
    #[inline]
    fn wide(self) -> f64 {
        self
    }
}
