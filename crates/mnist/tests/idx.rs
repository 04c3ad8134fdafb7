//! The IDX reader on good and bad files: every failure names the file and what is wrong.

use std::io::Write;
use std::path::{Path, PathBuf};

use mnist::idx;

fn images_bytes(n: u32, rows: u32, cols: u32, data_len: usize) -> Vec<u8> {
    let mut v = vec![0, 0, 8, 3];
    for d in [n, rows, cols] {
        v.extend_from_slice(&d.to_be_bytes());
    }
    v.extend((0..data_len).map(|i| (i % 251) as u8));
    v
}

fn labels_bytes(n: u32, labels: &[u8]) -> Vec<u8> {
    let mut v = vec![0, 0, 8, 1];
    v.extend_from_slice(&n.to_be_bytes());
    v.extend_from_slice(labels);
    v
}

fn write(dir: &Path, name: &str, bytes: &[u8], gzip: bool) -> PathBuf {
    let p = dir.join(name);
    let mut f = std::fs::File::create(&p).unwrap();
    if gzip {
        let mut e = flate2::write::GzEncoder::new(f, flate2::Compression::fast());
        e.write_all(bytes).unwrap();
        e.finish().unwrap();
    } else {
        f.write_all(bytes).unwrap();
    }
    p
}

fn err(r: Result<impl std::fmt::Debug, mnist::MnistError>) -> String {
    r.expect_err("should fail").to_string()
}

#[test]
fn good_files_read_raw_and_gzipped() {
    let dir = tempfile::tempdir().unwrap();
    for gz in [false, true] {
        let im = write(dir.path(), &format!("im{gz}"), &images_bytes(3, 2, 4, 24), gz);
        let lb = write(dir.path(), &format!("lb{gz}"), &labels_bytes(3, &[7, 0, 9]), gz);
        let set = idx::read_set(&im, &lb).unwrap();
        assert_eq!((set.images.count, set.images.rows, set.images.cols), (3, 2, 4));
        assert_eq!(set.labels, vec![7, 0, 9]);
        assert_eq!(set.images.image(1), &(8..16).map(|i| i as u8).collect::<Vec<_>>()[..]);
    }
}

#[test]
fn bad_files_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let good_lb = write(d, "lb", &labels_bytes(3, &[1, 2, 3]), false);
    // Truncated images.
    let p = write(d, "trunc", &images_bytes(3, 2, 4, 20), false);
    let e = err(idx::read_images(&p));
    assert!(e.contains("trunc") && e.contains("truncated") && e.contains("24"), "{e}");
    // Trailing data.
    let p = write(d, "long", &images_bytes(3, 2, 4, 30), false);
    assert!(err(idx::read_images(&p)).contains("trailing"));
    // Wrong magic: a label file read as images, and garbage.
    let e = err(idx::read_images(&good_lb));
    assert!(e.contains("magic number 0x00000801") && e.contains("0x00000803"), "{e}");
    let p = write(d, "junk", b"hello world, not idx", false);
    assert!(err(idx::read_labels(&p)).contains("magic"));
    let p = write(d, "tiny", b"\0\0", false);
    assert!(err(idx::read_labels(&p)).contains("too short"));
    // Empty file.
    let p = write(d, "empty", b"", false);
    assert!(err(idx::read_images(&p)).contains("too short"));
    // A label that is not a digit.
    let p = write(d, "lb10", &labels_bytes(2, &[3, 10]), false);
    let e = err(idx::read_labels(&p));
    assert!(e.contains("label 1 is 10"), "{e}");
    // Counts that disagree.
    let im = write(d, "im2", &images_bytes(2, 2, 4, 16), false);
    let e = err(idx::read_set(&im, &good_lb));
    assert!(e.contains("2 images but 3 labels"), "{e}");
    // A header that declares an absurd size is refused before allocating.
    let p = write(d, "huge", &images_bytes(u32::MAX, 1000, 1000, 0), false);
    assert!(err(idx::read_images(&p)).contains("corrupt"));
    // Broken gzip.
    let mut gz = Vec::new();
    {
        let mut e = flate2::write::GzEncoder::new(&mut gz, flate2::Compression::fast());
        e.write_all(&images_bytes(3, 2, 4, 24)).unwrap();
        e.finish().unwrap();
    }
    gz.truncate(gz.len() / 2);
    let p = write(d, "broken.gz", &gz, false);
    let e = err(idx::read_images(&p));
    assert!(e.contains("broken.gz") && e.contains("gzip"), "{e}");
    // Missing file and missing set.
    assert!(err(idx::read_images(&d.join("nope"))).contains("cannot open"));
    let e = err(idx::find_set(d, true));
    assert!(e.contains("t10k-images-idx3-ubyte"), "{e}");
}

#[test]
fn the_shared_mnist_files_read_as_published() {
    let dir = std::env::var_os("VF_SHARED_MNIST").map_or_else(|| PathBuf::from("../../../shared/mnist"), PathBuf::from);
    let (im, lb) = idx::find_set(&dir, true).expect("the shared MNIST test set (set VF_SHARED_MNIST)");
    let test = idx::read_set(&im, &lb).unwrap();
    assert_eq!((test.len(), test.images.rows, test.images.cols), (10_000, 28, 28));
    // The official test set starts 7 2 1 0 4 1 4 9 5 9.
    assert_eq!(&test.labels[..10], &[7, 2, 1, 0, 4, 1, 4, 9, 5, 9]);
    let (im, lb) = idx::find_set(&dir, false).unwrap();
    let train = idx::read_set(&im, &lb).unwrap();
    assert!(train.len() >= 10_000);
}
