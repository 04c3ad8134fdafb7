//! The pictures of the trained models: the tSNE of the test codes, and the latent
//! interpolation with the reconstructions.

use std::path::PathBuf;
use std::time::Instant;

use super::{check_sizes, load_models, DataSource, Experiment, Report};
use crate::error::MnistError;
use crate::figures::{self, Interpolation};
use crate::idx::DigitSet;
use crate::model::{Method, Model, LATENT};
use crate::tsne::{embed, TsneSettings};

/// Options of the tSNE.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TsneOptions {
    /// Test codes embedded, the first N (default: 10,000, quick 500; at most the set).
    pub count: Option<usize>,
    /// Iterations (default: 1,000, quick 300).
    pub iterations: Option<usize>,
}

/// One tSNE done.
#[derive(Clone, Debug, PartialEq)]
pub struct TsneReport {
    /// Whose codes.
    pub method: Method,
    /// Codes embedded.
    pub codes: usize,
    /// Seconds of the embedding.
    pub seconds: f64,
    /// bhtsne's own cost estimate ([`crate::tsne::Embedding::bhtsne_cost`]).
    pub bhtsne_cost: f64,
    /// The files written: `stem.png`, `stem.svg` and `stem.npz`.
    pub stem: PathBuf,
}

/// Options of the interpolation.
#[derive(Clone, Debug, PartialEq)]
pub struct InterpolateOptions {
    /// Digit pairs `A:B`: from the first test digit of class A to the first of class B.
    pub pairs: Vec<String>,
    /// Interpolation steps, both ends included (2 to 32).
    pub steps: usize,
}

impl Default for InterpolateOptions {
    /// 3 → 5 and 9 → 6 in 8 steps.
    fn default() -> Self {
        InterpolateOptions { pairs: vec!["3:5".into(), "9:6".into()], steps: 8 }
    }
}

/// The interpolation figures written.
#[derive(Clone, Debug, PartialEq)]
pub struct InterpolationReport {
    /// Pairs drawn.
    pub pairs: usize,
    /// Steps per pair.
    pub steps: usize,
    /// The Voronoi model drawn.
    pub voronoi: Method,
    /// The OccNet model drawn beside it (the widest given).
    pub occnet: Method,
    /// The folder of `interpolation.png/.svg` and `reconstructions.png/.svg`.
    pub out: PathBuf,
}

/// The `mnist tsne` command: reads the test set and the trained models and runs
/// [`tsne_model`] for each.
///
/// # Errors
/// Those of [`DataSource::load`], [`load_models`], [`check_sizes`] and [`tsne_model`].
pub fn tsne(
    exp: &Experiment,
    opts: &TsneOptions,
    data: &DataSource,
    report: &mut dyn Report,
) -> Result<Vec<TsneReport>, MnistError> {
    let test = data.load(true)?;
    let models = load_models(exp, report)?;
    check_sizes(&models, &test)?;
    models.iter().map(|m| tsne_model(exp, m, &test, opts, report)).collect()
}

/// Embeds the codes of the first test digits with tSNE and writes `tsne_METHOD.png/.svg`
/// (coloured by class) and `tsne_METHOD.npz` (codes, embedding, labels, bhtsne's cost,
/// perplexity).
///
/// # Errors
/// [`MnistError::Config`] for too few codes for the perplexity; [`MnistError::Write`].
pub fn tsne_model(
    exp: &Experiment,
    model: &Model,
    test: &DigitSet,
    opts: &TsneOptions,
    report: &mut dyn Report,
) -> Result<TsneReport, MnistError> {
    let n = opts.count.unwrap_or(if exp.quick { 500 } else { 10_000 }).min(test.len());
    let images: Vec<&[u8]> = (0..n).map(|i| test.images.image(i)).collect();
    let codes = model.encode(&images);
    let settings = TsneSettings {
        epochs: opts.iterations.unwrap_or(if exp.quick { 300 } else { 1000 }),
        ..TsneSettings::default()
    };
    let t = Instant::now();
    report.tsne_start(model.method, n);
    let emb = embed(&codes, LATENT, &settings)?;
    let seconds = t.elapsed().as_secs_f64();
    let labels = &test.labels[..n];
    let title = format!(
        "tSNE of the {} encoder's codes of {n} test digits (perplexity {})",
        model.method.label(),
        settings.perplexity
    );
    let d = figures::tsne_drawing(&emb.points, labels, &title);
    let stem = exp.out.join(format!("tsne_{}", model.method.name()));
    figures::write_both(&d, &stem)?;
    let mut npz = vf_common::npz::NpzOut::new();
    npz.add_vec("codes", codes)?;
    npz.add_vec("embedding", emb.points.iter().flat_map(|p| *p).collect::<Vec<f64>>())?;
    npz.add_vec("labels", labels.to_vec())?;
    npz.add_vec("bhtsne_cost", vec![emb.bhtsne_cost])?;
    npz.add_vec("perplexity", vec![settings.perplexity])?;
    npz.write(&stem.with_extension("npz"))?;
    let r = TsneReport { method: model.method, codes: n, seconds, bhtsne_cost: emb.bhtsne_cost, stem };
    report.tsne_done(&r);
    Ok(r)
}

/// The `mnist interpolate` command: reads the test set and the trained models and runs
/// [`interpolate_models`].
///
/// # Errors
/// Those of [`DataSource::load`], [`load_models`], [`check_sizes`] and
/// [`interpolate_models`].
pub fn interpolate(
    exp: &Experiment,
    opts: &InterpolateOptions,
    data: &DataSource,
    report: &mut dyn Report,
) -> Result<InterpolationReport, MnistError> {
    let test = data.load(true)?;
    let models = load_models(exp, report)?;
    check_sizes(&models, &test)?;
    interpolate_models(exp, &models, &test, opts, report)
}

/// Draws the latent interpolation of each pair (the Voronoi model beside the widest OccNet
/// model) as `interpolation.png/.svg`, and the reconstructions of the first test digit of
/// each class by every model as `reconstructions.png/.svg`.
///
/// # Errors
/// [`MnistError::Options`] for steps out of 2..=32, a malformed pair, a class the test set
/// lacks, or no Voronoi or no OccNet model; [`MnistError::Write`].
pub fn interpolate_models(
    exp: &Experiment,
    models: &[Model],
    test: &DigitSet,
    opts: &InterpolateOptions,
    report: &mut dyn Report,
) -> Result<InterpolationReport, MnistError> {
    let steps = opts.steps;
    if !(2..=32).contains(&steps) {
        return Err(MnistError::Options(format!("--steps {steps}: must be in 2..=32")));
    }
    let voronoi = models.iter().find(|m| m.method == Method::Voronoi).ok_or_else(|| {
        MnistError::Options("the interpolation needs the voronoi model: include voronoi in --methods".into())
    })?;
    let occnet = models
        .iter()
        .filter(|m| matches!(m.method, Method::OccNet { .. }))
        .max_by_key(|m| m.decoder.params.len())
        .ok_or_else(|| {
            MnistError::Options("the interpolation needs an OccNet model: include one in --methods".into())
        })?;
    let first_of = |class: u8| test.labels.iter().position(|&l| l == class);
    let mut list = Vec::new();
    for p in &opts.pairs {
        let parse = |s: &str| s.trim().parse::<u8>().ok().filter(|&d| d <= 9);
        let (a, b) = p
            .split_once(':')
            .and_then(|(a, b)| Some((parse(a)?, parse(b)?)))
            .ok_or_else(|| MnistError::Options(format!("--pairs {p}: a pair is two digits A:B, e.g. 3:5")))?;
        let (ia, ib) = (first_of(a), first_of(b));
        let (Some(ia), Some(ib)) = (ia, ib) else {
            return Err(MnistError::Options(format!(
                "--pairs {p}: the test set has no digit {}",
                if ia.is_none() { a } else { b }
            )));
        };
        list.push(Interpolation {
            title: format!("{a} to {b} (test digits #{ia} and #{ib})"),
            a: (test.images.image(ia), a),
            b: (test.images.image(ib), b),
            rows: test.images.rows,
            cols: test.images.cols,
        });
    }
    let d = figures::interpolation_drawing(voronoi, occnet, &list, steps);
    figures::write_both(&d, &exp.out.join("interpolation"))?;
    // Reconstructions of the first test digit of each class, in test-set order.
    let mut picks: Vec<usize> = (0..10u8).filter_map(first_of).collect();
    picks.sort_unstable();
    let digits: Vec<(&[u8], u8)> = picks.iter().map(|&i| (test.images.image(i), test.labels[i])).collect();
    let refs: Vec<&Model> = models.iter().collect();
    let r = figures::reconstructions_drawing(&refs, &digits, test.images.rows, test.images.cols);
    figures::write_both(&r, &exp.out.join("reconstructions"))?;
    let r = InterpolationReport {
        pairs: list.len(),
        steps,
        voronoi: voronoi.method,
        occnet: occnet.method,
        out: exp.out.clone(),
    };
    report.interpolation_done(&r);
    Ok(r)
}
