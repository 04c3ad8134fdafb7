//! Times training steps (batch gather, forward, backward, Adam) of an OccNet-style
//! decoder, f32, the whole data set as one batch every step; prints one JSON line.
//!
//!     cargo run --release -p baselines --example step_timing -- [width] [depth] [batch] [steps] [kind]
//!
//! Defaults: 256 5 65536 10 occnet (the 3→256×5→1 MLP of the issue). `kind` is `occnet` or
//! `deepsdf`. The first step (page faults in fresh buffers) is timed separately.

use baselines::{DecoderConfig, TrainConfig, Trainer, TrainingData};
use std::time::Instant;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: usize| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (width, depth, batch, steps) = (arg(1, 256), arg(2, 5), arg(3, 65_536), arg(4, 10));
    let kind = a.get(5).map(String::as_str).unwrap_or("occnet");
    let cfg = match kind {
        "deepsdf" => DecoderConfig::deepsdf(width, depth, None, 0.1),
        _ => DecoderConfig::occnet(width, depth),
    };
    let mut s = 0x2545_F491_4F6C_DD1Du64;
    let mut r = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let points: Vec<[f64; 3]> = (0..batch).map(|_| [r(), r(), r()]).collect();
    let sdf: Vec<f64> =
        points.iter().map(|p| (p.iter().map(|c| (c - 0.5).powi(2)).sum::<f64>()).sqrt() - 0.35).collect();
    let occ: Vec<f64> = sdf.iter().map(|&d| (d < 0.0) as u8 as f64).collect();
    let data = TrainingData { points, occupancy: Some(occ), sdf: Some(sdf) };
    let mut model = baselines::Decoder::new(cfg, 0).expect("config");
    let tc = TrainConfig { batch, steps, ..Default::default() };
    let mut trainer = Trainer::new(&model, batch, &tc).expect("trainer");
    let t = Instant::now();
    let first = trainer.step(&mut model, &data).expect("step");
    let first_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut last = first;
    for _ in 0..steps {
        last = trainer.step(&mut model, &data).expect("step");
    }
    let per = t.elapsed().as_secs_f64() / steps.max(1) as f64;
    println!(
        "{{\"impl\":\"baselines\",\"kind\":\"{kind}\",\"width\":{width},\"depth\":{depth},\"batch\":{batch},\"params\":{},\"threads\":{},\"steps\":{steps},\"first_step_s\":{first_s:.4},\"step_s\":{per:.4},\"steps_per_s\":{:.3},\"loss_first\":{:.6},\"loss_last\":{:.6}}}",
        model.num_params(),
        rayon::current_num_threads(),
        1.0 / per,
        first.loss,
        last.loss
    );
}
