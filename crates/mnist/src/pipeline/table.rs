//! The table on the test set: every model evaluated, written as `table.md`,
//! `results.json` and `results.csv`.

use std::path::Path;

use super::{load_models, write_text, DataSource, Experiment, Report};
use crate::error::MnistError;
use crate::eval::{self, MethodResult};
use crate::idx::DigitSet;
use crate::model::Model;

/// Test images in the 112 × 112 IoU (16× the work of the 28 × 28 grid; OccNet 16k takes
/// about 40 ms an image there).
pub const FINE_IMAGES: usize = 1000;

/// Options of the evaluation.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EvalOptions {
    /// Test images evaluated, the first N (default: all, quick 1,000).
    pub test_count: Option<usize>,
}

/// The `mnist eval` command: reads the test set and the trained models, checks that they
/// fit ([`check_sizes`]) and runs [`evaluate_models`].
///
/// # Errors
/// Those of [`DataSource::load`], [`load_models`], [`check_sizes`] and
/// [`evaluate_models`].
pub fn evaluate(
    exp: &Experiment,
    opts: &EvalOptions,
    data: &DataSource,
    report: &mut dyn Report,
) -> Result<Vec<MethodResult>, MnistError> {
    let test = data.load(true)?;
    let models = load_models(exp, report)?;
    check_sizes(&models, &test)?;
    let n = opts.test_count.unwrap_or(if exp.quick { 1000 } else { usize::MAX });
    evaluate_models(exp, &models, &test, n, report)
}

/// Checks that the models take images of the test set's size and that the set is not
/// empty.
///
/// # Errors
/// [`MnistError::Options`] naming the test set.
pub fn check_sizes(models: &[Model], test: &DigitSet) -> Result<(), MnistError> {
    let pixels = test.images.rows * test.images.cols;
    if let Some(m) = models.iter().find(|m| m.encoder.n_in() != pixels) {
        return Err(MnistError::Options(format!(
            "{}: {}×{} images, but the {} model was trained on {} pixels per image",
            test.source.display(),
            test.images.rows,
            test.images.cols,
            m.method.name(),
            m.encoder.n_in()
        )));
    }
    if test.is_empty() {
        return Err(MnistError::Options(format!("{}: the test set is empty", test.source.display())));
    }
    Ok(())
}

/// Evaluates every model on the first `n` test digits (the 112 × 112 IoU on the first
/// [`FINE_IMAGES`]) and writes the results ([`write_results`]).
///
/// # Errors
/// [`MnistError::Write`].
pub fn evaluate_models(
    exp: &Experiment,
    models: &[Model],
    test: &DigitSet,
    n: usize,
    report: &mut dyn Report,
) -> Result<Vec<MethodResult>, MnistError> {
    report.eval_start(models.len());
    let mut results = Vec::new();
    for m in models {
        report.eval_method(m.method);
        results.push(eval::evaluate(m, test, n, FINE_IMAGES));
        report.eval_method_done(m.method);
    }
    report.eval_end();
    write_results(&exp.out, &results, test)?;
    Ok(results)
}

/// Writes `out/table.md` (the seed's table beside ours), `out/results.json` and
/// `out/results.csv`, each atomically.
///
/// # Errors
/// [`MnistError::Write`].
pub fn write_results(out: &Path, results: &[MethodResult], test: &DigitSet) -> Result<(), MnistError> {
    let mut md = String::new();
    md.push_str(&format!(
        "Test set: the first {} digits of {} (mismatched pixels on the 28 × 28 grid: per image; IoU: mean per image).\n\n",
        results.first().map_or(0, |r| r.images),
        test.source.display()
    ));
    md.push_str(&eval::table_markdown(results));
    write_text(&out.join("table.md"), &md)?;
    let json = serde_json::to_string_pretty(results).map_err(|e| MnistError::Write(e.to_string()))?;
    write_text(&out.join("results.json"), &json)?;
    let mut csv = String::from("method,decoder_params,encoder_params,images,mismatched_mean,mismatched_std,mismatched_median,iou28,iou112,images112\n");
    for r in results {
        csv.push_str(&format!(
            "{},{},{},{},{:.3},{:.3},{:.1},{:.5},{:.5},{}\n",
            r.method.name(),
            r.decoder_params,
            r.encoder_params,
            r.images,
            r.mismatched_pixels.mean,
            r.mismatched_pixels.std,
            r.mismatched_pixels.median,
            r.iou.mean,
            r.iou_fine.mean,
            r.images_fine
        ));
    }
    write_text(&out.join("results.csv"), &csv)
}
