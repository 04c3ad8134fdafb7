//! Every parameter's gradient against central finite differences, in f64, for both
//! decoders with and without skip connections, on one chunk and on many (the parallel
//! fixed-order reduction).

use baselines::{loss_and_grad, DecoderConfig, GradEngine, Mlp, TrainingData};

fn lcg(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed;
    move || {
        s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn data(n: usize, seed: u64) -> TrainingData {
    let mut r = lcg(seed);
    let points: Vec<[f64; 3]> = (0..n).map(|_| [r(), r(), r()]).collect();
    let sdf: Vec<f64> = points
        .iter()
        .map(|p| ((p[0] - 0.5).powi(2) + (p[1] - 0.5).powi(2) + (p[2] - 0.5).powi(2)).sqrt() - 0.3)
        .collect();
    let occupancy = sdf.iter().map(|&d| if d < 0.0 { 1.0 } else { 0.0 }).collect();
    TrainingData { points, occupancy: Some(occupancy), sdf: Some(sdf) }
}

fn loss(model: &Mlp<f64>, d: &TrainingData) -> f64 {
    loss_and_grad(model, d).unwrap().0
}

/// Checks every parameter; returns the worst relative error.
/// For DeepSDF with `delta < 1`, δ is replaced by the median |output| of the initial
/// decoder, so that half of the points are clamped (zero gradient) and half are not.
#[allow(clippy::needless_range_loop)] // index i addresses both the parameters and the gradient
fn check(mut cfg: DecoderConfig, seed: u64) -> f64 {
    let d = data(200, seed + 17);
    if cfg.kind == baselines::DecoderKind::DeepSdf && cfg.delta < 1.0 {
        let mut f: Vec<f64> =
            Mlp::<f64>::new(cfg.clone(), seed).unwrap().eval(&d.points).iter().map(|v| v.abs()).collect();
        f.sort_by(f64::total_cmp);
        cfg.delta = 0.5 * (f[99] + f[100]);
    }
    let mut model = Mlp::<f64>::new(cfg.clone(), seed).unwrap();
    let (_, grad) = loss_and_grad(&model, &d).unwrap();
    if cfg.kind == baselines::DecoderKind::DeepSdf && cfg.delta < 1.0 {
        // Both branches of the clamp are exercised.
        let f = model.eval(&d.points);
        let clamped = f.iter().filter(|v| v.abs() >= cfg.delta).count();
        assert!(clamped > 0 && clamped < f.len(), "{cfg:?}: {clamped} of {} outputs clamped", f.len());
    }
    assert_eq!(grad.len(), model.num_params());
    // Every tensor gets a gradient (so the check below is not vacuous).
    for (l, &(n_in, n_out, w, b)) in model.layer_shapes().iter().enumerate() {
        let max = |r: std::ops::Range<usize>| grad[r].iter().fold(0.0f64, |m, g| m.max(g.abs()));
        assert!(max(w..w + n_in * n_out) > 1e-6, "{cfg:?}: W{l} has a zero gradient");
        assert!(max(b..b + n_out) > 1e-6, "{cfg:?}: b{l} has a zero gradient");
    }
    let h = 1e-6;
    let mut worst = 0.0f64;
    for i in 0..model.num_params() {
        let p0 = model.params()[i];
        model.params_mut()[i] = p0 + h;
        let lp = loss(&model, &d);
        model.params_mut()[i] = p0 - h;
        let lm = loss(&model, &d);
        model.params_mut()[i] = p0;
        let fd = (lp - lm) / (2.0 * h);
        let err = (fd - grad[i]).abs() / (1e-7 + fd.abs().max(grad[i].abs()));
        let (layer, what) = model
            .layer_shapes()
            .iter()
            .enumerate()
            .find_map(|(l, &(_, _, w, b))| {
                if i >= w && i < b {
                    Some((l, "W"))
                } else if i >= b && i < b + model.layer_shapes()[l].1 {
                    Some((l, "b"))
                } else {
                    None
                }
            })
            .unwrap();
        assert!(
            err < 1e-5 || (fd - grad[i]).abs() < 1e-9,
            "{cfg:?}: parameter {i} ({what}{layer}): backprop {} vs finite difference {fd}",
            grad[i]
        );
        worst = worst.max(if (fd - grad[i]).abs() < 1e-9 { 0.0 } else { err });
    }
    worst
}

#[test]
fn occnet_gradients() {
    check(DecoderConfig::occnet(7, 3), 1);
    check(DecoderConfig::occnet(5, 1), 2);
}

#[test]
fn occnet_skip_gradients() {
    let mut c = DecoderConfig::occnet(6, 3);
    c.skip = Some(2);
    check(c, 3);
}

/// δ < 1: half of the outputs clamped (zero gradient), half not; δ = 2: the clamp never binds.
#[test]
fn deepsdf_gradients() {
    check(DecoderConfig::deepsdf(7, 3, None, 0.3), 4);
    // δ ≥ 1: the clamp never binds.
    check(DecoderConfig::deepsdf(6, 2, None, 2.0), 5);
}

#[test]
fn deepsdf_skip_gradients() {
    check(DecoderConfig::deepsdf(6, 4, Some(2), 0.3), 6);
    // Skip into the output layer.
    check(DecoderConfig::deepsdf(5, 2, Some(2), 0.3), 7);
}

/// The multi-chunk path (parallel chunks, fixed-order sum) gives the single-chunk gradient
/// up to rounding, and the loss is identical in value to the single-chunk one up to rounding.
#[test]
fn chunked_gradient_matches_single_chunk() {
    for cfg in [DecoderConfig::occnet(8, 3), DecoderConfig::deepsdf(8, 3, Some(2), 0.1)] {
        let d = data(1000, 9);
        let model = Mlp::<f64>::new(cfg.clone(), 11).unwrap();
        let (l1, g1) = loss_and_grad(&model, &d).unwrap();
        let idx: Vec<u32> = (0..1000).collect();
        let targets = d.targets(cfg.kind).unwrap();
        let mut e = GradEngine::new(&model, 1000, 37).unwrap();
        let l2 = e.loss_grad(&model, &d.points, targets, &idx).unwrap();
        // Misuse is an error, not a panic.
        assert!(e.loss_grad(&model, &d.points, targets, &[0, 1000]).is_err());
        assert!(e.loss_grad(&model, &d.points, targets, &[]).is_err());
        assert!(e.loss_grad(&model, &d.points, &targets[1..], &[0]).is_err());
        let big: Vec<u32> = (0..1001).map(|i| i % 1000).collect();
        assert!(e.loss_grad(&model, &d.points, targets, &big).is_err());
        let other = Mlp::<f64>::new(DecoderConfig::occnet(9, 3), 0).unwrap();
        assert!(e.loss_grad(&other, &d.points, targets, &idx).is_err());
        assert!((l1 - l2).abs() < 1e-12 * l1.abs().max(1.0), "{l1} vs {l2}");
        for (a, b) in g1.iter().zip(&e.grad) {
            assert!((a - b).abs() < 1e-12 * (1.0 + a.abs()), "{a} vs {b}");
        }
    }
}

/// The f32 decoder's gradient agrees with the f64 one (same seed) to f32 accuracy.
#[test]
fn f32_gradient_close_to_f64() {
    let d = data(500, 3);
    for cfg in [DecoderConfig::occnet(16, 3), DecoderConfig::deepsdf(16, 3, Some(2), 0.1)] {
        let m64 = Mlp::<f64>::new(cfg.clone(), 5).unwrap();
        let m32 = Mlp::<f32>::new(cfg.clone(), 5).unwrap();
        let (l64, g64) = loss_and_grad(&m64, &d).unwrap();
        let (l32, g32) = loss_and_grad(&m32, &d).unwrap();
        assert!((l64 - l32).abs() < 1e-5 * l64.abs().max(1.0));
        let scale = g64.iter().fold(0.0f64, |m, g| m.max(g.abs()));
        for (a, b) in g64.iter().zip(&g32) {
            assert!((a - *b as f64).abs() < 1e-4 * scale, "{a} vs {b}");
        }
    }
}
