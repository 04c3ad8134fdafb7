//! Exact sign predicates: filtered orientation and in-sphere tests, and their symbolically
//! perturbed versions.
//!
//! Every predicate first evaluates Shewchuk's stage-A floating-point expression with its
//! proven error bound (a semi-static filter inlined here, so the common case costs no
//! call), and only when the sign is uncertain calls the adaptive exact predicates of the
//! `robust` crate (Shewchuk 1997, "Adaptive precision floating-point arithmetic and fast
//! robust geometric predicates", DCG 18:305–363).
//!
//! Both the filter bound and the adaptive arithmetic are exact only when no intermediate
//! value overflows or underflows; [`crate::normalize`] guarantees that by construction
//! (see [`crate::normalize::SafeRange`]).
//!
//! Sign conventions used throughout the crate (they match CGAL's):
//! - [`orient`]`(a, b, c, d)` is the sign of `det[b − a, c − a, d − a]`: positive when the
//!   tetrahedron `abcd` has positive volume (right-handed).
//! - [`insphere`]`(a, b, c, d, e)`, for a positively oriented `abcd`, is positive when `e`
//!   is strictly inside the circumsphere.
//!
//! Degenerate (zero) in-sphere results are resolved by the symbolic perturbation of
//! Edelsbrunner & Mücke 1990 ("Simulation of Simplicity", ACM TOG 9(1):66–104) applied to
//! the lifted coordinate only, as analysed by Devillers & Teillaud 2011 ("Perturbations
//! for Delaunay and weighted Delaunay 3D triangulations", CGTA 44(3):160–168): point `p`
//! is lifted to `|p|² + ε^{rank(p)}` where the rank is the lexicographic (x, y, z) order,
//! larger points receiving the dominant perturbation. The perturbed predicate never
//! returns zero for a non-degenerate tetrahedron and five distinct points, and it makes
//! the triangulation unique: it does not depend on the insertion order.

use robust::Coord3D;
use std::cmp::Ordering;

use crate::fp::exponent;
pub use crate::fp::Point;

const EPSILON: f64 = f64::EPSILON * 0.5; // 2^-53, Shewchuk's epsilon
const O3D_ERRBOUND_A: f64 = (7.0 + 56.0 * EPSILON) * EPSILON;
const ISP_ERRBOUND_A: f64 = (16.0 + 224.0 * EPSILON) * EPSILON;

#[inline(always)]
fn c3(p: &Point) -> Coord3D<f64> {
    Coord3D { x: p[0], y: p[1], z: p[2] }
}

/// Sign (−1, 0, +1) of `det[b − a, c − a, d − a]`: +1 when `abcd` is positively oriented.
///
/// Exact for inputs in the normalised safe range (Shewchuk 1997 stage-A filter, then
/// `robust::orient3d`).
#[inline(always)]
pub fn orient(a: &Point, b: &Point, c: &Point, d: &Point) -> i32 {
    // Shewchuk's orient3d(pa, pb, pc, pd) = det[pa − pd, pb − pd, pc − pd], which is minus
    // det[b − a, c − a, d − a]. We evaluate Shewchuk's expression with (a, b, c, d) and
    // negate the sign.
    let adx = a[0] - d[0];
    let bdx = b[0] - d[0];
    let cdx = c[0] - d[0];
    let ady = a[1] - d[1];
    let bdy = b[1] - d[1];
    let cdy = c[1] - d[1];
    let adz = a[2] - d[2];
    let bdz = b[2] - d[2];
    let cdz = c[2] - d[2];
    let bdxcdy = bdx * cdy;
    let cdxbdy = cdx * bdy;
    let cdxady = cdx * ady;
    let adxcdy = adx * cdy;
    let adxbdy = adx * bdy;
    let bdxady = bdx * ady;
    let det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady);
    let permanent = (bdxcdy.abs() + cdxbdy.abs()) * adz.abs()
        + (cdxady.abs() + adxcdy.abs()) * bdz.abs()
        + (adxbdy.abs() + bdxady.abs()) * cdz.abs();
    let errbound = O3D_ERRBOUND_A * permanent;
    if det > errbound {
        return -1;
    }
    if -det > errbound {
        return 1;
    }
    orient_exact(a, b, c, d)
}

#[cold]
#[inline(never)]
fn orient_exact(a: &Point, b: &Point, c: &Point, d: &Point) -> i32 {
    if let Some([u, v, w]) = small_int_diffs([b, c, d], a) {
        // det[b − a, c − a, d − a] with entries below 2^22: minors below 2^45 (i64),
        // the determinant below 2^69 (i128).
        let m0 = (v[1] * w[2] - v[2] * w[1]) as i128;
        let m1 = (v[0] * w[2] - v[2] * w[0]) as i128;
        let m2 = (v[0] * w[1] - v[1] * w[0]) as i128;
        let det = u[0] as i128 * m0 - u[1] as i128 * m1 + u[2] as i128 * m2;
        return det.signum() as i32;
    }
    let s = robust::orient3d(c3(a), c3(b), c3(c), c3(d));
    -sign(s)
}

/// Fast exact path for the uncertain cases of small-integer-like inputs (lattices,
/// integer points on spheres, grid-snapped data), where Shewchuk's adaptive stages are
/// slow because the determinant is exactly zero.
///
/// Returns the differences `p − o` for the points `p` of `ps` as integers, scaled by a
/// common power of two `2^s`, when every difference is exact in f64 (zero TwoDiff
/// error, Knuth 1969) and every scaled difference is an integer of magnitude below
/// 2^22. Multiplying all differences by `2^s > 0` multiplies a determinant of degree k
/// by `2^(ks) > 0`, so signs are preserved; the integer determinants are then evaluated
/// exactly in i128. `None` otherwise (the caller falls back to `robust`).
#[inline]
fn small_int_diffs<const N: usize>(ps: [&Point; N], o: &Point) -> Option<[[i64; 3]; N]> {
    let mut d = [[0.0f64; 3]; N];
    let mut max = 0.0f64;
    for (k, p) in ps.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (p[i], o[i]);
            let x = a - b;
            let bv = a - x;
            let av = x + bv;
            let tail = (a - av) + (bv - b);
            if tail != 0.0 {
                return None;
            }
            d[k][i] = x;
            max = max.max(x.abs());
        }
    }
    if max == 0.0 {
        return Some([[0; 3]; N]);
    }
    let s = 21 - exponent(max);
    if !(-1000..=1000).contains(&s) {
        return None;
    }
    let scale = f64::from_bits(((s + 1023) as u64) << 52);
    let mut out = [[0i64; 3]; N];
    for k in 0..N {
        for i in 0..3 {
            let v = d[k][i] * scale; // exact: a power of two, result in [2^-1000, 2^22)
                                     // |v| < 2^22, so the cast is exact exactly when v is an integer.
            let n = v as i64;
            if n as f64 != v {
                return None;
            }
            out[k][i] = n;
        }
    }
    Some(out)
}

#[inline(always)]
fn sign(x: f64) -> i32 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Sign of the in-sphere determinant: for a positively oriented `abcd` ([`orient`] > 0),
/// +1 when `e` is strictly inside the circumsphere, −1 strictly outside, 0 cospherical.
/// For a negatively oriented `abcd` the sign is reversed. Unperturbed.
#[inline(always)]
pub fn insphere(a: &Point, b: &Point, c: &Point, d: &Point, e: &Point) -> i32 {
    let aex = a[0] - e[0];
    let bex = b[0] - e[0];
    let cex = c[0] - e[0];
    let dex = d[0] - e[0];
    let aey = a[1] - e[1];
    let bey = b[1] - e[1];
    let cey = c[1] - e[1];
    let dey = d[1] - e[1];
    let aez = a[2] - e[2];
    let bez = b[2] - e[2];
    let cez = c[2] - e[2];
    let dez = d[2] - e[2];

    let aexbey = aex * bey;
    let bexaey = bex * aey;
    let ab = aexbey - bexaey;
    let bexcey = bex * cey;
    let cexbey = cex * bey;
    let bc = bexcey - cexbey;
    let cexdey = cex * dey;
    let dexcey = dex * cey;
    let cd = cexdey - dexcey;
    let dexaey = dex * aey;
    let aexdey = aex * dey;
    let da = dexaey - aexdey;
    let aexcey = aex * cey;
    let cexaey = cex * aey;
    let ac = aexcey - cexaey;
    let bexdey = bex * dey;
    let dexbey = dex * bey;
    let bd = bexdey - dexbey;

    let abc = aez * bc - bez * ac + cez * ab;
    let bcd = bez * cd - cez * bd + dez * bc;
    let cda = cez * da + dez * ac + aez * cd;
    let dab = dez * ab + aez * bd + bez * da;

    let alift = aex * aex + aey * aey + aez * aez;
    let blift = bex * bex + bey * bey + bez * bez;
    let clift = cex * cex + cey * cey + cez * cez;
    let dlift = dex * dex + dey * dey + dez * dez;

    let det = (dlift * abc - clift * dab) + (blift * cda - alift * bcd);

    let aezp = aez.abs();
    let bezp = bez.abs();
    let cezp = cez.abs();
    let dezp = dez.abs();
    let aexbeyp = aexbey.abs();
    let bexaeyp = bexaey.abs();
    let bexceyp = bexcey.abs();
    let cexbeyp = cexbey.abs();
    let cexdeyp = cexdey.abs();
    let dexceyp = dexcey.abs();
    let dexaeyp = dexaey.abs();
    let aexdeyp = aexdey.abs();
    let aexceyp = aexcey.abs();
    let cexaeyp = cexaey.abs();
    let bexdeyp = bexdey.abs();
    let dexbeyp = dexbey.abs();
    let permanent = ((cexdeyp + dexceyp) * bezp + (dexbeyp + bexdeyp) * cezp + (bexceyp + cexbeyp) * dezp) * alift
        + ((dexaeyp + aexdeyp) * cezp + (aexceyp + cexaeyp) * dezp + (cexdeyp + dexceyp) * aezp) * blift
        + ((aexbeyp + bexaeyp) * dezp + (bexdeyp + dexbeyp) * aezp + (dexaeyp + aexdeyp) * bezp) * clift
        + ((bexceyp + cexbeyp) * aezp + (cexaeyp + aexceyp) * bezp + (aexbeyp + bexaeyp) * cezp) * dlift;
    let errbound = ISP_ERRBOUND_A * permanent;
    // Shewchuk's insphere is positive inside for *his* positive orientation, which is our
    // negative one; hence the sign flip.
    if det > errbound {
        return -1;
    }
    if -det > errbound {
        return 1;
    }
    insphere_exact(a, b, c, d, e)
}

#[cold]
#[inline(never)]
fn insphere_exact(a: &Point, b: &Point, c: &Point, d: &Point, e: &Point) -> i32 {
    if let Some([pa, pb, pc, pd]) = small_int_diffs([a, b, c, d], e) {
        // Shewchuk's expansion of the lifted determinant, in integers: entries below
        // 2^22, 2×2 minors below 2^45, 3×3 minors below 2^69, lifts below 2^46, the
        // determinant below 2^118 (i128).
        let [aex, aey, aez] = pa;
        let [bex, bey, bez] = pb;
        let [cex, cey, cez] = pc;
        let [dex, dey, dez] = pd;
        let ab = (aex * bey - bex * aey) as i128;
        let bc = (bex * cey - cex * bey) as i128;
        let cd = (cex * dey - dex * cey) as i128;
        let da = (dex * aey - aex * dey) as i128;
        let ac = (aex * cey - cex * aey) as i128;
        let bd = (bex * dey - dex * bey) as i128;
        let (aez, bez, cez, dez) = (aez as i128, bez as i128, cez as i128, dez as i128);
        let abc = aez * bc - bez * ac + cez * ab;
        let bcd = bez * cd - cez * bd + dez * bc;
        let cda = cez * da + dez * ac + aez * cd;
        let dab = dez * ab + aez * bd + bez * da;
        let lift = |p: [i64; 3]| (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) as i128;
        let det = (lift(pd) * abc - lift(pc) * dab) + (lift(pb) * cda - lift(pa) * bcd);
        return -(det.signum() as i32);
    }
    -sign(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)))
}

/// Lexicographic (x, y, z) order of two points: the perturbation order.
#[inline]
pub fn lex_cmp(p: &Point, q: &Point) -> Ordering {
    p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1])).then(p[2].total_cmp(&q[2]))
}

/// Perturbed in-sphere: is `e` inside the circumsphere of the positively oriented
/// tetrahedron `t = [a, b, c, d]`? Never ambiguous for five distinct points.
///
/// Simulation of simplicity on the lifted coordinate (Edelsbrunner–Mücke 1990,
/// Devillers–Teillaud 2011): when the exact determinant is zero, the sign is decided by
/// the first non-vanishing coefficient of the perturbation polynomial, taken from the
/// point with the largest perturbation (lexicographically largest) downwards. The
/// coefficient of the query point is −orient(t) (so a dominant `e` is outside); the
/// coefficient of a vertex of `t` is the orientation of `t` with that vertex replaced by
/// `e`.
#[inline]
pub fn in_conflict_finite(t: [&Point; 4], e: &Point) -> bool {
    let s = insphere(t[0], t[1], t[2], t[3], e);
    if s != 0 {
        return s > 0;
    }
    perturbed_insphere_tie(t, e)
}

#[cold]
#[inline(never)]
fn perturbed_insphere_tie(t: [&Point; 4], e: &Point) -> bool {
    // Indices 0..4 are the tetrahedron's vertices, 4 is the query point; visit them from
    // the lexicographically largest down (selection: usually one or two steps).
    let pt = |i: usize| if i == 4 { e } else { t[i] };
    let mut used = [false; 5];
    for _ in 0..5 {
        let i = largest_unused(&used, pt);
        used[i] = true;
        if i == 4 {
            return false; // dominant query point: outside (t is non-degenerate)
        }
        let mut r = t;
        r[i] = e;
        let o = orient(r[0], r[1], r[2], r[3]);
        if o != 0 {
            return o > 0;
        }
    }
    unreachable!("perturbed insphere: the query point always ends the loop")
}

/// The lexicographically largest point among the unused indices.
#[inline]
fn largest_unused<'p, const N: usize>(used: &[bool; N], pt: impl Fn(usize) -> &'p Point) -> usize {
    let mut best = usize::MAX;
    #[allow(clippy::needless_range_loop)] // i is passed to pt too
    for i in 0..N {
        if !used[i] && (best == usize::MAX || lex_cmp(pt(i), pt(best)) == Ordering::Greater) {
            best = i;
        }
    }
    best
}

/// Perturbed conflict test of an infinite tetrahedron `(a, b, c, ∞)` with `e`.
///
/// `abc` is a convex-hull facet oriented so that the hull lies on its negative side
/// (`orient(a, b, c, x) < 0` for interior `x`). `e` conflicts when it is strictly on the
/// positive side, or coplanar and strictly inside the circumcircle of `abc`, the
/// cocircular case being resolved by the same perturbation as [`in_conflict_finite`]
/// (the infinite vertex never dominates: its coefficient vanishes for coplanar `e`).
/// `far` is a power of two larger than every |coordinate| (used to build an exact
/// off-plane point for the coplanar case).
#[inline]
pub fn in_conflict_infinite(a: &Point, b: &Point, c: &Point, e: &Point, far: f64) -> bool {
    let o = orient(a, b, c, e);
    if o != 0 {
        return o > 0;
    }
    coplanar_in_conflict(a, b, c, e, far)
}

/// A point off the plane of the non-degenerate triangle `abc`, exactly representable,
/// with `far` a power of two at least as large as every |coordinate|; returns the point
/// and the orientation sign of `(a, b, c, q)`.
///
/// `q = a + far·e_k` for the first axis `k` that lies off the plane: the displacement is
/// along one axis and nonzero after rounding (because `far > |a_k|`), so it is off the
/// plane whenever the plane's normal has a nonzero `k` component, which holds for at
/// least one axis. The orientation is checked exactly anyway.
fn off_plane_point(a: &Point, b: &Point, c: &Point, far: f64) -> (Point, i32) {
    for k in 0..3 {
        let mut q = *a;
        q[k] += far;
        let s = orient(a, b, c, &q);
        if s != 0 {
            return (q, s);
        }
    }
    unreachable!("off_plane_point: triangle is degenerate")
}

/// Exact, perturbed "is coplanar `e` inside the circumcircle of `abc`" (Devillers &
/// Teillaud 2011, the 2D case of the lifted perturbation; CGAL's
/// `coplanar_side_of_bounded_circle`).
#[cold]
#[inline(never)]
pub fn coplanar_in_conflict(a: &Point, b: &Point, c: &Point, e: &Point, far: f64) -> bool {
    // The sphere through a, b, c and any off-plane q cuts the plane in the circle abc, so
    // in-circle(abc, e) = in-sphere(abcq, e) for coplanar e.
    let (q, sq) = off_plane_point(a, b, c, far);
    let s = insphere(a, b, c, &q, e) * sq;
    if s != 0 {
        return s > 0;
    }
    // Cocircular: perturbation, dominant point first.
    let pts = [a, b, c, e];
    let mut used = [false; 4];
    for _ in 0..4 {
        let i = largest_unused(&used, |k| pts[k]);
        used[i] = true;
        if i == 3 {
            return false;
        }
        let mut r = [a, b, c];
        r[i] = e;
        // 2D orientation of r relative to abc, computed with the same off-plane point.
        let o = orient(r[0], r[1], r[2], &q) * sq;
        if o != 0 {
            return o > 0;
        }
    }
    unreachable!("coplanar perturbed in-circle: the query point always ends the loop")
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: Point = [0.0, 0.0, 0.0];
    const B: Point = [1.0, 0.0, 0.0];
    const C: Point = [0.0, 1.0, 0.0];
    const D: Point = [0.0, 0.0, 1.0];

    #[test]
    fn orientation_convention_is_right_handed() {
        assert_eq!(orient(&A, &B, &C, &D), 1);
        assert_eq!(orient(&B, &A, &C, &D), -1);
        assert_eq!(orient(&A, &B, &C, &[0.5, 0.5, 0.0]), 0);
    }

    #[test]
    fn insphere_convention_positive_inside() {
        assert_eq!(insphere(&A, &B, &C, &D, &[0.2, 0.2, 0.2]), 1);
        assert_eq!(insphere(&A, &B, &C, &D, &[2.0, 2.0, 2.0]), -1);
        assert_eq!(insphere(&A, &B, &C, &D, &[1.0, 1.0, 0.0]), 0);
        // Negative orientation reverses the sign.
        assert_eq!(insphere(&B, &A, &C, &D, &[0.2, 0.2, 0.2]), -1);
    }

    #[test]
    fn perturbation_is_antisymmetric_across_a_facet() {
        // Five cospherical points (cube corners): for two tetrahedra sharing a facet,
        // "e is inside sphere(t1)" and "a is inside sphere(t2)" are the same lifted
        // determinant, so the perturbed answers must agree.
        let pts: [Point; 5] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]];
        let (a, b, c, d, e) = (&pts[0], &pts[1], &pts[2], &pts[3], &pts[4]);
        assert_eq!(insphere(a, b, c, d, e), 0);
        // abcd positive; the tetrahedron on the other side of bcd with apex e is b,c,d,e
        // with orientation fixed below.
        let t2 = if orient(b, d, c, e) > 0 { [b, d, c, e] } else { [b, c, d, e] };
        let e_in_t1 = in_conflict_finite([a, b, c, d], e);
        let a_in_t2 = in_conflict_finite(t2, a);
        assert_eq!(e_in_t1, a_in_t2);
    }

    #[test]
    fn small_integer_path_agrees_with_robust() {
        // Random small-integer and dyadic configurations, many degenerate: the i128 path
        // must give exactly robust's signs.
        let mut state = 12345u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((state >> 33) % 7) as f64 * 0.25 - 0.5
        };
        let mut taken = 0;
        for _ in 0..20000 {
            let p: Vec<Point> = (0..5).map(|_| [next(), next(), next()]).collect();
            let r_o = -sign(robust::orient3d(c3(&p[0]), c3(&p[1]), c3(&p[2]), c3(&p[3])));
            assert_eq!(orient_exact(&p[0], &p[1], &p[2], &p[3]), r_o);
            let r_i = -sign(robust::insphere(c3(&p[0]), c3(&p[1]), c3(&p[2]), c3(&p[3]), c3(&p[4])));
            assert_eq!(insphere_exact(&p[0], &p[1], &p[2], &p[3], &p[4]), r_i);
            taken += small_int_diffs([&p[0], &p[1], &p[2], &p[3]], &p[4]).is_some() as usize;
        }
        assert_eq!(taken, 20000);
        // Non-dyadic inputs fall back.
        assert!(small_int_diffs([&[0.1, 0.0, 0.0]], &[0.0, 0.0, 1e-17]).is_none());
        // Large cospherical integers.
        let (a, b, c, d, e) = (
            [3449.0, 70.0, 7.0],
            [-3449.0, 70.0, -7.0],
            [70.0, 3449.0, 7.0],
            [7.0, 70.0, -3449.0],
            [-7.0, -70.0, 3449.0],
        );
        let r = -sign(robust::insphere(c3(&a), c3(&b), c3(&c), c3(&d), c3(&e)));
        assert_eq!(insphere_exact(&a, &b, &c, &d, &e), r);
    }

    #[test]
    fn coplanar_incircle_exact() {
        let far = 4.0;
        // abc in the plane z = 0, oriented so that +z is positive side.
        assert_eq!(orient(&A, &B, &C, &D), 1);
        assert!(coplanar_in_conflict(&A, &B, &C, &[0.4, 0.4, 0.0], far));
        assert!(!coplanar_in_conflict(&A, &B, &C, &[2.0, 2.0, 0.0], far));
        // Cocircular (1,1,0): the perturbation decides, and must be consistent with the
        // triangle on the other side of the shared edge.
        let e: Point = [1.0, 1.0, 0.0];
        let r1 = coplanar_in_conflict(&A, &B, &C, &e, far);
        // Triangle (b, e, c) oriented like abc (+z positive side) shares edge bc.
        assert_eq!(orient(&B, &e, &C, &D), 1);
        let r2 = coplanar_in_conflict(&B, &e, &C, &A, far);
        assert_eq!(r1, r2);
    }
}
