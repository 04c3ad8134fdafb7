//! The geometric pieces of the cell bounds: points of a triangle from barycentric
//! coordinates, the covering radius of a triangle by its corners (for the Lipschitz bound)
//! and the maximum of the lower envelope of affine functions (for the convexity bound).

use vf_common::vec3::distance;

use super::V3;

#[inline]
pub(super) fn at(tri: &[V3; 3], uv: [f64; 2]) -> V3 {
    let [a, b, c] = tri;
    [0, 1, 2].map(|k| a[k] + uv[0] * (b[k] - a[k]) + uv[1] * (c[k] - a[k]))
}

/// Covering radius of a triangle by its corners: the largest distance from a point of the
/// triangle to its nearest corner, slightly enlarged. Acute: the circumradius. Right or
/// obtuse (longest edge `c` opposite the obtuse corner, other edges `a`, `b`): the larger of
/// the distances at which the perpendicular bisectors of `a` and `b` meet `c`,
/// `b²c / (b² + c² − a²)` and `a²c / (a² + c² − b²)` (each ≤ c/2); half the longest edge
/// for needles, where those formulas lose accuracy.
pub(super) fn covering_radius(x: &[V3; 3]) -> f64 {
    let mut s = [distance(x[1], x[2]), distance(x[2], x[0]), distance(x[0], x[1])];
    s.sort_by(f64::total_cmp);
    let (a, b, c) = (s[0], s[1], s[2]);
    let r = if c * c >= a * a + b * b {
        if a < 1e-3 * c {
            0.5 * c
        } else {
            let (a2, b2, c2) = (a * a, b * b, c * c);
            let r1 = b2 * c / (b2 + c2 - a2);
            let r2 = a2 * c / (a2 + c2 - b2);
            (r1.max(r2) * (1.0 + 1e-9)).min(0.5 * c)
        }
    } else {
        // Heron, stable form (Kahan), a <= b <= c.
        let p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
        if p > 0.0 {
            (a * b * c / p.sqrt()).max(0.5 * c)
        } else {
            c
        }
    };
    r * (1.0 + 1e-12)
}

/// `max over λ in the barycentric simplex of min_i Σ_j λ_j rows[i][j]`: the largest value
/// of the lower envelope of up to three affine functions over a triangle, given by their
/// values at the corners.
///
/// Why it bounds the distance: for a target triangle `t`, `d(·, t)` is convex, so on the
/// cell it lies below the affine interpolation of its corner values (Jensen); `d(·, B)` is
/// at most the smallest of these. The lower envelope is concave and piecewise affine, so its
/// maximum over the triangle is at a corner, where two functions cross on an edge, or where
/// three are equal inside; all such points are evaluated. Unlike the maximum over the
/// corners, this is exact where the closest feature is a face plane on each side of a
/// crease, so cells at a ridge of `d(·, B)` settle after a few splits.
pub(super) fn max_of_min_affine(rows: &[[f64; 3]]) -> f64 {
    let eval = |l: [f64; 3]| rows.iter().map(|r| r[0] * l[0] + r[1] * l[1] + r[2] * l[2]).fold(f64::INFINITY, f64::min);
    let mut best = f64::NEG_INFINITY;
    for j in 0..3 {
        let mut l = [0.0; 3];
        l[j] = 1.0;
        best = best.max(eval(l));
    }
    for (j, k) in [(0, 1), (1, 2), (2, 0)] {
        for a in 0..rows.len() {
            for b in a + 1..rows.len() {
                let denom = (rows[a][k] - rows[a][j]) - (rows[b][k] - rows[b][j]);
                if denom != 0.0 {
                    let s = (rows[b][j] - rows[a][j]) / denom;
                    if s > 0.0 && s < 1.0 {
                        let mut l = [0.0; 3];
                        l[j] = 1.0 - s;
                        l[k] = s;
                        best = best.max(eval(l));
                    }
                }
            }
        }
    }
    if rows.len() == 3 {
        // λ·(r0 − r1) = 0, λ·(r0 − r2) = 0, λ·1 = 1 by Cramer's rule.
        let m = [
            [rows[0][0] - rows[1][0], rows[0][1] - rows[1][1], rows[0][2] - rows[1][2]],
            [rows[0][0] - rows[2][0], rows[0][1] - rows[2][1], rows[0][2] - rows[2][2]],
            [1.0, 1.0, 1.0],
        ];
        let det3 = |m: &[[f64; 3]; 3]| {
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
                + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        };
        let det = det3(&m);
        if det != 0.0 && det.is_finite() {
            let mut l = [0.0; 3];
            for (c, lc) in l.iter_mut().enumerate() {
                let mut mc = m;
                for (r, row) in mc.iter_mut().enumerate() {
                    row[c] = if r == 2 { 1.0 } else { 0.0 };
                }
                *lc = det3(&mc) / det;
            }
            if l.iter().all(|&x| (0.0..=1.0).contains(&x)) {
                best = best.max(eval(l));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force over a fine barycentric grid (a lower bound of the true maximum).
    fn grid_max(rows: &[[f64; 3]], n: usize) -> f64 {
        let mut best = f64::NEG_INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let l = [i as f64 / n as f64, j as f64 / n as f64, (n - i - j) as f64 / n as f64];
                let v = rows.iter().map(|r| r[0] * l[0] + r[1] * l[1] + r[2] * l[2]).fold(f64::INFINITY, f64::min);
                best = best.max(v);
            }
        }
        best
    }

    #[test]
    fn max_of_min_affine_matches_a_dense_grid() {
        let mut state = 12345u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..3000 {
            let k = 1 + case % 3;
            let rows: Vec<[f64; 3]> = (0..k).map(|_| [rnd() * 2.0, rnd() * 2.0, rnd() * 2.0]).collect();
            let got = max_of_min_affine(&rows);
            let grid = grid_max(&rows, 300);
            // Never below what the grid sees; the grid's spacing bounds the other side.
            assert!(got >= grid - 1e-12, "case {case}: {got} < grid {grid} for {rows:?}");
            assert!(got <= grid + 2.0 * 2.0 / 300.0 + 1e-12, "case {case}: {got} >> grid {grid} for {rows:?}");
        }
        // A ridge: two planes crossing inside the triangle; the envelope peaks on the crossing.
        let rows = [[0.0, 1.0, 1.0], [1.0, 0.0, 1.0]];
        assert!((max_of_min_affine(&rows) - 1.0).abs() < 1e-15);
        let rows = [[0.0, 2.0, 0.0], [2.0, 0.0, 0.0]];
        assert!((max_of_min_affine(&rows) - 1.0).abs() < 1e-15);
        // Three-way interior peak.
        let rows = [[3.0, 0.0, 0.0], [0.0, 3.0, 0.0], [0.0, 0.0, 3.0]];
        assert!((max_of_min_affine(&rows) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn covering_radius_bounds_the_distance_to_the_nearest_corner() {
        let mut state = 99u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut tris = vec![
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.8, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.05, 0.0]],
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]],
            [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
        ];
        for _ in 0..200 {
            tris.push([[rnd(), rnd(), rnd()], [rnd(), rnd(), rnd()], [rnd(), rnd(), rnd()]]);
        }
        for x in tris {
            let r = covering_radius(&x);
            let n = 200;
            let mut worst = 0.0f64;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let uv = [i as f64 / n as f64, j as f64 / n as f64];
                    let p = at(&x, uv);
                    worst = worst.max(distance(p, x[0]).min(distance(p, x[1])).min(distance(p, x[2])));
                }
            }
            assert!(worst <= r, "{x:?}: {worst} > {r}");
            assert!(r <= worst * 1.05 + 0.01, "{x:?}: {r} loose vs {worst}");
        }
    }
}
