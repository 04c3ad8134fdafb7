//! Signed solid angle of one triangle seen from a point.

use vf_common::vec3::{dot, norm, V3};

/// Signed solid angle Ω (steradians) subtended by triangle `(a, b, c)` at the point `q`,
/// by the formula of Van Oosterom and Strackee (1983), "The solid angle of a plane
/// triangle", IEEE Trans. Biomed. Eng. 30(2):
///
/// `tan(Ω/2) = det[a−q, b−q, c−q] / (|a||b||c| + (a·b)|c| + (b·c)|a| + (c·a)|b|)`
/// (with `a` standing for `a−q` etc.), evaluated with `atan2` so Ω ∈ (−2π, 2π].
///
/// - `q`, `a`, `b`, `c`: points in the mesh frame, f64.
/// - returns: Ω in steradians; positive when the triangle is counter-clockwise seen from
///   `q`'s side opposite its normal, i.e. a point inside a closed mesh whose triangles are
///   counter-clockwise seen from outside sums to +4π. Matches `igl::solid_angle` (which
///   returns Ω/4π) operation by operation.
#[inline(always)]
pub fn solid_angle(q: V3, a: V3, b: V3, c: V3) -> f64 {
    let (det, denom) = tangent_parts(q, a, b, c);
    2.0 * super::atan::atan2(det, denom)
}

/// Numerator and denominator of `tan(Ω/2)` in [`solid_angle`] (shared with
/// [`solid_angle_lanes`], so the two agree bit for bit).
#[inline(always)]
fn tangent_parts(q: V3, a: V3, b: V3, c: V3) -> (f64, f64) {
    let va = [a[0] - q[0], a[1] - q[1], a[2] - q[2]];
    let vb = [b[0] - q[0], b[1] - q[1], b[2] - q[2]];
    let vc = [c[0] - q[0], c[1] - q[1], c[2] - q[2]];
    let la = norm(va);
    let lb = norm(vb);
    let lc = norm(vc);
    // Same expansion of the determinant as libigl's solid_angle.cpp.
    let det = va[0] * vb[1] * vc[2] + vb[0] * vc[1] * va[2] + vc[0] * va[1] * vb[2]
        - vc[0] * vb[1] * va[2]
        - vb[0] * va[1] * vc[2]
        - va[0] * vc[1] * vb[2];
    let denom = la * lb * lc + dot(vb, vc) * la + dot(vc, va) * lb + dot(va, vb) * lc;
    (det, denom)
}

/// [`solid_angle`] of one triangle seen from `N` points `(qx[i], qy[i], qz[i])` at once,
/// bit-identical to calling it for each point (same operations in the same order; the
/// `atan2` is [`super::atan::atan2_lanes`]), written lane by lane so it vectorises.
#[inline(always)]
pub fn solid_angle_lanes<const N: usize>(qx: &[f64; N], qy: &[f64; N], qz: &[f64; N], a: V3, b: V3, c: V3) -> [f64; N] {
    let mut det = [0.0; N];
    let mut denom = [0.0; N];
    for i in 0..N {
        (det[i], denom[i]) = tangent_parts([qx[i], qy[i], qz[i]], a, b, c);
    }
    let mut out = super::atan::atan2_lanes(&det, &denom);
    for o in &mut out {
        *o *= 2.0;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn lanes_equal_one_at_a_time_bit_for_bit() {
        let tri = [[0.1, -0.2, 0.05], [1.0, 0.3, -0.1], [-0.2, 0.9, 0.4]];
        let mut state = 42u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.0
        };
        for round in 0..5_000 {
            let mut q = [[0.0; 3]; 8];
            for p in &mut q {
                *p = [next(), next(), next()];
            }
            if round % 5 == 0 {
                // A corner (a zero length) and the centroid (on the triangle: det = 0).
                q[round % 8] = tri[round % 3];
                q[(round + 3) % 8] = std::array::from_fn(|k| (tri[0][k] + tri[1][k] + tri[2][k]) / 3.0);
            }
            let qx = q.map(|p| p[0]);
            let qy = q.map(|p| p[1]);
            let qz = q.map(|p| p[2]);
            let lanes = solid_angle_lanes(&qx, &qy, &qz, tri[0], tri[1], tri[2]);
            for i in 0..8 {
                let one = solid_angle(q[i], tri[0], tri[1], tri[2]);
                assert!(lanes[i].to_bits() == one.to_bits() || (lanes[i].is_nan() && one.is_nan()), "{:?}", q[i]);
            }
        }
    }
    #[test]
    fn octant_triangle_is_one_eighth_of_sphere() {
        // The triangle (e_x, e_y, e_z) seen from the origin covers one octant: 4π/8.
        let w = solid_angle([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert!((w - PI / 2.0).abs() < 1e-15, "{w}");
        // Reversed orientation flips the sign.
        let w = solid_angle([0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]);
        assert!((w + PI / 2.0).abs() < 1e-15, "{w}");
    }

    #[test]
    fn coplanar_point_outside_gives_zero() {
        let w = solid_angle([5.0, 5.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert_eq!(w, 0.0);
    }
}
