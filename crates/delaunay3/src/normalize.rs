//! Input checking and exact power-of-two normalisation.
//!
//! Shewchuk's adaptive predicates (and the crate's stage-A filters in front of them) are
//! exact as long as no intermediate product overflows or underflows. Multiplying every
//! coordinate by the same power of two `2^k` is exact in binary floating point and
//! preserves the sign of every orientation and in-sphere determinant (they are
//! homogeneous of degree 3 and 5 in the coordinates, and `2^k > 0`). So the input is
//! rescaled into [`SafeRange`] once, at the entry, and only inputs whose *spread* cannot
//! fit are rejected.

use crate::error::DelaunayError;
use crate::fp::{exponent, Point};

/// The range the predicates run in, after scaling by `2^k`.
///
/// Every nonzero scaled |coordinate| lies in `[2^MIN_EXP, 2^(MAX_EXP+1))`.
///
/// Justification. Every f64 of magnitude ≥ `2^MIN_EXP` is an integer multiple of
/// `u = 2^(MIN_EXP−52) = 2^-162`, and so are all differences, sums and roundings the
/// predicates form from them; a nonzero product of degree ≤ 5 (the in-sphere degree)
/// of such values is then ≥ `u^5 = 2^-810`, and the smallest error-bound terms
/// (≈ ε² · that ≈ 2^-916) stay far above the subnormal threshold `2^-1022`: no
/// underflow. At the top, coordinates (and the auxiliary off-plane point of the
/// coplanar in-circle test, at most `2^(MAX_EXP+2)`) are below `2^191`; a degree-5 term
/// is below `2^955` and the sums in Shewchuk's exact in-sphere stay below `2^970`
/// (Dekker splitting multiplies degree-4 terms by `2^27 + 1`, still below `2^800`): no
/// overflow.
///
/// Consequently the accepted inputs are: all coordinates finite, and
/// `floor(log2 max|x|) − floor(log2 min_{x≠0}|x|) ≤ MAX_SPAN_BITS = 299`, i.e. a ratio
/// below about `2^300 ≈ 2e90` between the largest and the smallest nonzero
/// |coordinate|. Absolute magnitudes are free (subnormals to `f64::MAX`): sets scaled by
/// 1e-300 or 1e300 are handled exactly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SafeRange;

impl SafeRange {
    /// Binary exponent of the smallest allowed nonzero scaled |coordinate|.
    pub const MIN_EXP: i32 = -110;
    /// Scaled |coordinates| are below `2^(MAX_EXP + 1)`.
    pub const MAX_EXP: i32 = 189;
    /// Largest accepted `floor(log2 max) − floor(log2 min nonzero)`.
    pub const MAX_SPAN_BITS: i32 = Self::MAX_EXP - Self::MIN_EXP;
}

/// Multiply by `2^k` exactly (two steps so that `2^k` itself need not be representable;
/// both factors move the value the same way, so no intermediate under/overflows when
/// the result is in range).
pub(crate) fn scale_pow2(x: f64, k: i32) -> f64 {
    let k1 = k / 2;
    let k2 = k - k1;
    x * pow2(k1) * pow2(k2)
}

fn pow2(k: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&k));
    f64::from_bits(((k + 1023) as u64) << 52)
}

/// The checked, scaled copy of the input.
pub(crate) struct Normalized {
    /// #N×3 f64: input points times `2^scale_exp`, `-0.0` replaced by `0.0`.
    pub points: Vec<Point>,
    /// The exponent `k` of the scaling `2^k`.
    pub scale_exp: i32,
    /// A power of two strictly larger than every scaled |coordinate|.
    pub far: f64,
}

/// Check every coordinate once and scale into [`SafeRange`].
///
/// `points`: #N×3 f64, any frame. Errors: [`DelaunayError::NonFinite`],
/// [`DelaunayError::RangeTooWide`].
pub(crate) fn normalize(points: &[[f64; 3]]) -> Result<Normalized, DelaunayError> {
    let mut emin = i32::MAX;
    let mut emax = i32::MIN;
    let (mut imin, mut imax) = (0usize, 0usize);
    for (i, p) in points.iter().enumerate() {
        for &x in p {
            if !x.is_finite() {
                return Err(DelaunayError::NonFinite { index: i, coords: *p });
            }
            if x != 0.0 {
                let e = exponent(x);
                if e < emin {
                    emin = e;
                    imin = i;
                }
                if e > emax {
                    emax = e;
                    imax = i;
                }
            }
        }
    }
    if emax == i32::MIN {
        // All coordinates are zero (or no points): nothing to scale; the degeneracy is
        // reported by the caller.
        return Ok(Normalized { points: points.iter().map(|p| p.map(|x| x + 0.0)).collect(), scale_exp: 0, far: 1.0 });
    }
    let lo = SafeRange::MIN_EXP - emin;
    let hi = SafeRange::MAX_EXP - emax;
    if lo > hi {
        let min_abs = points[imin].iter().map(|x| x.abs()).filter(|&x| x != 0.0).fold(f64::INFINITY, f64::min);
        let max_abs = points[imax].iter().map(|x| x.abs()).fold(0.0, f64::max);
        return Err(DelaunayError::RangeTooWide {
            min_abs,
            min_index: imin,
            max_abs,
            max_index: imax,
            span_bits: emax - emin,
            max_span_bits: SafeRange::MAX_SPAN_BITS,
        });
    }
    let k = 0i32.clamp(lo, hi);
    let scaled: Vec<Point> = if k == 0 {
        points.iter().map(|p| p.map(|x| x + 0.0)).collect()
    } else {
        points.iter().map(|p| p.map(|x| scale_pow2(x, k) + 0.0)).collect()
    };
    Ok(Normalized { points: scaled, scale_exp: k, far: pow2(emax + k + 1) })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scaling_is_exact_and_reversible() {
        for &x in &[1e-300, 5e-324, 1e300, 3.0, -7.25e-200] {
            let k = SafeRange::MIN_EXP - exponent(x);
            let y = scale_pow2(x, k);
            assert_eq!(scale_pow2(y, -k), x);
            assert_eq!(exponent(y), SafeRange::MIN_EXP);
        }
    }

    #[test]
    fn rejects_nan_inf_and_too_wide() {
        assert!(matches!(normalize(&[[0.0, f64::NAN, 0.0]]), Err(DelaunayError::NonFinite { index: 0, .. })));
        assert!(matches!(
            normalize(&[[1.0, 0.0, 0.0], [f64::NEG_INFINITY, 0.0, 0.0]]),
            Err(DelaunayError::NonFinite { index: 1, .. })
        ));
        let e = normalize(&[[1e-200, 0.0, 0.0], [1e200, 0.0, 0.0]]);
        assert!(matches!(e, Err(DelaunayError::RangeTooWide { .. })));
        // A wide but acceptable spread.
        let n = normalize(&[[1e-30, 0.0, 0.0], [1e40, 0.0, 0.0]]).unwrap();
        assert_eq!(n.scale_exp, 0);
        let n = normalize(&[[1e-150, 0.0, 0.0], [2e-150, 0.0, 0.0]]).unwrap();
        assert!(n.scale_exp > 0);
        assert!(n.points.iter().all(|p| p[0] < n.far));
    }
}
