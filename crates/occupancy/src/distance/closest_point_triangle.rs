//! Exact closest point on one triangle.

use vf_common::vec3::{add, dot, norm_squared, scale, sub, V3};

/// Closest point to `p` on the closed triangle `(a, b, c)`, by the Voronoi-region method
/// of Ericson, *Real-Time Collision Detection* (2005), §5.1.5, in f64 (the same method
/// libigl's `point_simplex_squared_distance` uses).
///
/// - `p`, `a`, `b`, `c`: points in the mesh frame, f64.
/// - returns: the closest point, in the mesh frame.
///
/// Degenerate (zero-area) triangles are handled: when the face region's barycentric
/// denominator vanishes, the answer is the closest point on the three edges.
#[inline]
pub fn closest_point_triangle(p: V3, a: V3, b: V3, c: V3) -> V3 {
    let ab = sub(b, a);
    let ac = sub(c, a);
    let ap = sub(p, a);
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    // Each edge region divides by the edge's squared length (d1 − d3 = |ab|², and so on):
    // a zero-length edge (two corners coincide) skips to the degenerate case below.
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0 {
        let v = d1 / (d1 - d3);
        return add(a, scale(ab, v));
    }
    let cp = sub(p, c);
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0 {
        let w = d2 / (d2 - d6);
        return add(a, scale(ac, w));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return add(b, scale(sub(c, b), w));
    }
    let sum = va + vb + vc;
    if sum > 0.0 && sum.is_finite() {
        let denom = 1.0 / sum;
        let v = vb * denom;
        let w = vc * denom;
        let q = add(add(a, scale(ab, v)), scale(ac, w));
        if q.iter().all(|x| x.is_finite()) {
            return q;
        }
    }
    // Degenerate triangle (collinear or coincident corners): best of the three edges.
    let mut best = closest_point_segment(p, a, b);
    for q in [closest_point_segment(p, b, c), closest_point_segment(p, c, a)] {
        if norm_squared(sub(p, q)) < norm_squared(sub(p, best)) {
            best = q;
        }
    }
    best
}

/// Closest point to `p` on the segment `[a, b]` (f64, mesh frame).
#[inline]
pub fn closest_point_segment(p: V3, a: V3, b: V3) -> V3 {
    let ab = sub(b, a);
    let len2 = norm_squared(ab);
    if len2 <= 0.0 {
        return a;
    }
    let t = (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0);
    add(a, scale(ab, t))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute(p: V3, a: V3, b: V3, c: V3) -> f64 {
        // Dense barycentric grid plus edges: an upper bound that converges to the truth.
        let n = 400;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let u = i as f64 / n as f64;
                let v = j as f64 / n as f64;
                let q = add(add(a, scale(sub(b, a), u)), scale(sub(c, a), v));
                best = best.min(norm_squared(sub(p, q)));
            }
        }
        best
    }

    #[test]
    fn all_regions_match_dense_search() {
        let a = [0.0, 0.0, 0.0];
        let b = [1.0, 0.2, 0.1];
        let c = [0.3, 1.1, -0.2];
        let pts = [
            [-1.0, -1.0, 0.5],
            [2.0, 0.0, 0.0],
            [0.3, 2.0, 0.0],
            [0.5, -1.0, 0.3],
            [-1.0, 0.5, 0.3],
            [1.0, 1.0, 0.0],
            [0.4, 0.4, 1.0],
            [0.4, 0.4, -1.0],
        ];
        for p in pts {
            let q = closest_point_triangle(p, a, b, c);
            let d = norm_squared(sub(p, q));
            let bd = brute(p, a, b, c);
            assert!(d <= bd + 1e-12, "{p:?}: {d} > {bd}");
            assert!(bd - d < 1e-4, "{p:?}: {d} vs {bd}");
        }
    }

    #[test]
    fn degenerate_triangles_give_finite_answers() {
        let p = [0.5, 1.0, 0.0];
        let q = closest_point_triangle(p, [0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]);
        assert!((norm_squared(sub(p, q)) - 1.0).abs() < 1e-15, "{q:?}");
        let q = closest_point_triangle(p, [0.0; 3], [0.0; 3], [0.0; 3]);
        assert_eq!(q, [0.0; 3]);
    }

    #[test]
    fn two_coincident_corners_are_a_segment() {
        // A triangle with a repeated corner (as rounding to float32 leaves in crusts) was
        // 0/0 in the edge region of its zero-length edge: a NaN distance in `eval`'s
        // Chamfer. Every order of the corners, and points around the segment and beyond
        // its ends, must give the segment's closest point.
        let (s, t) = ([0.1, -0.2, 0.3], [1.1, 0.4, -0.2]);
        let pts = [[0.0, 0.0, 0.0], [0.5, 1.0, 0.2], [2.0, 0.5, 0.0], [-1.0, -0.5, 0.7], [0.6, 0.1, 0.05], s, t];
        for p in pts {
            let want = closest_point_segment(p, s, t);
            for (a, b, c) in [(s, s, t), (s, t, s), (t, s, s), (t, t, s), (s, t, t), (t, s, t)] {
                let q = closest_point_triangle(p, a, b, c);
                assert!(q.iter().all(|x| x.is_finite()), "{p:?} on {a:?} {b:?} {c:?}: {q:?}");
                let (d, w) = (norm_squared(sub(p, q)), norm_squared(sub(p, want)));
                assert!((d - w).abs() <= 1e-15 * (1.0 + w), "{p:?} on {a:?} {b:?} {c:?}: {d} vs {w}");
            }
        }
    }
}
