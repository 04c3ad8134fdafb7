//! SAL's geometric initialisation: a DeepSDF-style decoder starts as the signed distance of
//! a sphere (so it has a surface before any training), and trains from there.

use baselines::{DecoderConfig, Mlp, Schedule, TrainConfig, TrainingData};
use vf_common::rng::{SplitMix64, Stream};

fn points(n: usize, seed: u64) -> Vec<[f64; 3]> {
    let mut rng = SplitMix64::new(seed, Stream::StudySphereData);
    (0..n).map(|_| [0, 1, 2].map(|_| 2.0 * rng.uniform() - 1.0)).collect()
}

#[test]
fn a_wide_decoder_starts_as_the_spheres_signed_distance() {
    let (radius, scale) = (0.7, 0.5);
    let model: Mlp<f64> = Mlp::new_geometric(DecoderConfig::deepsdf(256, 3, None, 0.1), 3, radius, scale).unwrap();
    let x = points(4000, 1);
    let f = model.eval(&x);
    let mut err = 0.0;
    let mut agree = 0;
    let mut clear = 0;
    for (p, v) in x.iter().zip(&f) {
        let d = scale * ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - radius);
        err += (v - d.tanh()).abs();
        if d.abs() > 0.05 {
            clear += 1;
            agree += usize::from((*v < 0.0) == (d < 0.0));
        }
    }
    let mean = err / x.len() as f64;
    // Finite width and depth: SAL's construction is exact only in the limit (measured 0.046
    // here, against 0.23 for the default initialisation below).
    assert!(mean < 0.08, "mean |f − tanh(s(‖x‖ − r))| = {mean}");
    assert!(agree as f64 >= 0.97 * clear as f64, "sign agrees at {agree} of {clear} points off the surface");
}

#[test]
fn the_default_initialisation_is_not_a_sphere() {
    // The check above can fail: PyTorch's default initialisation is far from the distance.
    let model: Mlp<f64> = Mlp::new(DecoderConfig::deepsdf(256, 3, None, 0.1), 3).unwrap();
    let x = points(4000, 1);
    let f = model.eval(&x);
    let err: f64 = x
        .iter()
        .zip(&f)
        .map(|(p, v)| (v - (0.5 * ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 0.7)).tanh()).abs())
        .sum::<f64>()
        / x.len() as f64;
    assert!(err > 0.15, "{err}");
}

#[test]
fn skip_layers_and_every_width_initialise_and_train() {
    // A small decoder with a skip connection: finite, and a few hundred steps of training on
    // a sphere's distance lower the loss from the start.
    let config = DecoderConfig::deepsdf(16, 3, Some(2), 0.1);
    let mut model: Mlp<f32> = Mlp::new_geometric(config, 0, 1.0, 0.5).unwrap();
    let x = points(20_000, 2);
    let sdf: Vec<f64> = x.iter().map(|p| 0.5 * ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - 0.7)).collect();
    let data = TrainingData { points: x, occupancy: None, sdf: Some(sdf) };
    assert!(model.eval(&data.points[..100]).iter().all(|v| v.is_finite()));
    let config = TrainConfig { steps: 300, batch: 2048, lr: 3e-3, schedule: Schedule::Constant, ..Default::default() };
    let report = baselines::train(&mut model, &data, &config, |_| std::ops::ControlFlow::Continue(())).unwrap();
    let first = report.losses[..10].iter().sum::<f64>() / 10.0;
    let last = report.losses[report.losses.len() - 10..].iter().sum::<f64>() / 10.0;
    assert!(last < 0.5 * first, "loss {first} → {last}");
}

#[test]
fn bad_sphere_settings_are_refused() {
    for (r, s) in [(0.0, 0.5), (f64::NAN, 0.5), (1.0, -1.0), (1.0, f64::INFINITY)] {
        assert!(Mlp::<f32>::new_geometric(DecoderConfig::deepsdf(8, 2, None, 0.1), 0, r, s).is_err(), "{r} {s}");
    }
}

#[test]
fn the_learning_rate_factor_scales_the_steps() {
    // Two trainers from the same model and seed: a factor of 0 freezes the parameters.
    let config = DecoderConfig::occnet(8, 2);
    let model: Mlp<f32> = Mlp::new(config, 0).unwrap();
    let x = points(4096, 3);
    let occ: Vec<f64> = x.iter().map(|p| f64::from(p[0] * p[0] + p[1] * p[1] + p[2] * p[2] < 0.5)).collect();
    let data = TrainingData { points: x, occupancy: Some(occ), sdf: None };
    let tc = TrainConfig { steps: 10, batch: 1024, ..Default::default() };
    let mut frozen = model.clone();
    let mut t = baselines::Trainer::new(&frozen, data.points.len(), &tc).unwrap();
    t.set_lr_factor(0.0);
    assert_eq!(t.lr_factor(), 0.0);
    for _ in 0..5 {
        let rec = t.step(&mut frozen, &data).unwrap();
        assert_eq!(rec.lr, 0.0);
    }
    assert_eq!(frozen.params(), model.params());
    let mut moving = model.clone();
    let mut t = baselines::Trainer::new(&moving, data.points.len(), &tc).unwrap();
    t.step(&mut moving, &data).unwrap();
    assert_ne!(moving.params(), model.params());
}
