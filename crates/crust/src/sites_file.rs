//! The sites file: `.npz` shared by training (which writes it) and the crust (which reads
//! it), readable with `numpy.load`.
//!
//! | array | shape, dtype | meaning |
//! |---|---|---|
//! | `sites` | (K, 3) float64 | site positions, unit-cube coordinates |
//! | `labels` | (K,) uint8 | 1 = inside, 0 = outside |
//! | `transform` | (4, 4) float64 | row-major affine map from unit-cube coordinates back to the original mesh frame (homogeneous column vectors) |
//! | `format_version` | (1,) int64 | 1 |
//!
//! Training may add further arrays (boundary sites, settings); readers ignore what they do
//! not know.

use std::io::Cursor;
use std::path::Path;

use ndarray::{Array1, Array2};
use ndarray_npy::NpzReader;
use vf_common::npz::NpzOut;

use crate::error::SitesFileError;

/// The current `format_version`.
pub const FORMAT_VERSION: i64 = 1;

/// Sites, labels and the transform back to the mesh frame.
#[derive(Clone, Debug, PartialEq)]
pub struct SitesFile {
    /// #K×3 f64, unit-cube coordinates.
    pub sites: Vec<[f64; 3]>,
    /// #K bool, true = inside.
    pub inside: Vec<bool>,
    /// 4×4 row-major, unit cube → mesh frame.
    pub transform: [[f64; 4]; 4],
}

impl SitesFile {
    /// Map a point from unit-cube coordinates to the mesh frame with `transform`.
    pub fn to_mesh_frame(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.transform;
        [0, 1, 2].map(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2] + m[r][3])
    }

    /// Whether `transform` mirrors (negative determinant of its linear part): triangles
    /// mapped through it must have their winding flipped to stay counter-clockwise.
    pub fn transform_mirrors(&self) -> bool {
        linear_determinant(&self.transform) < 0.0
    }

    /// Read and check a sites file.
    ///
    /// # Errors
    /// Naming the file and the array: missing arrays, wrong shapes or dtypes, labels other
    /// than 0/1, non-finite values, an unknown `format_version`, a singular transform.
    pub fn read(path: &Path) -> Result<SitesFile, SitesFileError> {
        let p = path.display().to_string();
        let invalid = |message: String| SitesFileError::Invalid { path: p.clone(), message };
        let bytes = std::fs::read(path).map_err(|source| SitesFileError::Io { path: p.clone(), source })?;
        let mut npz = NpzReader::new(Cursor::new(bytes))
            .map_err(|e| invalid(format!("not an .npz archive ({e}); write it with numpy.savez")))?;
        let version: Array1<i64> = npz
            .by_name("format_version")
            .map_err(|e| invalid(format!("array `format_version` missing or not int64 of shape (1,) ({e})")))?;
        if version.len() != 1 || version[0] != FORMAT_VERSION {
            return Err(invalid(format!("format_version is {version}, this program reads {FORMAT_VERSION}")));
        }
        let sites: Array2<f64> = npz
            .by_name("sites")
            .map_err(|e| invalid(format!("array `sites` missing or not float64 of shape (K, 3) ({e})")))?;
        if sites.ncols() != 3 {
            return Err(invalid(format!(
                "`sites` has shape ({}, {}); it must be (K, 3)",
                sites.nrows(),
                sites.ncols()
            )));
        }
        let labels: Array1<u8> = npz
            .by_name("labels")
            .map_err(|e| invalid(format!("array `labels` missing or not uint8 of shape (K,) ({e})")))?;
        if labels.len() != sites.nrows() {
            return Err(invalid(format!("{} labels for {} sites", labels.len(), sites.nrows())));
        }
        if let Some(i) = labels.iter().position(|&l| l > 1) {
            return Err(invalid(format!("label {i} is {}; labels are 0 (outside) or 1 (inside)", labels[i])));
        }
        let t: Array2<f64> = npz
            .by_name("transform")
            .map_err(|e| invalid(format!("array `transform` missing or not float64 of shape (4, 4) ({e})")))?;
        if t.dim() != (4, 4) || t.iter().any(|x| !x.is_finite()) {
            return Err(invalid("`transform` must be a finite (4, 4) float64 matrix".into()));
        }
        let mut transform = [[0.0; 4]; 4];
        for r in 0..4 {
            for c in 0..4 {
                transform[r][c] = t[(r, c)];
            }
        }
        if linear_determinant(&transform) == 0.0 || transform[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(invalid("`transform` must be an invertible affine matrix with last row (0, 0, 0, 1)".into()));
        }
        let mut out = Vec::with_capacity(sites.nrows());
        for (i, r) in sites.rows().into_iter().enumerate() {
            let s = [r[0], r[1], r[2]];
            if s.iter().any(|c| !c.is_finite()) {
                return Err(invalid(format!("site {i} is {s:?}, not finite")));
            }
            out.push(s);
        }
        Ok(SitesFile { sites: out, inside: labels.iter().map(|&l| l == 1).collect(), transform })
    }

    /// Write the file atomically.
    pub fn write(&self, path: &Path) -> Result<(), SitesFileError> {
        let fail = |e: vf_common::npz::NpzError| match e {
            vf_common::npz::NpzError::Write(e) => SitesFileError::from(e),
            e => SitesFileError::Invalid { path: path.display().to_string(), message: e.to_string() },
        };
        let mut npz = NpzOut::new();
        npz.add_rows("sites", &self.sites)
            .and_then(|w| w.add_vec("labels", self.inside.iter().map(|&b| b as u8).collect::<Vec<u8>>()))
            .map_err(fail)?;
        let t = Array2::from_shape_vec((4, 4), self.transform.iter().flatten().copied().collect()).expect("4×4");
        npz.add("transform", &t).and_then(|w| w.add_vec("format_version", vec![FORMAT_VERSION])).map_err(fail)?;
        npz.write(path).map_err(fail)
    }
}

/// Determinant of the upper-left 3×3 block of a row-major 4×4 matrix.
fn linear_determinant(m: &[[f64; 4]; 4]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}
