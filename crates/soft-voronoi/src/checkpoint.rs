//! Checkpoints: the whole [`TrainState`] in one `.npz` (readable with `numpy.load`),
//! written atomically, restored bit-exactly.
//!
//! | array | shape, dtype | meaning |
//! |---|---|---|
//! | `format_version` | (1,) int64 | 1 |
//! | `config_json` | (n,) uint8 | the [`TrainConfig`](crate::TrainConfig) as UTF-8 JSON |
//! | `context_json` | (n,) uint8 | the caller's JSON (the CLI: input mesh, sampling, transform) |
//! | `step` | (1,) uint64 | steps done |
//! | `sites` | (K+B, 3) float64 | trainable then boundary sites, unit cube |
//! | `labels` | (K+B,) uint8 | 1 = inside |
//! | `adam_m`, `adam_v` | (K, 3) float64 | Adam moments |
//! | `graph_offsets`, `graph_neighbors` | uint32 | Delaunay graph at the last refresh (CSR) |
//! | `located_inside`, `located_closest` | (K,) uint8, (K, 3) float64 | sides and closest surface points at the last refresh |
//! | `history` | (steps, 10) float64 (9 in checkpoints written before the surface term) | per-step statistics ([`StepStats::NAMES`](crate::StepStats::NAMES)) |
//! | `data_fingerprint` | (1,) uint64 | fingerprint of the training samples |
//! | `best_step`, `best_loss`, `best_sites` | (1,) uint64, (1,) float64, (K, 3) float64 | the best iterate so far ([`TrainConfig::select_every`](crate::TrainConfig::select_every)); absent when there is none (and in older checkpoints) |
//!
//! f64 values are stored bit for bit, so a resumed run repeats the uninterrupted one
//! exactly.

use std::io::Cursor;
use std::path::Path;

use ndarray::Array2;
use ndarray_npy::NpzReader;
use vf_common::npz::NpzOut;

use crate::error::TrainError;
use crate::losses::{Located, SiteGraph};
use crate::train::{BestIterate, StepStats, TrainState};

/// The checkpoint format version.
pub const FORMAT_VERSION: i64 = 1;

/// Writes `state` and the caller's `context_json` to `path` atomically (temporary file
/// beside it, then rename).
///
/// # Errors
/// [`TrainError::Checkpoint`] when the file cannot be written.
pub fn write(path: &Path, state: &TrainState, context_json: &str) -> Result<(), TrainError> {
    let fail = |message: String| TrainError::Checkpoint { path: path.display().to_string(), message };
    let config = serde_json::to_string(&state.config).map_err(|e| fail(e.to_string()))?;
    let closest: Vec<[f64; 3]> = state.located.iter().map(|l| l.closest).collect();
    let hist: Vec<f64> = state.history.iter().flat_map(|s| s.to_row()).collect();
    let hist = Array2::from_shape_vec((state.history.len(), StepStats::COLUMNS), hist).expect("S×COLUMNS");
    let mut w = NpzOut::new();
    w.add_vec("format_version", vec![FORMAT_VERSION])
        .and_then(|w| w.add_vec("config_json", config.into_bytes()))
        .and_then(|w| w.add_vec("context_json", context_json.as_bytes().to_vec()))
        .and_then(|w| w.add_vec("step", vec![state.step as u64]))
        .and_then(|w| w.add_rows("sites", &state.sites))
        .and_then(|w| w.add_vec("labels", state.labels.iter().map(|&b| b as u8).collect::<Vec<u8>>()))
        .and_then(|w| w.add_rows("adam_m", &state.m))
        .and_then(|w| w.add_rows("adam_v", &state.v))
        .and_then(|w| w.add_vec("graph_offsets", state.graph.offsets.clone()))
        .and_then(|w| w.add_vec("graph_neighbors", state.graph.neighbors.clone()))
        .and_then(|w| w.add_vec("located_inside", state.located.iter().map(|l| l.inside as u8).collect::<Vec<u8>>()))
        .and_then(|w| w.add_rows("located_closest", &closest))
        .and_then(|w| w.add("history", &hist))
        .and_then(|w| w.add_vec("data_fingerprint", vec![state.data_fingerprint]))
        .map_err(|e| fail(e.to_string()))?;
    if let Some(b) = &state.best {
        w.add_vec("best_step", vec![b.step as u64])
            .and_then(|w| w.add_vec("best_loss", vec![b.loss]))
            .and_then(|w| w.add_rows("best_sites", &b.sites))
            .map_err(|e| fail(e.to_string()))?;
    }
    w.write(path).map_err(|e| fail(e.to_string()))
}

/// Reads a checkpoint: the state and the caller's context JSON.
///
/// # Errors
/// [`TrainError::Checkpoint`] naming the missing or malformed array.
pub fn read(path: &Path) -> Result<(TrainState, String), TrainError> {
    let fail = |message: String| TrainError::Checkpoint { path: path.display().to_string(), message };
    let bytes = std::fs::read(path).map_err(|e| fail(format!("cannot read ({e})")))?;
    let mut npz = NpzReader::new(Cursor::new(bytes)).map_err(|e| fail(format!("not an .npz archive ({e})")))?;
    macro_rules! arr1 {
        ($name:literal, $t:ty) => {
            npz.by_name::<ndarray::OwnedRepr<$t>, ndarray::Ix1>($name)
                .map_err(|e| fail(format!("array '{}': {e}", $name)))?
                .to_vec()
        };
    }
    macro_rules! arr2 {
        ($name:literal) => {{
            let a: Array2<f64> =
                npz.by_name($name).map_err(|e| fail(format!("array '{}' (n×3 float64): {e}", $name)))?;
            if a.ncols() != 3 && a.nrows() > 0 {
                return Err(fail(format!("array '{}' has {} columns, expected 3", $name, a.ncols())));
            }
            a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect::<Vec<[f64; 3]>>()
        }};
    }
    let version = arr1!("format_version", i64);
    if version != [FORMAT_VERSION] {
        return Err(fail(format!("format_version {version:?}; this build reads {FORMAT_VERSION}")));
    }
    let config_json =
        String::from_utf8(arr1!("config_json", u8)).map_err(|_| fail("config_json is not UTF-8".into()))?;
    let config = serde_json::from_str(&config_json).map_err(|e| fail(format!("config_json: {e}")))?;
    let context = String::from_utf8(arr1!("context_json", u8)).map_err(|_| fail("context_json is not UTF-8".into()))?;
    let step = arr1!("step", u64);
    let sites = arr2!("sites");
    let labels: Vec<bool> = arr1!("labels", u8).into_iter().map(|b| b != 0).collect();
    let m = arr2!("adam_m");
    let v = arr2!("adam_v");
    let graph = SiteGraph { offsets: arr1!("graph_offsets", u32), neighbors: arr1!("graph_neighbors", u32) };
    let inside = arr1!("located_inside", u8);
    let closest = arr2!("located_closest");
    let hist: Array2<f64> = npz.by_name("history").map_err(|e| fail(format!("array 'history': {e}")))?;
    if hist.ncols() != StepStats::COLUMNS && hist.ncols() != 9 {
        return Err(fail(format!("array 'history' has {} columns, expected {}", hist.ncols(), StepStats::COLUMNS)));
    }
    let history = hist.rows().into_iter().map(|r| StepStats::from_row(r.as_slice().unwrap_or(&r.to_vec()))).collect();
    let fp = arr1!("data_fingerprint", u64);
    if step.len() != 1 || fp.len() != 1 || inside.len() != closest.len() {
        return Err(fail("arrays 'step', 'data_fingerprint' or 'located_*' have the wrong length".into()));
    }
    let n = sites.len();
    let graph_ok = graph.offsets.is_empty()
        || (graph.offsets.len() == n + 1
            && graph.offsets.windows(2).all(|w| w[0] <= w[1])
            && *graph.offsets.last().unwrap_or(&0) as usize == graph.neighbors.len()
            && graph.neighbors.iter().all(|&j| (j as usize) < n));
    if !graph_ok {
        return Err(fail("the Delaunay graph arrays are inconsistent".into()));
    }
    if !sites.iter().chain(&m).chain(&v).flatten().all(|x| x.is_finite()) {
        return Err(fail("non-finite sites or Adam moments".into()));
    }
    let best =
        if npz.names().map_err(|e| fail(e.to_string()))?.iter().any(|n| n.trim_end_matches(".npy") == "best_step") {
            let best_step = arr1!("best_step", u64);
            let best_loss = arr1!("best_loss", f64);
            let best_sites = arr2!("best_sites");
            if best_step.len() != 1 || best_loss.len() != 1 || !best_sites.iter().flatten().all(|x| x.is_finite()) {
                return Err(fail("arrays 'best_*' have the wrong length or non-finite values".into()));
            }
            Some(BestIterate { step: best_step[0] as usize, loss: best_loss[0], sites: best_sites })
        } else {
            None
        };
    let located = inside.iter().zip(closest).map(|(&i, c)| Located { inside: i != 0, closest: c }).collect();
    let state = TrainState {
        config,
        step: step[0] as usize,
        sites,
        labels,
        m,
        v,
        graph,
        located,
        history,
        data_fingerprint: fp[0],
        best,
    };
    Ok((state, context))
}
