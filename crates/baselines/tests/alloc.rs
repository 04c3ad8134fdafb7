//! A training step allocates nothing of its own: counted with a global allocator. The only
//! allocations are matrixmultiply's packing buffers, at most one per matrix product
//! (matrix products smaller than its threshold allocate none); the count per step is
//! constant and bounded by the number of products.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use baselines::{Decoder, DecoderConfig, TrainConfig, Trainer, TrainingData};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        ALLOCS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[test]
fn steps_allocate_only_gemm_packing_buffers() {
    let n = 20_000;
    let points: Vec<[f64; 3]> =
        (0..n).map(|i| [(i % 97) as f64 / 97.0, (i % 89) as f64 / 89.0, (i % 83) as f64 / 83.0]).collect();
    let sdf: Vec<f64> = points.iter().map(|p| p[0] + p[1] - p[2] - 0.4).collect();
    let occ = sdf.iter().map(|&d| (d < 0.0) as u8 as f64).collect();
    let data = TrainingData { points, occupancy: Some(occ), sdf: Some(sdf) };
    for cfg in [DecoderConfig::occnet(64, 3), DecoderConfig::deepsdf(64, 3, Some(2), 0.1)] {
        let mut m = Decoder::new(cfg.clone(), 0).unwrap();
        let tc = TrainConfig { batch: 8192, chunk_rows: 2048, ..Default::default() };
        let mut t = Trainer::new(&m, n, &tc).unwrap();
        for _ in 0..3 {
            t.step(&mut m, &data).unwrap();
        }
        let chunks = 4;
        // Per chunk: depth + 1 forward products, depth + 1 weight-gradient products, depth
        // input-gradient products.
        let gemms = chunks * (3 * cfg.depth + 2);
        let mut per_step = Vec::new();
        for _ in 0..4 {
            let before = ALLOCS.load(Ordering::SeqCst);
            t.step(&mut m, &data).unwrap();
            per_step.push(ALLOCS.load(Ordering::SeqCst) - before);
        }
        eprintln!("{:?}: allocations per step {per_step:?} (matrix products per step: {gemms})", cfg.kind);
        assert!(per_step.iter().all(|&a| a <= gemms), "{per_step:?} > {gemms}");
    }
}
