//! The autoencoders: one encoder shape shared by every method, and either the Voronoi
//! decoder (code → 128 labelled sites) or an OccNet decoder (code + point → occupancy).

use serde::{Deserialize, Serialize};
use soft_voronoi::losses::{self, SiteGraph};
use soft_voronoi::{Kernel, SiteIndex};
use vf_common::{ChunkRng, Stream};

use crate::digit::Digit;
use crate::error::MnistError;
use crate::net::{occnet_logits, Dense, OccNetScratch, Tape};

/// Latent code size.
pub const LATENT: usize = 16;
/// Width of the encoder's and the Voronoi decoder's hidden layers.
pub const WIDTH: usize = 1024;
/// Sites of the Voronoi decoder: the first half inside, the second half outside.
pub const SITES: usize = 128;

/// Which decoder.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Method {
    /// 3 hidden layers of 1,024 → 128 sites in 2D.
    Voronoi,
    /// One hidden layer of `hidden` units on [code; point] → occupancy logit.
    OccNet {
        /// Hidden units.
        hidden: usize,
    },
}

impl Method {
    /// The seed's four methods, in table order.
    pub fn all() -> Vec<Method> {
        vec![
            Method::OccNet { hidden: 128 },
            Method::OccNet { hidden: 512 },
            Method::OccNet { hidden: 16384 },
            Method::Voronoi,
        ]
    }

    /// Short name: `voronoi`, `occnet128`, ….
    pub fn name(&self) -> String {
        match self {
            Method::Voronoi => "voronoi".into(),
            Method::OccNet { hidden } => format!("occnet{hidden}"),
        }
    }

    /// Display name as in the seed's table.
    pub fn label(&self) -> String {
        match self {
            Method::Voronoi => format!("Voronoi {SITES}"),
            Method::OccNet { hidden } if *hidden >= 1024 && hidden % 1024 == 0 => format!("OccNet {}k", hidden / 1024),
            Method::OccNet { hidden } => format!("OccNet {hidden}"),
        }
    }

    /// Layer sizes of the decoder.
    pub fn decoder_sizes(&self) -> Vec<usize> {
        match self {
            Method::Voronoi => vec![LATENT, WIDTH, WIDTH, WIDTH, 2 * SITES],
            Method::OccNet { hidden } => vec![LATENT + 2, *hidden, 1],
        }
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s == "voronoi" {
            return Ok(Method::Voronoi);
        }
        if let Some(h) = s.strip_prefix("occnet") {
            let h = h.strip_suffix('k').map_or_else(|| h.parse::<usize>(), |k| k.parse::<usize>().map(|k| k * 1024));
            if let Ok(h) = h {
                if (1..=65536).contains(&h) {
                    return Ok(Method::OccNet { hidden: h });
                }
            }
        }
        Err(format!(
            "unknown method '{s}' (expected voronoi, occnet128, occnet512, occnet16k or occnetN with N in 1..=65536)"
        ))
    }
}

/// Layer sizes of the encoder for `pixels`-pixel images: four hidden layers of 1,024 units
/// and a linear layer to the 16-d code.
pub fn encoder_sizes(pixels: usize) -> Vec<usize> {
    vec![pixels, WIDTH, WIDTH, WIDTH, WIDTH, LATENT]
}

/// Weights of the Voronoi decoder's loss terms (the seed's four).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct VoronoiLoss {
    /// β of the soft-argmin (the seed: 10,000, in unit-square lengths).
    pub beta: f64,
    /// Reconstruction E|O − V|.
    pub reconstruction: f64,
    /// Bounds Σ max(−p, 0) + max(p − 1, 0).
    pub bounds: f64,
    /// Distance of each site to its side of the digit.
    pub signed_distance: f64,
    /// Centroidal ‖L p‖² on the Delaunay graph.
    pub centroidal: f64,
}

impl Default for VoronoiLoss {
    fn default() -> Self {
        VoronoiLoss { beta: 10_000.0, reconstruction: 1.0, bounds: 1.0, signed_distance: 1.0, centroidal: 1.0 }
    }
}

/// The labels of the decoder's sites: the first half inside.
pub fn site_labels() -> Vec<bool> {
    (0..SITES).map(|k| k < SITES / 2).collect()
}

/// Sites from the decoder's output row (2 × SITES numbers): 0.5 + output, so an untrained
/// decoder spreads them around the middle of the square.
pub fn sites_of(row: &[f32]) -> Vec<[f64; 2]> {
    row.chunks_exact(2).map(|c| [0.5 + f64::from(c[0]), 0.5 + f64::from(c[1])]).collect()
}

/// The exact 2D Delaunay edges of `sites` (spade), for the centroidal term.
pub fn delaunay_graph(sites: &[[f64; 2]]) -> SiteGraph {
    let labels = vec![false; sites.len()];
    let edges =
        crust::planar::planar_diagram(sites, &labels, [0.0; 2], [1.0; 2]).map(|d| d.delaunay_edges).unwrap_or_default();
    SiteGraph::from_edges(sites.len(), edges)
}

/// The four loss terms of one image (unweighted), and the weighted total.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LossParts {
    /// The weighted sum of the four terms (an OccNet's: its cross-entropy).
    pub total: f64,
    /// Reconstruction E|O − V| of the soft occupancy at the training points.
    pub reconstruction: f64,
    /// Bounds: how far sites lie outside the unit square.
    pub bounds: f64,
    /// Distance of each site to its side of the digit.
    pub signed_distance: f64,
    /// Centroidal ‖L p‖² on the Delaunay graph.
    pub centroidal: f64,
}

/// The Voronoi decoder's loss for one image and its gradient with respect to the sites
/// (added into `grad`): the soft-Voronoi kernel, losses and Delaunay graph of the
/// `soft_voronoi` crate in two dimensions.
pub fn voronoi_loss_grad(
    cfg: &VoronoiLoss,
    digit: &Digit,
    boundary: &[[f64; 2]],
    sites: &[[f64; 2]],
    points: &[[f64; 2]],
    occupancy: &[bool],
    grad: &mut [[f64; 2]],
) -> LossParts {
    let labels = site_labels();
    let kernel = Kernel::new(cfg.beta);
    let mut parts = LossParts::default();
    if sites.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
        parts.total = f64::NAN;
        return parts;
    }
    let index = SiteIndex::<2>::new(sites);
    parts.reconstruction =
        losses::reconstruction(&kernel, &index, sites, &labels, points, occupancy, cfg.reconstruction, grad);
    parts.bounds = losses::bounds(sites, cfg.bounds, grad);
    if cfg.signed_distance > 0.0 {
        let located = digit.locate(boundary, sites);
        parts.signed_distance = losses::signed_distance_cached(&located, sites, &labels, cfg.signed_distance, grad);
    }
    if cfg.centroidal > 0.0 {
        let graph = delaunay_graph(sites);
        parts.centroidal = losses::centroidal(&graph, sites, cfg.centroidal, grad);
    }
    parts.total = cfg.reconstruction * parts.reconstruction
        + cfg.bounds * parts.bounds
        + cfg.signed_distance * parts.signed_distance
        + cfg.centroidal * parts.centroidal;
    parts
}

/// An autoencoder: encoder and decoder.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    /// Which decoder.
    pub method: Method,
    /// Image → code.
    pub encoder: Dense,
    /// Code → sites, or (code, point) → logit.
    pub decoder: Dense,
}

impl Model {
    /// A freshly initialised model for images of `pixels` pixels, from `seed`.
    pub fn new(method: Method, pixels: usize, seed: u64) -> Self {
        let mut rng = ChunkRng::for_chunk(seed, Stream::MnistInit, 0);
        let encoder = Dense::new(&encoder_sizes(pixels), &mut rng);
        let mut rng = ChunkRng::for_chunk(seed, Stream::MnistInit, 1);
        let decoder = Dense::new(&method.decoder_sizes(), &mut rng);
        Model { method, encoder, decoder }
    }

    /// Parameters of the decoder alone (the seed's comparison) and of the encoder.
    pub fn param_counts(&self) -> (usize, usize) {
        (self.decoder.params.len(), self.encoder.params.len())
    }

    /// Codes of `images` (each `pixels` bytes), `n × LATENT`, in fixed-size chunks.
    pub fn encode(&self, images: &[&[u8]]) -> Vec<f32> {
        use rayon::prelude::*;
        let chunks: Vec<Vec<f32>> = images
            .par_chunks(64)
            .map(|chunk| {
                let x = pixels_to_input(chunk);
                let mut t = Tape::default();
                self.encoder.forward(&x, chunk.len(), &mut t);
                t.output().to_vec()
            })
            .collect();
        chunks.concat()
    }

    /// The decoded sites of each code (Voronoi decoder only).
    pub fn decode_sites(&self, codes: &[f32]) -> Result<Vec<Vec<[f64; 2]>>, MnistError> {
        if self.method != Method::Voronoi {
            return Err(MnistError::Config(format!("{} decodes no sites", self.method.label())));
        }
        let n = codes.len() / LATENT;
        let mut t = Tape::default();
        self.decoder.forward(codes, n, &mut t);
        Ok(t.output().chunks_exact(2 * SITES).map(sites_of).collect())
    }

    /// Occupancy of the decoded shape of `code` at `points`: the label of the nearest site
    /// (exact: the hard Voronoi occupancy), or the OccNet logit ≥ 0.
    pub fn occupancy(&self, code: &[f32], points: &[[f64; 2]], scratch: &mut Option<OccNetScratch>) -> Vec<bool> {
        match self.method {
            Method::Voronoi => {
                let sites = self.decode_sites(code).expect("a Voronoi model").remove(0);
                hard_occupancy(&sites, points)
            }
            Method::OccNet { hidden } => {
                let s = scratch.get_or_insert_with(|| OccNetScratch::new(hidden));
                let mut logits = Vec::new();
                occnet_logits(&self.decoder, code, points, s, &mut logits);
                logits.iter().map(|&l| l >= 0.0).collect()
            }
        }
    }
}

/// The label of the nearest site at each point (sites with a non-finite coordinate give
/// "outside" everywhere).
pub fn hard_occupancy(sites: &[[f64; 2]], points: &[[f64; 2]]) -> Vec<bool> {
    if sites.iter().any(|p| !(p[0].is_finite() && p[1].is_finite())) {
        return vec![false; points.len()];
    }
    let labels = site_labels();
    let index = SiteIndex::<2>::new(sites);
    points.iter().map(|&x| soft_voronoi::kernel::hard_label(&index, sites, &labels, x)).collect()
}

/// Network input of images: intensities / 255, row-major.
pub fn pixels_to_input(images: &[&[u8]]) -> Vec<f32> {
    images.iter().flat_map(|im| im.iter().map(|&v| f32::from(v) / 255.0)).collect()
}
