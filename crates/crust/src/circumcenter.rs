//! Circumcentres of tetrahedra in double-double arithmetic.
//!
//! The crust's vertices are circumcentres of Delaunay tetrahedra, many of them slivers or
//! nearly cospherical, where the textbook f64 formula loses most of its digits. Here the
//! edge vectors are formed exactly (an f64 difference is exactly a double-double), and
//! the numerators and the determinant are evaluated in double-double (error-free
//! transformations with FMA; Dekker 1971, Hida–Li–Bailey 2001), about 104 bits.
//!
//! # Error bound
//! For a tetrahedron with edge vectors u, v, w from corner a and D = u·(v×w), the computed
//! circumcentre c̃ satisfies, before the final rounding to f64,
//! ‖c̃ − c‖ ≤ 2⁻⁹⁶ · (‖u‖²‖v‖‖w‖ + ‖v‖²‖w‖‖u‖ + ‖w‖²‖u‖‖v‖) · (1 + ‖c − a‖·‖u‖‖v‖‖w‖/|D|) / |D|,
//! a conservative bound from the forward error of each double-double operation (relative
//! error below 2⁻¹⁰⁴ per operation, fewer than 2⁸ operations). For any tetrahedron whose
//! `|D| / (‖u‖‖v‖‖w‖)` exceeds 2⁻⁴⁰ this is far below the f64 rounding of the result, so
//! the returned coordinates are the f64 rounding of the exact circumcentre to within one
//! ulp. Exactly cospherical neighbours are not left to this bound at all: the crust merges
//! them by an exact in-sphere test, so they share one vertex.

/// A double-double number `hi + lo` with `|lo| ≤ ulp(hi)/2`.
#[derive(Clone, Copy, Debug)]
struct Dd {
    hi: f64,
    lo: f64,
}

#[inline]
fn two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    Dd { hi: s, lo: e }
}

#[inline]
fn quick_two_sum(a: f64, b: f64) -> Dd {
    let s = a + b;
    Dd { hi: s, lo: b - (s - a) }
}

#[inline]
fn two_prod(a: f64, b: f64) -> Dd {
    let p = a * b;
    Dd { hi: p, lo: a.mul_add(b, -p) }
}

impl Dd {
    #[inline]
    fn exact_diff(a: f64, b: f64) -> Dd {
        two_sum(a, -b)
    }
    #[inline]
    fn add(self, o: Dd) -> Dd {
        let s = two_sum(self.hi, o.hi);
        let t = two_sum(self.lo, o.lo);
        let s = quick_two_sum(s.hi, s.lo + t.hi);
        quick_two_sum(s.hi, s.lo + t.lo)
    }
    #[inline]
    fn neg(self) -> Dd {
        Dd { hi: -self.hi, lo: -self.lo }
    }
    #[inline]
    fn sub(self, o: Dd) -> Dd {
        self.add(o.neg())
    }
    #[inline]
    fn mul(self, o: Dd) -> Dd {
        let p = two_prod(self.hi, o.hi);
        quick_two_sum(p.hi, p.lo + (self.hi * o.lo + self.lo * o.hi))
    }
    #[inline]
    fn div(self, o: Dd) -> Dd {
        let q1 = self.hi / o.hi;
        let r = self.sub(o.mul(Dd { hi: q1, lo: 0.0 }));
        let q2 = r.hi / o.hi;
        let r = r.sub(o.mul(Dd { hi: q2, lo: 0.0 }));
        let q3 = r.hi / o.hi;
        quick_two_sum(q1, q2).add(Dd { hi: q3, lo: 0.0 })
    }
    #[inline]
    fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
}

type V3 = [Dd; 3];

fn cross(a: &V3, b: &V3) -> V3 {
    [a[1].mul(b[2]).sub(a[2].mul(b[1])), a[2].mul(b[0]).sub(a[0].mul(b[2])), a[0].mul(b[1]).sub(a[1].mul(b[0]))]
}

fn dot(a: &V3, b: &V3) -> Dd {
    a[0].mul(b[0]).add(a[1].mul(b[1])).add(a[2].mul(b[2]))
}

/// Circumcentre of the tetrahedron `(a, b, c, d)` (any orientation), or `None` when its
/// corners are exactly coplanar (no circumsphere).
///
/// `a`..`d`: f64 points; result in the same frame. See the module doc for the error bound.
pub fn circumcenter(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> Option<[f64; 3]> {
    let e = |p: [f64; 3]| -> V3 { [0, 1, 2].map(|k| Dd::exact_diff(p[k], a[k])) };
    let (u, v, w) = (e(b), e(c), e(d));
    let vw = cross(&v, &w);
    let wu = cross(&w, &u);
    let uv = cross(&u, &v);
    let det = dot(&u, &vw);
    if det.hi == 0.0 {
        // The double-double determinant of exact differences is zero only if the exact
        // one is (its error is far below its magnitude otherwise); confirm exactly.
        if robust::orient3d(pt(a), pt(b), pt(c), pt(d)) == 0.0 {
            return None;
        }
    }
    let (nu, nv, nw) = (dot(&u, &u), dot(&v, &v), dot(&w, &w));
    let two_det = det.add(det);
    let mut out = [0.0; 3];
    for k in 0..3 {
        let num = nu.mul(vw[k]).add(nv.mul(wu[k])).add(nw.mul(uv[k]));
        out[k] = num.div(two_det).add(Dd { hi: a[k], lo: 0.0 }).to_f64();
    }
    Some(out)
}

fn pt(p: [f64; 3]) -> robust::Coord3D<f64> {
    robust::Coord3D { x: p[0], y: p[1], z: p[2] }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_tetrahedron_and_unit_cube_corner() {
        let c = circumcenter([0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]).unwrap();
        assert_eq!(c, [0.5, 0.5, 0.5]);
        assert!(circumcenter([0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]).is_none());
    }

    #[test]
    fn equidistant_to_the_corners_on_random_and_sliver_tets() {
        let mut s = 0x1234_5678_9abc_def0u64;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        for i in 0..2000 {
            let a = [r(), r(), r()];
            let b = [r(), r(), r()];
            let c = [r(), r(), r()];
            // Every other tet is a sliver: d almost on the plane of a, b, c.
            let d = if i % 2 == 0 {
                [r(), r(), r()]
            } else {
                let t = r();
                [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]) + (1.0 - t) * 0.5 * (c[k] - a[k]) + 1e-7 * r())
            };
            let Some(x) = circumcenter(a, b, c, d) else { continue };
            let dist = |p: [f64; 3]| ((x[0] - p[0]).powi(2) + (x[1] - p[1]).powi(2) + (x[2] - p[2]).powi(2)).sqrt();
            let ra = dist(a);
            for p in [b, c, d] {
                assert!((dist(p) - ra).abs() <= 1e-15 * ra.max(1.0) * 8.0, "{i}: {} vs {ra}", dist(p));
            }
        }
    }
}
