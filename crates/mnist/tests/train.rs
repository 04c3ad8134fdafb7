//! Training: a checkpointed, interrupted and resumed run is bit-identical to an
//! uninterrupted one; a model overfits one digit.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use mnist::{eval, idx, DigitSet, Method, MnistError, TrainSettings, TrainState};

fn shared() -> PathBuf {
    std::env::var_os("VF_SHARED_MNIST").map_or_else(|| PathBuf::from("../../../shared/mnist"), PathBuf::from)
}

fn test_set() -> DigitSet {
    let (im, lb) = idx::find_set(&shared(), true).expect("the shared MNIST test set (set VF_SHARED_MNIST)");
    idx::read_set(&im, &lb).unwrap()
}

#[test]
fn an_interrupted_run_resumes_bit_for_bit() {
    let data = test_set().truncated(48);
    for method in [Method::Voronoi, Method::OccNet { hidden: 64 }] {
        let settings = TrainSettings { epochs: 2, batch: 16, points: 64, train_images: 48, ..TrainSettings::full() };
        let never = AtomicBool::new(false);
        let mut whole = TrainState::new(method, 784, settings.clone());
        whole.run(&data, None, 0, &never, |_| {}).unwrap();
        assert_eq!(whole.step, 6);

        let dir = tempfile::tempdir().unwrap();
        let ck = dir.path().join("checkpoint.npz");
        let stop = AtomicBool::new(false);
        let mut first = TrainState::new(method, 784, settings.clone());
        let r = first.run(&data, Some(&ck), 0, &stop, |p| {
            if p.epoch == 0 && p.batch == 2 {
                stop.store(true, Ordering::SeqCst);
            }
        });
        assert!(matches!(r, Err(MnistError::Interrupted)), "{r:?}");
        let mut resumed = TrainState::load(&ck).unwrap();
        assert_eq!((resumed.step, resumed.epoch, resumed.batch_in_epoch), (2, 0, 2));
        resumed.run(&data, Some(&ck), 1, &never, |_| {}).unwrap();
        assert_eq!(resumed.model, whole.model, "{method:?}");
        assert_eq!(
            resumed.curve.iter().map(|c| c.loss).collect::<Vec<_>>(),
            whole.curve.iter().map(|c| c.loss).collect::<Vec<_>>()
        );
        // The finished checkpoint loads to the same model.
        assert_eq!(TrainState::load(&ck).unwrap().model, whole.model);
    }
}

#[test]
fn a_damaged_checkpoint_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("checkpoint.npz");
    std::fs::write(&p, b"not a checkpoint").unwrap();
    let e = TrainState::load(&p).unwrap_err().to_string();
    assert!(e.contains("checkpoint.npz") && e.contains("npz"), "{e}");
}

#[test]
fn the_voronoi_autoencoder_overfits_one_digit() {
    // Measured: 20 mismatched pixels of 784 (the digit has 125 ink pixels), IoU 0.85,
    // after 300 steps; an untrained decoder draws ~270.
    let data = test_set().truncated(1);
    let settings = TrainSettings { epochs: 300, batch: 1, train_images: 1, ..TrainSettings::full() };
    let mut state = TrainState::new(Method::Voronoi, 784, settings);
    let before = eval::evaluate(&state.model, &data, 1, 1);
    state.run(&data, None, 0, &AtomicBool::new(false), |_| {}).unwrap();
    let after = eval::evaluate(&state.model, &data, 1, 1);
    assert!(
        after.mismatched_pixels.mean <= 30.0,
        "{} mismatched pixels (before training {})",
        after.mismatched_pixels.mean,
        before.mismatched_pixels.mean
    );
    assert!(after.iou.mean >= 0.75, "IoU {}", after.iou.mean);
    assert!(before.mismatched_pixels.mean > 2.0 * after.mismatched_pixels.mean);
}
