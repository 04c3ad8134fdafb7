//! tSNE of latent codes with the `bhtsne` crate (Barnes–Hut, θ = 0.5), seeded: the
//! initial embedding is drawn here (N(0, 10⁻⁴), as van der Maaten's code does) instead
//! of by the crate's unseeded generator, so a run is reproducible.

use serde::{Deserialize, Serialize};
use vf_common::{ChunkRng, Stream};

use crate::error::MnistError;

/// Settings of the embedding.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct TsneSettings {
    /// Perplexity (scikit-learn's default 30).
    pub perplexity: f64,
    /// Barnes–Hut θ.
    pub theta: f64,
    /// Gradient-descent iterations.
    pub epochs: usize,
    /// Seed of the initial embedding.
    pub seed: u64,
}

impl Default for TsneSettings {
    fn default() -> Self {
        TsneSettings { perplexity: 30.0, theta: 0.5, epochs: 1000, seed: 0 }
    }
}

/// An embedding and its cost.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Embedding {
    /// One 2D point per code.
    pub points: Vec<[f64; 2]>,
    /// bhtsne's own cost estimate of the result (`tSNE::kl_divergence`). It is not the
    /// exact KL divergence: on 1,000 MNIST codes it read 3.7 where the exact value (by
    /// scikit-learn's formula, tests/reference/test_mnist.py) was 1.7, so it is kept for
    /// reference only and the quality check uses the exact value.
    pub bhtsne_cost: f64,
}

/// Embeds `codes` (`n × dim`, row-major) in 2D.
///
/// # Errors
/// [`MnistError::Config`] when there are too few codes for the perplexity (bhtsne needs
/// n − 1 ≥ 3 × perplexity) or a code is not finite.
pub fn embed(codes: &[f32], dim: usize, settings: &TsneSettings) -> Result<Embedding, MnistError> {
    let n = codes.len() / dim.max(1);
    if dim == 0 || n * dim != codes.len() {
        return Err(MnistError::Config(format!("{} numbers are not a whole number of {dim}-d codes", codes.len())));
    }
    if (n as f64 - 1.0) < 3.0 * settings.perplexity {
        return Err(MnistError::Config(format!(
            "{n} codes are too few for perplexity {} (need at least {})",
            settings.perplexity,
            (3.0 * settings.perplexity).ceil() as usize + 1
        )));
    }
    if codes.iter().any(|c| !c.is_finite()) {
        return Err(MnistError::Config("a latent code is not finite".into()));
    }
    let rows: Vec<&[f32]> = codes.chunks_exact(dim).collect();
    let mut rng = ChunkRng::for_chunk(settings.seed, Stream::MnistTsne, 0);
    let init: Vec<f32> = (0..2 * n).map(|_| (1e-4 * rng.normal()) as f32).collect();
    let mut t: bhtsne::tSNE<f32, &[f32]> = bhtsne::tSNE::new(&rows);
    t.embedding_dim(2)
        .perplexity(settings.perplexity as f32)
        .epochs(settings.epochs)
        .initial_embedding(init)
        .barnes_hut(settings.theta as f32, |a, b| {
            a.iter().zip(b.iter()).map(|(x, y)| (x - y) * (x - y)).sum::<f32>().sqrt()
        });
    let y = t.embedding();
    let kl = t.kl_divergence().map_or(f64::NAN, f64::from);
    Ok(Embedding { points: y.chunks_exact(2).map(|p| [f64::from(p[0]), f64::from(p[1])]).collect(), bhtsne_cost: kl })
}
