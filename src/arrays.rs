//! `.npy` / `.npz` input and output for the CLI, through ndarray-npy.
//!
//! Outputs are assembled in memory and written with [`mesh_io::atomic_write`] (`.npz`:
//! [`vf_common::npz::NpzOut`]), so a failure leaves no partial file. Inputs are checked for
//! shape, dtype and finiteness, and errors name the file and how to fix it.

use std::io::Cursor;
use std::path::Path;

use ndarray::{Array1, Array2, ArrayBase, Data, Dimension};
use ndarray_npy::{ReadNpyExt, WritableElement, WriteNpyExt};

use crate::cli_error::CliError;

/// Read an (n, 3) array of points, f64 or f32, from a `.npy` file.
///
/// # Errors
/// Bad input naming the file for a missing file, a malformed header, another dtype or
/// shape, or a NaN/infinite coordinate (naming the row).
pub fn read_points_npy(path: &Path) -> Result<Vec<[f64; 3]>, CliError> {
    let bytes = std::fs::read(path).map_err(|e| CliError::input_in(path, format!("cannot read the file ({e}).")))?;
    let a: Array2<f64> = match Array2::<f64>::read_npy(Cursor::new(&bytes)) {
        Ok(a) => a,
        Err(e64) => match Array2::<f32>::read_npy(Cursor::new(&bytes)) {
            Ok(a) => a.mapv(f64::from),
            Err(_) => {
                return Err(CliError::input_in(path, format!("not a 2-D float64 or float32 .npy array ({e64}). Save it with numpy.save(path, points.astype(numpy.float64)) where points has shape (n, 3)."),
                ))
            }
        },
    };
    if a.ncols() != 3 {
        return Err(CliError::input_in(
            path,
            format!("the array has shape ({}, {}); points must have shape (n, 3).", a.nrows(), a.ncols()),
        ));
    }
    let mut out = Vec::with_capacity(a.nrows());
    for (i, row) in a.rows().into_iter().enumerate() {
        let p = [row[0], row[1], row[2]];
        if p.iter().any(|c| !c.is_finite()) {
            return Err(CliError::input_in(path, format!("row {i} is {p:?}, not finite. Remove or repair the point.")));
        }
        out.push(p);
    }
    Ok(out)
}

/// (n, k) array from rows of any element type.
pub fn rows_array<T: Copy, const K: usize>(rows: &[[T; K]]) -> Array2<T> {
    Array2::from_shape_vec((rows.len(), K), rows.iter().flatten().copied().collect()).expect("n×k elements")
}

/// 1-D array from a slice.
pub fn vec_array<T: Copy>(v: &[T]) -> Array1<T> {
    Array1::from(v.to_vec())
}

/// Write one array as `.npy`, atomically.
pub fn write_npy<A, S, D>(path: &Path, array: &ArrayBase<S, D>) -> Result<(), CliError>
where
    A: WritableElement,
    S: Data<Elem = A>,
    D: Dimension,
{
    let mut buf = Vec::new();
    array
        .write_npy(&mut buf)
        .map_err(|e| CliError::failure(format!("{}: cannot encode the array ({e})", path.display())))?;
    Ok(mesh_io::atomic_write(path, |w| w.write_all(&buf))?)
}

pub use vf_common::npz::NpzOut as Npz;
