//! The seed's table: mismatched pixels per test image on the 28 × 28 grid (the most
//! plausible reading of its unlabelled "Mean / Std / Med"), with IoU on that grid and on a
//! 4× supersampled grid (112 × 112 cell centres, ground truth from the bilinear
//! occupancy), per method, with each decoder's parameter count.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::digit::Digit;
use crate::idx::DigitSet;
use crate::model::{hard_occupancy, Method, Model, LATENT};
use crate::net::OccNetScratch;

/// Supersampling of the fine IoU grid.
pub const SUPERSAMPLE: usize = 4;

/// Mean, standard deviation (population) and median.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Stats {
    /// Mean.
    pub mean: f64,
    /// Population standard deviation.
    pub std: f64,
    /// Median (the mean of the middle two for an even count).
    pub median: f64,
}

impl Stats {
    /// Of `values` (zeros when empty).
    pub fn of(values: &[f64]) -> Stats {
        if values.is_empty() {
            return Stats::default();
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        let mut s = values.to_vec();
        s.sort_by(f64::total_cmp);
        let m = s.len();
        let median = if m % 2 == 1 { s[m / 2] } else { 0.5 * (s[m / 2 - 1] + s[m / 2]) };
        Stats { mean, std: var.sqrt(), median }
    }
}

/// One method's row.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodResult {
    /// The method.
    pub method: Method,
    /// Its name in the table ([`Method::label`]).
    pub label: String,
    /// Decoder parameters (the seed compares these).
    pub decoder_params: usize,
    /// Encoder parameters (the same for every method).
    pub encoder_params: usize,
    /// Test images evaluated.
    pub images: usize,
    /// Mismatched pixels per image on the 28 × 28 grid.
    pub mismatched_pixels: Stats,
    /// IoU per image on the 28 × 28 grid.
    pub iou: Stats,
    /// IoU per image on the 112 × 112 grid, over the first `images_fine` images.
    pub iou_fine: Stats,
    /// Test images in the fine IoU (it costs 16× the 28 × 28 evaluation).
    pub images_fine: usize,
    /// Per-image mismatched pixels (for plots and tests).
    #[serde(skip)]
    pub per_image: Vec<f64>,
}

/// Occupancy grids of one decoded image: `n × n` cell centres, row-major.
pub fn decoded_grid(model: &Model, code: &[f32], n: usize, scratch: &mut Option<OccNetScratch>) -> Vec<bool> {
    let pts: Vec<[f64; 2]> =
        (0..n * n).map(|i| [((i % n) as f64 + 0.5) / n as f64, ((i / n) as f64 + 0.5) / n as f64]).collect();
    match model.method {
        Method::Voronoi => {
            let sites = model.decode_sites(code).expect("a Voronoi model").remove(0);
            hard_occupancy(&sites, &pts)
        }
        Method::OccNet { .. } => model.occupancy(code, &pts, scratch),
    }
}

fn iou(a: &[bool], b: &[bool]) -> f64 {
    let (mut i, mut u) = (0usize, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        i += usize::from(x && y);
        u += usize::from(x || y);
    }
    if u == 0 {
        1.0
    } else {
        i as f64 / u as f64
    }
}

/// Evaluates `model` on the first `limit` digits of `test`, the fine IoU on the first
/// `fine_limit` of those.
pub fn evaluate(model: &Model, test: &DigitSet, limit: usize, fine_limit: usize) -> MethodResult {
    let n = limit.min(test.len());
    let n_fine = fine_limit.min(n);
    let (rows, cols) = (test.images.rows, test.images.cols);
    let images: Vec<&[u8]> = (0..n).map(|i| test.images.image(i)).collect();
    let codes = model.encode(&images);
    let side = rows.max(cols);
    let per: Vec<(f64, f64, f64)> = (0..n)
        .into_par_iter()
        .map_init(
            || None,
            |scratch, i| {
                let digit = Digit::new(images[i], rows, cols);
                let code = &codes[i * LATENT..(i + 1) * LATENT];
                let truth = digit.grid(side);
                let got = decoded_grid(model, code, side, scratch);
                let mismatched = truth.iter().zip(&got).filter(|(a, b)| a != b).count() as f64;
                let fine_iou = if i < n_fine {
                    let fine_truth = digit.grid(side * SUPERSAMPLE);
                    let fine = decoded_grid(model, code, side * SUPERSAMPLE, scratch);
                    iou(&fine_truth, &fine)
                } else {
                    f64::NAN
                };
                (mismatched, iou(&truth, &got), fine_iou)
            },
        )
        .collect();
    let (dp, ep) = model.param_counts();
    let mism: Vec<f64> = per.iter().map(|p| p.0).collect();
    MethodResult {
        method: model.method,
        label: model.method.label(),
        decoder_params: dp,
        encoder_params: ep,
        images: n,
        mismatched_pixels: Stats::of(&mism),
        iou: Stats::of(&per.iter().map(|p| p.1).collect::<Vec<_>>()),
        iou_fine: Stats::of(&per.iter().map(|p| p.2).filter(|v| !v.is_nan()).collect::<Vec<_>>()),
        images_fine: n_fine,
        per_image: mism,
    }
}

/// The seed's table (its Table 2 as the issue quotes it): (label, mean, std, median).
pub const SEED_TABLE: [(&str, f64, f64, f64); 4] = [
    ("OccNet 128", 83.8, 28.2, 85.7),
    ("OccNet 512", 76.2, 28.2, 75.4),
    ("OccNet 16k", 52.7, 14.3, 53.0),
    ("Voronoi 128", 58.0, 17.0, 58.3),
];

/// The Markdown table: ours next to the seed's numbers.
pub fn table_markdown(results: &[MethodResult]) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "| method | decoder params | mismatched pixels mean / std / median | seed's mean / std / median | IoU 28² | IoU 112² (first {}) |\n",
        results.first().map_or(0, |r| r.images_fine)
    ));
    s.push_str("|---|---|---|---|---|---|\n");
    for r in results {
        let seed = SEED_TABLE
            .iter()
            .find(|t| t.0 == r.label)
            .map_or_else(|| "–".to_string(), |t| format!("{:.1} / {:.1} / {:.1}", t.1, t.2, t.3));
        s.push_str(&format!(
            "| {} | {} | {:.1} / {:.1} / {:.1} | {} | {:.3} | {:.3} |\n",
            r.label,
            group(r.decoder_params),
            r.mismatched_pixels.mean,
            r.mismatched_pixels.std,
            r.mismatched_pixels.median,
            seed,
            r.iou.mean,
            r.iou_fine.mean
        ));
    }
    s
}

pub use vf_common::text::group;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_and_grouping() {
        let s = Stats::of(&[1.0, 3.0, 2.0, 10.0]);
        assert_eq!(s.mean, 4.0);
        assert_eq!(s.median, 2.5);
        assert!((s.std - ((9.0f64 + 1.0 + 4.0 + 36.0) / 4.0).sqrt()).abs() < 1e-12);
        assert_eq!(group(1234567), "1,234,567");
        assert_eq!(group(128), "128");
        assert_eq!(iou(&[true, false], &[false, false]), 0.0);
        assert_eq!(iou(&[false], &[false]), 1.0);
    }
}
