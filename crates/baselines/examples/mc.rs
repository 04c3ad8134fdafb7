//! Marching cubes on a grid from a `.npy` file, for the Python reference check
//! (`tests/reference/test_baselines.py` compares it with `skimage.measure.marching_cubes`).
//!
//!     cargo run --release -p baselines --example mc -- GRID.npy OUT.npz [LEVEL] [AMBIGUITY] [INSIDE]
//!
//! GRID.npy: a 3-D float64 array. LEVEL: default 0. AMBIGUITY: `decider` (default),
//! `separate` (skimage's `method="lorensen"`) or `join`. INSIDE: `above` (default) or
//! `below` (skimage's default `gradient_direction="descent"` orientation). OUT.npz: `verts` (n, 3) float64 in grid index units, `faces`
//! (m, 3) uint32. Exit code 2 on bad input, with a message.

use baselines::{marching_cubes, Ambiguity, Inside, McOptions};
use ndarray::{Array2, Array3};
use ndarray_npy::{read_npy, NpzWriter};

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 3 {
        return Err("usage: mc GRID.npy OUT.npz [LEVEL] [decider|separate|join] [above|below]".into());
    }
    let grid: Array3<f64> = read_npy(&a[1]).map_err(|e| format!("{}: {e}", a[1]))?;
    let level: f64 = match a.get(3) {
        Some(s) => s.parse().map_err(|_| format!("level {s:?} is not a number"))?,
        None => 0.0,
    };
    let ambiguity = match a.get(4).map(String::as_str).unwrap_or("decider") {
        "decider" => Ambiguity::AsymptoticDecider,
        "separate" => Ambiguity::SeparateAbove,
        "join" => Ambiguity::JoinAbove,
        other => return Err(format!("unknown ambiguity rule {other:?}")),
    };
    let inside = match a.get(5).map(String::as_str).unwrap_or("above") {
        "above" => Inside::Above,
        "below" => Inside::Below,
        other => return Err(format!("unknown inside {other:?}")),
    };
    let mesh = marching_cubes(grid.view(), &McOptions { level, ambiguity, inside, ..Default::default() })
        .map_err(|e| e.to_string())?;
    let verts =
        Array2::from_shape_vec((mesh.positions.len(), 3), mesh.positions.concat()).map_err(|e| e.to_string())?;
    let faces =
        Array2::from_shape_vec((mesh.triangles.len(), 3), mesh.triangles.concat()).map_err(|e| e.to_string())?;
    let file = std::fs::File::create(&a[2]).map_err(|e| format!("{}: {e}", a[2]))?;
    let mut npz = NpzWriter::new(file);
    npz.add_array("verts", &verts).map_err(|e| e.to_string())?;
    npz.add_array("faces", &faces).map_err(|e| e.to_string())?;
    npz.finish().map_err(|e| e.to_string())?;
    Ok(())
}
