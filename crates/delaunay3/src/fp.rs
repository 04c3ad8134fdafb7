//! f64 building blocks shared by the input normalisation (`normalize`) and the exact
//! predicates (`predicates`): the internal point type and the exact binary exponent of a
//! float. Both depend on this module and neither on the other: the normalisation produces
//! the points the predicates read, and the predicates' integer fast path needs the
//! exponent.

/// A point in the crate's internal (power-of-two scaled) frame: 3 f64.
pub type Point = [f64; 3];

/// floor(log2 |x|) for finite nonzero x, subnormals included.
pub(crate) fn exponent(x: f64) -> i32 {
    let bits = x.abs().to_bits();
    let e = (bits >> 52) as i32;
    if e > 0 {
        e - 1023
    } else {
        let mantissa = bits & ((1u64 << 52) - 1);
        63 - mantissa.leading_zeros() as i32 - 1074
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponent_of_normals_and_subnormals() {
        assert_eq!(exponent(1.0), 0);
        assert_eq!(exponent(1.5), 0);
        assert_eq!(exponent(-3.0), 1);
        assert_eq!(exponent(0.25), -2);
        assert_eq!(exponent(f64::MIN_POSITIVE), -1022);
        assert_eq!(exponent(5e-324), -1074);
        assert_eq!(exponent(f64::MAX), 1023);
    }
}
