//! An uncompressed `.npz` (numpy's archive of `.npy` arrays) built in memory and written
//! atomically with [`mesh_io::atomic_write`], so a failure never leaves half a file. No
//! compression keeps C codecs out of the build; numpy reads the files as they are.

use std::io::Cursor;
use std::path::Path;

use ndarray::{Array1, Array2, ArrayBase, Data, Dimension};
use ndarray_npy::{NpzWriter, WritableElement};

/// Why an `.npz` could not be written.
#[derive(Debug)]
pub enum NpzError {
    /// An array could not be encoded (the message names it).
    Encode(String),
    /// The file could not be written.
    Write(mesh_io::MeshError),
}

impl std::fmt::Display for NpzError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NpzError::Encode(m) => write!(f, "{m}"),
            NpzError::Write(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for NpzError {}

/// An `.npz` being assembled in memory.
pub struct NpzOut {
    writer: NpzWriter<Cursor<Vec<u8>>>,
}

impl Default for NpzOut {
    fn default() -> Self {
        Self::new()
    }
}

impl NpzOut {
    /// An empty archive.
    pub fn new() -> Self {
        NpzOut { writer: NpzWriter::new(Cursor::new(Vec::new())) }
    }

    /// Adds `array` under `name` (readable as `numpy.load(path)[name]`).
    ///
    /// # Errors
    /// [`NpzError::Encode`] naming the array.
    pub fn add<A, S, D>(&mut self, name: &str, array: &ArrayBase<S, D>) -> Result<&mut Self, NpzError>
    where
        A: WritableElement,
        S: Data<Elem = A>,
        D: Dimension,
    {
        self.writer
            .add_array(name, array)
            .map_err(|e| NpzError::Encode(format!("cannot encode array {name} ({e})")))?;
        Ok(self)
    }

    /// Adds a 1-D array from a vector.
    ///
    /// # Errors
    /// [`NpzError::Encode`] naming the array.
    pub fn add_vec<A: WritableElement>(&mut self, name: &str, values: Vec<A>) -> Result<&mut Self, NpzError> {
        self.add(name, &Array1::from(values))
    }

    /// Adds #N×3 points (or any rows of three) as an N×3 array.
    ///
    /// # Errors
    /// [`NpzError::Encode`] naming the array.
    pub fn add_rows<A: WritableElement + Copy>(&mut self, name: &str, rows: &[[A; 3]]) -> Result<&mut Self, NpzError> {
        let a = Array2::from_shape_vec((rows.len(), 3), rows.iter().flatten().copied().collect())
            .expect("N rows of 3 make an N×3 array");
        self.add(name, &a)
    }

    /// Finishes the archive and writes it to `path` atomically.
    ///
    /// # Errors
    /// [`NpzError::Encode`] if the archive cannot be finished, [`NpzError::Write`] if the
    /// file cannot be written (the message names `path`).
    pub fn write(self, path: &Path) -> Result<(), NpzError> {
        let bytes = self
            .writer
            .finish()
            .map_err(|e| NpzError::Encode(format!("{}: cannot finish the archive ({e})", path.display())))?
            .into_inner();
        mesh_io::atomic_write(path, |w| w.write_all(&bytes)).map_err(NpzError::Write)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray_npy::NpzReader;

    #[test]
    fn round_trips_and_leaves_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("vf-common-npz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("a.npz");
        let mut npz = NpzOut::new();
        npz.add_rows("p", &[[1.0f64, 2.0, 3.0], [4.0, 5.0, 6.0]]).unwrap().add_vec("l", vec![1u8, 0]).unwrap();
        npz.write(&path).unwrap();
        let mut r = NpzReader::new(std::fs::File::open(&path).unwrap()).unwrap();
        let p: Array2<f64> = r.by_name("p").unwrap();
        assert_eq!(p.shape(), &[2, 3]);
        assert_eq!(p[[1, 2]], 6.0);
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 1, "{names:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_missing_directory_is_a_write_error_naming_the_path() {
        let path = Path::new("/nonexistent-dir-vf/x.npz");
        let mut npz = NpzOut::new();
        npz.add_vec("l", vec![1u8]).unwrap();
        let e = npz.write(path).unwrap_err();
        assert!(matches!(e, NpzError::Write(_)) && e.to_string().contains("nonexistent-dir-vf"), "{e}");
    }
}
