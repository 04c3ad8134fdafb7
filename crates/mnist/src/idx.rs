//! The IDX files MNIST is published in (gzip or raw), read as published: a big-endian
//! header (two zero bytes, the type code 0x08 = unsigned byte, the number of dimensions,
//! then each dimension as a u32) and the data. Images are 0x00000803 (N × rows × cols),
//! labels 0x00000801 (N). So the official 60,000-image training set works unchanged.
//!
//! Every failure names the file and says what was expected: a wrong magic number, a
//! truncated or over-long file, a gzip stream that does not decode, a label above 9, or an
//! image and a label file that disagree on the count.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::error::MnistError;

/// Largest number of pixel bytes accepted (4 GiB): far above MNIST (47 MB) and EMNIST,
/// low enough that a corrupt header cannot make us allocate the machine away.
pub const MAX_BYTES: u64 = 1 << 32;

/// Images of one IDX file.
#[derive(Clone, Debug, PartialEq)]
pub struct Images {
    /// Number of images.
    pub count: usize,
    /// Rows per image.
    pub rows: usize,
    /// Columns per image.
    pub cols: usize,
    /// `count × rows × cols` intensities, row-major, 0 = background.
    pub pixels: Vec<u8>,
}

impl Images {
    /// The pixels of image `i`.
    pub fn image(&self, i: usize) -> &[u8] {
        let n = self.rows * self.cols;
        &self.pixels[i * n..(i + 1) * n]
    }
}

/// A labelled set of digits.
#[derive(Clone, Debug, PartialEq)]
pub struct DigitSet {
    /// The images.
    pub images: Images,
    /// One class (0–9) per image.
    pub labels: Vec<u8>,
    /// Where they came from (images file).
    pub source: PathBuf,
}

impl DigitSet {
    /// Number of digits.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// The first `n` digits (all when `n` ≥ the count).
    pub fn truncated(mut self, n: usize) -> Self {
        let n = n.min(self.len());
        self.labels.truncate(n);
        self.images.count = n;
        self.images.pixels.truncate(n * self.images.rows * self.images.cols);
        self
    }
}

fn bad(path: &Path, message: impl Into<String>) -> MnistError {
    MnistError::Idx { path: path.to_path_buf(), message: message.into() }
}

/// The whole file, gunzipped when it starts with the gzip magic (1f 8b), at most
/// `MAX_BYTES` + 1 KiB.
fn read_all(path: &Path) -> Result<Vec<u8>, MnistError> {
    let file = std::fs::File::open(path).map_err(|e| bad(path, format!("cannot open the file ({e})")))?;
    let mut head = [0u8; 2];
    let mut raw = Vec::new();
    let limit = MAX_BYTES + 1024;
    let mut reader = std::io::BufReader::new(file);
    let n = reader.read(&mut head).map_err(|e| bad(path, format!("cannot read the file ({e})")))?;
    let rest = head[..n].to_vec();
    if n == 2 && head == [0x1f, 0x8b] {
        let chained = std::io::Cursor::new(rest).chain(reader);
        flate2::read::GzDecoder::new(chained)
            .take(limit)
            .read_to_end(&mut raw)
            .map_err(|e| bad(path, format!("the gzip stream does not decode ({e}); download the file again")))?;
    } else {
        raw = rest;
        reader.take(limit).read_to_end(&mut raw).map_err(|e| bad(path, format!("cannot read the file ({e})")))?;
    }
    Ok(raw)
}

/// Parses the header: (type code, dimensions), after checking the two zero bytes and the
/// unsigned-byte type.
fn header(path: &Path, data: &[u8], want_dims: usize, what: &str, magic: u32) -> Result<Vec<usize>, MnistError> {
    if data.len() < 4 {
        return Err(bad(
            path,
            format!("{} bytes: too short for an IDX header; is this an IDX {what} file?", data.len()),
        ));
    }
    let m = u32::from_be_bytes([data[0], data[1], data[2], data[3]]);
    if m != magic {
        return Err(bad(
            path,
            format!(
                "magic number 0x{m:08x}, expected 0x{magic:08x} for IDX {what} (unsigned bytes, {want_dims} dimension{}); is this the right file?",
                if want_dims == 1 { "" } else { "s" }
            ),
        ));
    }
    let need = 4 + 4 * want_dims;
    if data.len() < need {
        return Err(bad(path, format!("{} bytes: the header needs {need}; the file is truncated", data.len())));
    }
    Ok((0..want_dims)
        .map(|d| {
            let o = 4 + 4 * d;
            u32::from_be_bytes([data[o], data[o + 1], data[o + 2], data[o + 3]]) as usize
        })
        .collect())
}

fn check_length(path: &Path, data: &[u8], header_len: usize, body: u64) -> Result<(), MnistError> {
    if body > MAX_BYTES {
        return Err(bad(
            path,
            format!("the header declares {body} data bytes, more than the {MAX_BYTES} accepted; the header is corrupt"),
        ));
    }
    let have = (data.len() - header_len) as u64;
    if have < body {
        return Err(bad(
            path,
            format!("{have} data bytes but the header declares {body}: the file is truncated; download it again"),
        ));
    }
    if have > body {
        return Err(bad(
            path,
            format!("{have} data bytes but the header declares {body}: trailing data; is the file corrupt?"),
        ));
    }
    Ok(())
}

/// Reads an IDX image file (magic 0x00000803).
///
/// # Errors
/// [`MnistError::Idx`] naming the file and the problem.
pub fn read_images(path: &Path) -> Result<Images, MnistError> {
    let data = read_all(path)?;
    let dims = header(path, &data, 3, "images", 0x0000_0803)?;
    let (count, rows, cols) = (dims[0], dims[1], dims[2]);
    if rows == 0 || cols == 0 {
        return Err(bad(path, format!("images of {rows}×{cols} pixels: both sides must be at least 1")));
    }
    let body = count as u64 * rows as u64 * cols as u64;
    check_length(path, &data, 16, body)?;
    Ok(Images { count, rows, cols, pixels: data[16..].to_vec() })
}

/// Reads an IDX label file (magic 0x00000801); every label must be 0–9.
///
/// # Errors
/// [`MnistError::Idx`] naming the file and the problem (a label above 9 by its index).
pub fn read_labels(path: &Path) -> Result<Vec<u8>, MnistError> {
    let data = read_all(path)?;
    let dims = header(path, &data, 1, "labels", 0x0000_0801)?;
    check_length(path, &data, 8, dims[0] as u64)?;
    let labels = data[8..].to_vec();
    if let Some(i) = labels.iter().position(|&l| l > 9) {
        return Err(bad(path, format!("label {i} is {}, not a digit 0–9", labels[i])));
    }
    Ok(labels)
}

/// Reads an image file and its label file and checks they agree.
///
/// # Errors
/// Either file's error, or [`MnistError::Mismatch`] when the counts differ.
pub fn read_set(images: &Path, labels: &Path) -> Result<DigitSet, MnistError> {
    let im = read_images(images)?;
    let lb = read_labels(labels)?;
    if im.count != lb.len() {
        return Err(MnistError::Mismatch {
            images: images.to_path_buf(),
            labels: labels.to_path_buf(),
            message: format!("{} images but {} labels; the two files must come from the same set", im.count, lb.len()),
        });
    }
    Ok(DigitSet { images: im, labels: lb, source: images.to_path_buf() })
}

/// Which files of a data folder make a set: `train` prefers the official 60,000-image
/// `train-images-idx3-ubyte[.gz]` and falls back to the 10,000 digits shipped here
/// (`train10k-…`); `test` is `t10k-…`.
///
/// # Errors
/// [`MnistError::Missing`] listing the names tried.
pub fn find_set(dir: &Path, test: bool) -> Result<(PathBuf, PathBuf), MnistError> {
    let stems: &[&str] = if test { &["t10k"] } else { &["train", "train10k"] };
    let mut tried = Vec::new();
    for stem in stems {
        for ext in ["", ".gz"] {
            let im = dir.join(format!("{stem}-images-idx3-ubyte{ext}"));
            let lb = dir.join(format!("{stem}-labels-idx1-ubyte{ext}"));
            if im.is_file() && lb.is_file() {
                return Ok((im, lb));
            }
            tried.push(im.display().to_string());
        }
    }
    Err(MnistError::Missing {
        dir: dir.to_path_buf(),
        message: format!(
            "no {} set found (tried {}); give the folder that holds the MNIST IDX files, or name them with --{}-images/--{}-labels",
            if test { "test" } else { "training" },
            tried.join(", "),
            if test { "test" } else { "train" },
            if test { "test" } else { "train" }
        ),
    })
}
