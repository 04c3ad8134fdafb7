//! The workspace's small vector vocabulary: f64 helpers on plain `[f64; 3]` ([`V3`]). No
//! SIMD types, and each helper evaluates in one fixed order (written out below), so that
//! results are bit-reproducible wherever they are used.

/// A point or a vector in 3-D.
pub type V3 = [f64; 3];

/// a − b.
#[inline(always)]
pub fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a + b.
#[inline(always)]
pub fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a·s.
#[inline(always)]
pub fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// a · b, summed x, y, z.
#[inline(always)]
pub fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × b.
#[inline(always)]
pub fn cross(a: V3, b: V3) -> V3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// |a|², as [`dot`]`(a, a)`.
#[inline(always)]
pub fn norm_squared(a: V3) -> f64 {
    dot(a, a)
}

/// |a|.
#[inline(always)]
pub fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// a / |a| (not finite for a zero vector).
#[inline(always)]
pub fn normalize(a: V3) -> V3 {
    let l = norm(a);
    a.map(|x| x / l)
}

/// |a − b|², as the sum of the squared coordinate differences.
#[inline(always)]
pub fn distance_squared(a: V3, b: V3) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)
}

/// |a − b|, the square root of [`distance_squared`].
#[inline(always)]
pub fn distance(a: V3, b: V3) -> f64 {
    distance_squared(a, b).sqrt()
}

/// Squared distance from `p` to the axis-aligned box `[lo, hi]` (0 inside).
#[inline(always)]
pub fn box_distance_squared(p: V3, lo: V3, hi: V3) -> f64 {
    let mut d2 = 0.0;
    for k in 0..3 {
        let d = if p[k] < lo[k] {
            lo[k] - p[k]
        } else if p[k] > hi[k] {
            p[k] - hi[k]
        } else {
            0.0
        };
        d2 += d * d;
    }
    d2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_helpers_agree_with_hand_arithmetic() {
        let (a, b) = ([1.0, 2.0, 3.0], [4.0, -5.0, 6.0]);
        assert_eq!(sub(a, b), [-3.0, 7.0, -3.0]);
        assert_eq!(add(a, b), [5.0, -3.0, 9.0]);
        assert_eq!(scale(a, 2.0), [2.0, 4.0, 6.0]);
        assert_eq!(dot(a, b), 12.0);
        assert_eq!(cross(a, b), [27.0, 6.0, -13.0]);
        assert_eq!(norm_squared(a), 14.0);
        assert_eq!(distance_squared(a, b), 67.0);
        assert_eq!(distance(a, b), 67f64.sqrt());
        assert_eq!(normalize([0.0, 3.0, 4.0]), [0.0, 0.6, 0.8]);
        assert_eq!(box_distance_squared([2.0, 0.5, -1.0], [0.0; 3], [1.0; 3]), 2.0);
    }
}
