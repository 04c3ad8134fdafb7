//! A fast, accurate `atan2` for the solid-angle sums.
//!
//! `f64::atan2` (the platform libm, correctly rounded in glibc) takes about half the time
//! of a Van Oosterom–Strackee solid angle. This version uses the range reduction and
//! rational approximation of Cephes' `atan` (S. L. Moshier, *Methods and Programs for
//! Mathematical Functions*, 1989), accurate to a few units in the last place; tests
//! compare it with `f64::atan2` over all octants and special values.

// The coefficients are quoted with the digits Cephes publishes, more than f64 holds.
#![allow(clippy::excessive_precision)]

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

const P: [f64; 5] = [
    -8.750_608_600_031_904_122_785E-1,
    -1.615_753_718_733_365_076_637E1,
    -7.500_855_792_314_704_667_340E1,
    -1.228_866_684_490_136_173_410E2,
    -6.485_021_904_942_025_371_773E1,
];
const Q: [f64; 5] = [
    2.485_846_490_142_306_297_962E1,
    1.650_270_098_316_988_542_046E2,
    4.328_810_604_912_902_668_951E2,
    4.853_903_996_359_136_964_868E2,
    1.945_506_571_482_613_964_425E2,
];
/// tan(3π/8).
const T3P8: f64 = 2.414_213_562_373_095_048_80;
/// Low bits of π/2 beyond f64 (π/2 − FRAC_PI_2).
const MOREBITS: f64 = 6.123_233_995_736_765_886_130E-17;

/// atan(ay / ax) for finite `ay ≥ 0` and `ax > 0`. Cephes' three ranges (t ≤ 0.66,
/// 0.66 < t ≤ tan(3π/8), beyond) are told apart by comparing `ay` with multiples of `ax`,
/// and the reduced argument (t, (t − 1)/(t + 1) or −1/t) is formed from `ay` and `ax` with
/// one division instead of two (t itself is never rounded). Every range is computed by the
/// same expressions and the result selected, so [`atan2_lanes`] vectorises this code and
/// agrees with [`atan2`] bit for bit (tested).
#[inline(always)]
fn atan_ratio(ay: f64, ax: f64) -> f64 {
    let big = ay > T3P8 * ax;
    let small = ay <= 0.66 * ax;
    let (num, den, base, more) = if big {
        (-ax, ay, FRAC_PI_2, MOREBITS)
    } else if small {
        (ay, ax, 0.0, 0.0)
    } else {
        (ay - ax, ay + ax, FRAC_PI_4, 0.5 * MOREBITS)
    };
    atan_reduced(num / den, base, more)
}

/// `base + atan(x)` for a reduced argument `|x| ≤ 0.66` (`more`: low bits of `base`).
#[inline(always)]
fn atan_reduced(x: f64, base: f64, more: f64) -> f64 {
    let z = x * x;
    let p = (((P[0] * z + P[1]) * z + P[2]) * z + P[3]) * z + P[4];
    let q = ((((z + Q[0]) * z + Q[1]) * z + Q[2]) * z + Q[3]) * z + Q[4];
    let r = x * (z * p / q) + x;
    base + (r + more)
}

/// `atan2(y, x)` in (−π, π], agreeing with `f64::atan2` to a few ulps for finite
/// arguments (and exactly on the axes, including signed zeros of `y`).
#[inline(always)]
pub fn atan2(y: f64, x: f64) -> f64 {
    if needs_libm(y, x) {
        return y.atan2(x);
    }
    atan2_regular(y, x)
}

/// Arguments outside [`atan2_regular`]'s domain: a zero or non-finite `x`, a non-finite `y`.
#[inline(always)]
fn needs_libm(y: f64, x: f64) -> bool {
    !(x.is_finite() && y.is_finite()) || x == 0.0
}

/// `atan2(y, x)` for finite `y` and finite non-zero `x`.
#[inline(always)]
fn atan2_regular(y: f64, x: f64) -> f64 {
    let a = atan_ratio(y.abs(), x.abs());
    let a = if x < 0.0 { PI - a } else { a };
    if y.is_sign_negative() {
        -a
    } else {
        a
    }
}

/// [`atan2`] of `N` pairs at once, bit-identical to calling it on each pair (both run
/// [`atan2_regular`], whose ranges are selected, not branched, so the loop vectorises).
/// Lanes outside its domain ([`needs_libm`]) are recomputed one by one with [`atan2`].
#[inline(always)]
pub fn atan2_lanes<const N: usize>(y: &[f64; N], x: &[f64; N]) -> [f64; N] {
    let mut out = [0.0; N];
    let mut special = false;
    for i in 0..N {
        special |= needs_libm(y[i], x[i]);
        out[i] = atan2_regular(y[i], x[i]);
    }
    if special {
        for i in 0..N {
            if needs_libm(y[i], x[i]) {
                out[i] = atan2(y[i], x[i]);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lanes_equal_one_at_a_time_bit_for_bit() {
        let mut state = 987654321u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 4.0
        };
        let specials = [0.0, -0.0, 1.0, -1.0, 0.66, T3P8, f64::INFINITY, f64::NAN, 1e-300, 1e300];
        for round in 0..20_000 {
            let mut y = [0.0; 8];
            let mut x = [0.0; 8];
            for i in 0..8 {
                let scale = 10f64.powi((round + i) as i32 % 13 - 6);
                y[i] = next() * scale;
                x[i] = next();
                if round % 7 == 0 && i % 3 == 0 {
                    x[i] = specials[(round / 7 + i) % specials.len()];
                }
                if round % 11 == 0 && i % 4 == 1 {
                    y[i] = specials[(round / 11 + i) % specials.len()];
                }
            }
            let lanes = atan2_lanes(&y, &x);
            for i in 0..8 {
                let one = atan2(y[i], x[i]);
                assert!(
                    lanes[i].to_bits() == one.to_bits() || (lanes[i].is_nan() && one.is_nan()),
                    "{} {}",
                    y[i],
                    x[i]
                );
            }
        }
    }

    #[test]
    fn agrees_with_libm_everywhere() {
        let mut max_err: f64 = 0.0;
        let mut state = 12345u64;
        for i in 0..2_000_000u64 {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            let a = ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 4.0;
            let b = (((state.rotate_left(29)) >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 4.0;
            let scale = 10f64.powi((i % 13) as i32 - 6);
            let (y, x) = (a * scale, b);
            let want = y.atan2(x);
            let got = atan2(y, x);
            max_err = max_err.max((got - want).abs() / want.abs().max(1e-300));
        }
        assert!(max_err < 1e-15, "max relative error {max_err:e}");
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, 0.0),
            (1.0, 1.0),
            (1e-300, -1.0),
            (1e300, 1e-300),
        ] {
            assert!((atan2(y, x) - f64::atan2(y, x)).abs() <= 4.0 * f64::EPSILON, "{y} {x}");
        }
    }
}
