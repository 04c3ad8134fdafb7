//! A digit as an occupancy function on the unit square.
//!
//! Definition (the seed does not give one): a 28 × 28 image is sampled at pixel centres,
//! pixel (row r, column c) at x = (c + ½)/28, y = (r + ½)/28 — x to the right, y *down*, as
//! the image is stored — with zero intensity outside the image. The intensity I(x, y) is
//! the bilinear interpolation of the pixel values / 255 between pixel centres, and the
//! digit is the set where I ≥ ½. At a pixel centre this is the pixel ≥ 128, so on the
//! 28 × 28 grid the ground truth is simply the thresholded image.
//!
//! Along a horizontal or vertical line the bilinear intensity is piecewise linear (its
//! breakpoints are the pixel-centre coordinates), so where it crosses ½ on such a line is
//! exact. [`Digit::boundary`] collects those crossings on lines every ¼ pixel: boundary
//! points at most ⅛ pixel from any boundary point between them; they serve as the closest
//! points of the signed-distance regulariser and as the centres of the near-boundary
//! training samples.

use soft_voronoi::Located;
use vf_common::ChunkRng;

/// Side of the images (MNIST: 28).
pub const SIDE: usize = 28;

/// Lines per pixel on which boundary crossings are collected.
pub const BOUNDARY_LINES_PER_PIXEL: usize = 4;

/// One image as an occupancy function.
#[derive(Clone, Debug)]
pub struct Digit<'a> {
    pixels: &'a [u8],
    rows: usize,
    cols: usize,
}

impl<'a> Digit<'a> {
    /// The digit of `pixels` (`rows × cols`, row-major).
    pub fn new(pixels: &'a [u8], rows: usize, cols: usize) -> Self {
        debug_assert_eq!(pixels.len(), rows * cols);
        Digit { pixels, rows, cols }
    }

    fn px(&self, r: isize, c: isize) -> f64 {
        if r < 0 || c < 0 || r as usize >= self.rows || c as usize >= self.cols {
            0.0
        } else {
            f64::from(self.pixels[r as usize * self.cols + c as usize]) / 255.0
        }
    }

    /// Bilinear intensity in [0, 1] at (x, y) of the unit square.
    pub fn intensity(&self, p: [f64; 2]) -> f64 {
        let u = p[0] * self.cols as f64 - 0.5;
        let v = p[1] * self.rows as f64 - 0.5;
        if !(u.is_finite() && v.is_finite()) {
            return 0.0;
        }
        let (c0, r0) = (u.floor(), v.floor());
        let (fu, fv) = (u - c0, v - r0);
        let (c0, r0) =
            (c0.clamp(-2.0, self.cols as f64 + 1.0) as isize, r0.clamp(-2.0, self.rows as f64 + 1.0) as isize);
        let a = self.px(r0, c0) * (1.0 - fu) + self.px(r0, c0 + 1) * fu;
        let b = self.px(r0 + 1, c0) * (1.0 - fu) + self.px(r0 + 1, c0 + 1) * fu;
        a * (1.0 - fv) + b * fv
    }

    /// The occupancy: intensity ≥ ½.
    pub fn inside(&self, p: [f64; 2]) -> bool {
        self.intensity(p) >= 0.5
    }

    /// Occupancy on the `n × n` grid of cell centres ((i + ½)/n), row-major (rows are y).
    pub fn grid(&self, n: usize) -> Vec<bool> {
        let mut out = Vec::with_capacity(n * n);
        for r in 0..n {
            for c in 0..n {
                out.push(self.inside([(c as f64 + 0.5) / n as f64, (r as f64 + 0.5) / n as f64]));
            }
        }
        out
    }

    /// Points where the intensity crosses ½ on horizontal and vertical lines every
    /// 1/[`BOUNDARY_LINES_PER_PIXEL`] pixel (exact for the bilinear intensity, up to
    /// rounding).
    pub fn boundary(&self) -> Vec<[f64; 2]> {
        let mut out = Vec::new();
        let k = BOUNDARY_LINES_PER_PIXEL;
        // Horizontal lines y = (j + ½)/(k·rows): breakpoints at pixel-centre x's (plus the
        // zero border half a pixel outside).
        for j in 0..k * self.rows {
            let y = (j as f64 + 0.5) / (k * self.rows) as f64;
            let xs: Vec<f64> = (-1..=self.cols as isize).map(|c| (c as f64 + 0.5) / self.cols as f64).collect();
            crossings(&xs, |x| self.intensity([x, y]) - 0.5, |x| out.push([x, y]));
        }
        for j in 0..k * self.cols {
            let x = (j as f64 + 0.5) / (k * self.cols) as f64;
            let ys: Vec<f64> = (-1..=self.rows as isize).map(|r| (r as f64 + 0.5) / self.rows as f64).collect();
            crossings(&ys, |y| self.intensity([x, y]) - 0.5, |y| out.push([x, y]));
        }
        out
    }

    /// The side and a closest boundary point of each point (the signed-distance
    /// regulariser's input); with no boundary (an empty image) the closest point is the
    /// point itself, so the term is 0.
    pub fn locate(&self, boundary: &[[f64; 2]], points: &[[f64; 2]]) -> Vec<Located<2>> {
        points
            .iter()
            .map(|&p| {
                let closest =
                    boundary.iter().copied().min_by(|a, b| dist2(*a, p).total_cmp(&dist2(*b, p))).unwrap_or(p);
                Located { inside: self.inside(p), closest }
            })
            .collect()
    }

    /// `n` training points and their occupancy: half uniform in the unit square, half near
    /// the boundary (a boundary crossing plus a Gaussian offset of σ = ½ pixel, clamped to
    /// the square); all uniform when there is no boundary.
    pub fn sample(&self, boundary: &[[f64; 2]], n: usize, rng: &mut ChunkRng) -> (Vec<[f64; 2]>, Vec<bool>) {
        let sigma = 0.5 / self.rows.max(self.cols) as f64;
        let mut pts = Vec::with_capacity(n);
        for i in 0..n {
            let p = if i % 2 == 1 && !boundary.is_empty() {
                let b = boundary[((rng.next_u64() as u128 * boundary.len() as u128) >> 64) as usize];
                [(b[0] + sigma * rng.normal()).clamp(0.0, 1.0), (b[1] + sigma * rng.normal()).clamp(0.0, 1.0)]
            } else {
                [rng.uniform(), rng.uniform()]
            };
            pts.push(p);
        }
        let occ = pts.iter().map(|&p| self.inside(p)).collect();
        (pts, occ)
    }
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Roots of a function that is linear between consecutive `knots` (sign changes of
/// `f`, interpolated linearly, which is exact there).
fn crossings(knots: &[f64], f: impl Fn(f64) -> f64, mut emit: impl FnMut(f64)) {
    for w in knots.windows(2) {
        let (a, b) = (f(w[0]), f(w[1]));
        if (a < 0.0) != (b < 0.0) {
            let t = a / (a - b);
            emit(w[0] + t * (w[1] - w[0]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blob() -> Vec<u8> {
        let mut px = vec![0u8; SIDE * SIDE];
        for r in 8..20 {
            for c in 10..18 {
                px[r * SIDE + c] = 255;
            }
        }
        px[3 * SIDE + 3] = 200;
        px
    }

    #[test]
    fn pixel_centres_are_the_thresholded_image_and_crossings_are_on_the_level_set() {
        let px = blob();
        let d = Digit::new(&px, SIDE, SIDE);
        let g = d.grid(SIDE);
        for i in 0..SIDE * SIDE {
            assert_eq!(g[i], px[i] >= 128, "pixel {i}");
        }
        let b = d.boundary();
        assert!(!b.is_empty());
        for p in &b {
            assert!((d.intensity(*p) - 0.5).abs() < 1e-9, "{p:?}");
        }
        // The 8×12 block's level set is the rectangle half a pixel out from the centres of
        // its edge pixels... shrunk to where the bilinear ramp crosses ½: exactly the pixel
        // edges (ramps between 1 and 0 over one pixel cross ½ midway).
        let (x0, x1) = (10.0 / 28.0, 18.0 / 28.0);
        assert!(b.iter().any(|p| (p[0] - x0).abs() < 1e-12));
        assert!(b.iter().all(|p| p[0] >= x0 - 1e-9 || p[0] < 5.0 / 28.0));
        assert!(b.iter().all(|p| p[0] <= x1 + 1e-9));
        let loc = d.locate(&b, &[[0.5, 0.5], [0.9, 0.9]]);
        assert!(loc[0].inside && !loc[1].inside);
        let empty = vec![0u8; SIDE * SIDE];
        let e = Digit::new(&empty, SIDE, SIDE);
        assert!(e.boundary().is_empty());
        assert_eq!(e.locate(&[], &[[0.2, 0.3]])[0].closest, [0.2, 0.3]);
    }
}
