//! The decoders: fully connected ReLU networks `x ∈ R³ → R`, forward and hand-written
//! backward passes over preallocated per-chunk workspaces.
//!
//! Layout: linear layer `l` (`0..=depth`) maps `in_l → out_l` with `out_l = width` for the
//! `depth` hidden layers and `1` for the output layer; `in_0 = 3` and `in_l = width` (plus 3
//! when `skip == Some(l)`: the input point is concatenated to that layer's input, as in
//! DeepSDF). Parameters live in one flat vector, layer by layer: the weight matrix `W_l`
//! (`in_l × out_l`, row-major, so a layer is `Z = A·W + b` on row-major activations) and
//! then the bias `b_l`.

use ndarray::linalg::general_mat_mul;
use ndarray::{s, Array3, ArrayView2, ArrayViewMut2};
use rayon::prelude::*;

use crate::error::{config_err, BaselineError, Result};
use crate::scalar::Real;
use vf_common::rng::{SplitMix64, Stream};

/// Which decoder and loss.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecoderKind {
    /// Occupancy Networks style: the output is an occupancy logit (positive inside), trained
    /// with binary cross-entropy on occupancy targets in [0, 1].
    OccNet,
    /// DeepSDF style: the output is `tanh` of the last layer, a signed distance (negative
    /// inside), trained with the clamped L1 loss `|clamp(f, ±δ) − clamp(s, ±δ)|`.
    DeepSdf,
}

/// Shape and loss of a decoder.
#[derive(Clone, Debug, PartialEq)]
pub struct DecoderConfig {
    /// OccNet or DeepSDF: the output and the loss.
    pub kind: DecoderKind,
    /// Units per hidden layer (≥ 1).
    pub width: usize,
    /// Number of hidden layers (≥ 1); there are `depth + 1` linear layers.
    pub depth: usize,
    /// `Some(l)` with `1 ≤ l ≤ depth`: concatenate the input point to the input of linear
    /// layer `l` (DeepSDF uses the middle layer). `None`: plain MLP.
    pub skip: Option<usize>,
    /// DeepSDF clamp δ (> 0, finite); ignored by OccNet. DeepSDF's paper uses 0.1.
    pub delta: f64,
}

impl DecoderConfig {
    /// An OccNet-style decoder without skip connection.
    pub fn occnet(width: usize, depth: usize) -> Self {
        DecoderConfig { kind: DecoderKind::OccNet, width, depth, skip: None, delta: 0.1 }
    }

    /// A DeepSDF-style decoder.
    pub fn deepsdf(width: usize, depth: usize, skip: Option<usize>, delta: f64) -> Self {
        DecoderConfig { kind: DecoderKind::DeepSdf, width, depth, skip, delta }
    }

    /// Check every field; the error names the field.
    pub fn validate(&self) -> Result<()> {
        if self.width == 0 {
            return config_err("width", self.width, "a decoder needs at least one unit per hidden layer");
        }
        if self.depth == 0 {
            return config_err("depth", self.depth, "a decoder needs at least one hidden layer");
        }
        if let Some(l) = self.skip {
            if l == 0 || l > self.depth {
                return config_err("skip", l, "the skip layer must be between 1 and depth (layer 0 already sees x)");
            }
        }
        if self.kind == DecoderKind::DeepSdf && !(self.delta.is_finite() && self.delta > 0.0) {
            return config_err("delta", self.delta, "the DeepSDF clamp must be finite and positive");
        }
        // Parameter count and the largest activation must fit comfortably in memory indices.
        let n = self.count_params().ok_or(BaselineError::Config {
            field: "width",
            value: self.width.to_string(),
            reason: "the parameter count overflows",
        })?;
        if n > (1usize << 34) {
            return config_err("width", self.width, "more than 2^34 parameters");
        }
        Ok(())
    }

    fn count_params(&self) -> Option<usize> {
        let mut n = 0usize;
        for l in 0..=self.depth {
            let (i, o) = self.layer_dims(l);
            n = n.checked_add(i.checked_mul(o)?.checked_add(o)?)?;
        }
        Some(n)
    }

    /// Exact number of trainable parameters (weights and biases), after validation.
    pub fn num_params(&self) -> Result<usize> {
        self.validate()?;
        Ok(self.count_params().unwrap_or(0))
    }

    /// `(in, out)` of linear layer `l`.
    fn layer_dims(&self, l: usize) -> (usize, usize) {
        let n_in = if l == 0 { 3 } else { self.width + if self.skip == Some(l) { 3 } else { 0 } };
        let n_out = if l == self.depth { 1 } else { self.width };
        (n_in, n_out)
    }
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Layer {
    pub n_in: usize,
    pub n_out: usize,
    /// Offset of `W` (then `b` at `w + n_in * n_out`) in the flat parameter vector.
    pub w: usize,
}

impl Layer {
    pub fn b(&self) -> usize {
        self.w + self.n_in * self.n_out
    }
}

/// A decoder in float type `T` (use [`Decoder`] = `Mlp<f32>` for training; `Mlp<f64>` is
/// what the gradient checks use).
#[derive(Clone, Debug)]
pub struct Mlp<T: Real> {
    config: DecoderConfig,
    pub(crate) layers: Vec<Layer>,
    pub(crate) params: Vec<T>,
}

/// The decoder used for training and the sphere study: `f32` like PyTorch's default.
pub type Decoder = Mlp<f32>;

impl<T: Real> Mlp<T> {
    /// A decoder with PyTorch's default `nn.Linear` initialisation (weights and biases
    /// uniform in ±1/√fan_in), drawn from `seed` in a fixed order: the same seed gives the
    /// same parameters (up to rounding to `T`) in `f32` and `f64`.
    pub fn new(config: DecoderConfig, seed: u64) -> Result<Self> {
        config.validate()?;
        let mut layers = Vec::with_capacity(config.depth + 1);
        let mut off = 0;
        for l in 0..=config.depth {
            let (n_in, n_out) = config.layer_dims(l);
            layers.push(Layer { n_in, n_out, w: off });
            off += n_in * n_out + n_out;
        }
        let mut rng = SplitMix64::new(seed, Stream::MlpInit);
        let mut params = Vec::with_capacity(off);
        for layer in &layers {
            let bound = 1.0 / (layer.n_in as f64).sqrt();
            for _ in 0..layer.n_in * layer.n_out + layer.n_out {
                params.push(T::of((2.0 * rng.uniform() - 1.0) * bound));
            }
        }

        Ok(Mlp { config, layers, params })
    }

    /// A decoder that starts as the signed distance of a sphere: the geometric
    /// initialisation of SAL (Atzmon & Lipman, CVPR 2020), so a DeepSDF-style decoder begins
    /// with a surface instead of a constant. Hidden layers: weights N(0, 2/out), biases 0
    /// (the input point's columns of a skip layer start at 0); output layer: weights
    /// `scale`·√π/√in (with a tiny N(0, 1e-6) jitter), bias −`scale`·`radius`. For wide
    /// ReLU layers the output is then ≈ `scale`·(‖x‖ − `radius`) in the network's
    /// coordinates (`scale` converts them to the targets' unit; DeepSDF's `tanh` is ≈ the
    /// identity there). Drawn from `seed` in a fixed order.
    ///
    /// # Errors
    /// An invalid `config`, or a non-finite or non-positive `radius` or `scale`.
    pub fn new_geometric(config: DecoderConfig, seed: u64, radius: f64, scale: f64) -> Result<Self> {
        if !(radius.is_finite() && radius > 0.0) {
            return config_err("radius", radius, "the initial sphere's radius must be finite and positive");
        }
        if !(scale.is_finite() && scale > 0.0) {
            return config_err("scale", scale, "the output scale must be finite and positive");
        }
        let mut model = Self::new(config, seed)?;
        let mut rng = SplitMix64::new(seed, Stream::MlpInit);
        // Box–Muller from the stream's uniforms (one normal per pair; the order is fixed).
        let mut normal = move || {
            let u1 = rng.uniform().max(1e-300);
            let u2 = rng.uniform();
            (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
        };
        let last = model.layers.len() - 1;
        let skip = model.config.skip;
        for (l, layer) in model.layers.clone().iter().enumerate() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            for i in 0..n_in {
                for o in 0..n_out {
                    let v = if l == last {
                        scale * std::f64::consts::PI.sqrt() / (n_in as f64).sqrt() + 1e-6 * normal()
                    } else if skip == Some(l) && i >= n_in - 3 {
                        0.0
                    } else {
                        normal() * (2.0 / n_out as f64).sqrt()
                    };
                    model.params[layer.w + i * n_out + o] = T::of(v);
                }
            }
            for o in 0..n_out {
                model.params[layer.b() + o] = T::of(if l == last { -scale * radius } else { 0.0 });
            }
        }
        Ok(model)
    }

    /// The decoder's shape and loss.
    pub fn config(&self) -> &DecoderConfig {
        &self.config
    }

    /// Exact number of trainable parameters.
    pub fn num_params(&self) -> usize {
        self.params.len()
    }

    /// All parameters, flat: per linear layer `W` (`in × out`, row-major) then `b`.
    pub fn params(&self) -> &[T] {
        &self.params
    }

    /// All parameters, flat and writable (the layout of [`Mlp::params`]).
    pub fn params_mut(&mut self) -> &mut [T] {
        &mut self.params
    }

    /// `(in, out, offset of W, offset of b)` for each linear layer, in order.
    pub fn layer_shapes(&self) -> Vec<(usize, usize, usize, usize)> {
        self.layers.iter().map(|l| (l.n_in, l.n_out, l.w, l.b())).collect()
    }

    /// Decoder values at `points`: the occupancy logit (OccNet: surface at 0, positive
    /// inside) or the signed distance `tanh(·)` (DeepSDF: surface at 0, negative inside).
    /// Parallel over chunks of 4,096 points; each point's value does not depend on the
    /// chunking or the thread count.
    pub fn eval(&self, points: &[[f64; 3]]) -> Vec<f64> {
        self.eval_with(points.len(), |i| points[i])
    }

    /// Values at the points `point(0), …, point(n − 1)`, generated chunk by chunk.
    fn eval_with(&self, n: usize, point: impl Fn(usize) -> [f64; 3] + Sync) -> Vec<f64> {
        const ROWS: usize = 4096;
        let mut out = vec![0.0; n];
        let tanh = self.config.kind == DecoderKind::DeepSdf;
        out.par_chunks_mut(ROWS).enumerate().for_each_init(
            || Workspace::new(self, ROWS.min(n.max(1)), false),
            |ws, (c, o)| {
                let m = o.len();
                ws.load_points(self, (c * ROWS..c * ROWS + m).map(&point));
                ws.forward(self, m);
                for (o, z) in o.iter_mut().zip(&ws.out[..m]) {
                    *o = if tanh { z.tanh().wide() } else { z.wide() };
                }
            },
        );
        out
    }

    /// [`Mlp::eval`] on the `res³` grid points of the unit cube: entry `[i, j, k]` is the
    /// value at `(i, j, k) / (res − 1)`. `2 ≤ res ≤ 1024`. Parallel over chunks of points;
    /// about 100,000 points/s for the 264,449-parameter 3→256×5→1 decoder on 2 loaded cores
    /// (res 128: 20 s; `examples/extract_timing.rs`).
    pub fn eval_grid(&self, res: usize) -> Result<Array3<f64>> {
        self.eval_grid_box(res, [0.0; 3], [1.0; 3])
    }

    /// [`Mlp::eval`] on the `res³` grid points of the box `[lo, hi]`: entry `[i, j, k]` is
    /// the value at `lo + (hi − lo) · (i, j, k) / (res − 1)`.
    pub fn eval_grid_box(&self, res: usize, lo: [f64; 3], hi: [f64; 3]) -> Result<Array3<f64>> {
        if res < 2 {
            return config_err("res", res, "a grid needs at least 2 points per axis");
        }
        if res > 1024 {
            return config_err("res", res, "at most 1024 points per axis (8 GiB of f64)");
        }
        if (0..3).any(|k| !(lo[k].is_finite() && hi[k].is_finite() && lo[k] < hi[k])) {
            return config_err("box", format!("{lo:?}..{hi:?}"), "the box must be finite with lo < hi");
        }
        let coord = |k: usize, i: usize| lo[k] + (hi[k] - lo[k]) * (i as f64 / (res - 1) as f64);
        let vals = self.eval_with(res * res * res, |n| {
            let (i, j, k) = (n / (res * res), (n / res) % res, n % res);
            [coord(0, i), coord(1, j), coord(2, k)]
        });
        Array3::from_shape_vec((res, res, res), vals).map_err(|e| BaselineError::Data(e.to_string()))
    }
}

/// Activations, deltas and (for training) a gradient accumulator for one chunk of up to
/// `rows` points. Allocated once; a training step only writes into it.
pub(crate) struct Workspace<T: Real> {
    /// `acts[l]`: input of linear layer `l`, `rows × in_l`, row-major.
    pub acts: Vec<Vec<T>>,
    /// Output pre-activation, `rows`.
    pub out: Vec<T>,
    pub d_cur: Vec<T>,
    pub d_next: Vec<T>,
    /// Gradient of this chunk's share of the loss, flat like the parameters.
    pub grad: Vec<T>,
    pub loss: f64,
}

impl<T: Real> Workspace<T> {
    pub fn new(model: &Mlp<T>, rows: usize, training: bool) -> Self {
        let w = model.config.width.max(1);
        Workspace {
            acts: model.layers.iter().map(|l| vec![T::zero(); rows * l.n_in]).collect(),
            out: vec![T::zero(); rows],
            d_cur: if training { vec![T::zero(); rows * w] } else { Vec::new() },
            d_next: if training { vec![T::zero(); rows * w] } else { Vec::new() },
            grad: if training { vec![T::zero(); model.params.len()] } else { Vec::new() },
            loss: 0.0,
        }
    }

    /// Write the input points into layer 0's input and the skip layer's last 3 columns.
    pub fn load_points(&mut self, model: &Mlp<T>, points: impl Iterator<Item = [f64; 3]>) {
        let skip = model.config.skip;
        let (head, tail) = self.acts.split_at_mut(1);
        let skip_buf = skip.map(|l| (&mut tail[l - 1], model.layers[l].n_in));
        let x0 = &mut head[0];
        match skip_buf {
            None => {
                for (r, p) in points.enumerate() {
                    for k in 0..3 {
                        x0[3 * r + k] = T::of(p[k]);
                    }
                }
            }
            Some((buf, n_in)) => {
                let base = n_in - 3;
                for (r, p) in points.enumerate() {
                    for k in 0..3 {
                        let v = T::of(p[k]);
                        x0[3 * r + k] = v;
                        buf[r * n_in + base + k] = v;
                    }
                }
            }
        }
    }

    /// Forward pass of the first `m` loaded rows; fills `acts[1..]` and `out`.
    pub fn forward(&mut self, model: &Mlp<T>, m: usize) {
        let p = &model.params;
        let nl = model.layers.len();
        for (l, layer) in model.layers.iter().enumerate() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            let w = ArrayView2::from_shape((n_in, n_out), &p[layer.w..layer.w + n_in * n_out]).expect("layer shape");
            let b = &p[layer.b()..layer.b() + n_out];
            let (lo, hi) = self.acts.split_at_mut(l + 1);
            let a = ArrayView2::from_shape((m, n_in), &lo[l][..m * n_in]).expect("activation shape");
            if l + 1 < nl {
                let next_in = model.layers[l + 1].n_in;
                let buf = &mut hi[0][..m * next_in];
                {
                    let mut c = ArrayViewMut2::from_shape((m, next_in), &mut *buf).expect("activation shape");
                    let mut c = c.slice_mut(s![.., ..n_out]);
                    general_mat_mul(T::one(), &a, &w, T::zero(), &mut c);
                }
                for row in buf.chunks_exact_mut(next_in) {
                    for (z, &bj) in row[..n_out].iter_mut().zip(b) {
                        let v = *z + bj;
                        *z = if v > T::zero() { v } else { T::zero() };
                    }
                }
            } else {
                let out = &mut self.out[..m];
                {
                    let mut c = ArrayViewMut2::from_shape((m, 1), &mut *out).expect("output shape");
                    general_mat_mul(T::one(), &a, &w, T::zero(), &mut c);
                }
                for z in out.iter_mut() {
                    *z = *z + b[0];
                }
            }
        }
    }

    /// Loss of the first `m` rows against `targets` (summed, divided by `n_total`) and its
    /// gradient with respect to every parameter, into `self.grad` and `self.loss`. Call
    /// after [`Workspace::forward`].
    pub fn backward(&mut self, model: &Mlp<T>, m: usize, targets: impl Iterator<Item = f64>, n_total: usize) {
        let inv_n = 1.0 / n_total as f64;
        let cfg = &model.config;
        // Output delta dL/dz into d_cur (m × 1), loss in f64.
        let mut loss = 0.0f64;
        match cfg.kind {
            DecoderKind::OccNet => {
                for ((d, &z), y) in self.d_cur[..m].iter_mut().zip(&self.out[..m]).zip(targets) {
                    let z64 = z.wide();
                    // softplus(z) − y·z, stably.
                    loss += z64.max(0.0) + (-z64.abs()).exp().ln_1p() - y * z64;
                    let sig = if z64 >= 0.0 {
                        1.0 / (1.0 + (-z64).exp())
                    } else {
                        let e = z64.exp();
                        e / (1.0 + e)
                    };
                    *d = T::of((sig - y) * inv_n);
                }
            }
            DecoderKind::DeepSdf => {
                let delta = cfg.delta;
                for ((d, &z), s) in self.d_cur[..m].iter_mut().zip(&self.out[..m]).zip(targets) {
                    let f = z.wide().tanh();
                    let cf = f.clamp(-delta, delta);
                    let cs = s.clamp(-delta, delta);
                    let r = cf - cs;
                    loss += r.abs();
                    let sign = if r > 0.0 {
                        1.0
                    } else if r < 0.0 {
                        -1.0
                    } else {
                        0.0
                    };
                    let pass = if f.abs() < delta { 1.0 - f * f } else { 0.0 };
                    *d = T::of(sign * pass * inv_n);
                }
            }
        }
        self.loss = loss * inv_n;

        let p = &model.params;
        for (l, layer) in model.layers.iter().enumerate().rev() {
            let (n_in, n_out) = (layer.n_in, layer.n_out);
            let dz = ArrayView2::from_shape((m, n_out), &self.d_cur[..m * n_out]).expect("delta shape");
            let a = ArrayView2::from_shape((m, n_in), &self.acts[l][..m * n_in]).expect("activation shape");
            {
                let (gw, gb) = self.grad[layer.w..layer.b() + n_out].split_at_mut(n_in * n_out);
                let mut gw = ArrayViewMut2::from_shape((n_in, n_out), gw).expect("weight shape");
                general_mat_mul(T::one(), &a.t(), &dz, T::zero(), &mut gw);
                gb.fill(T::zero());
                for row in self.d_cur[..m * n_out].chunks_exact(n_out) {
                    for (g, &d) in gb.iter_mut().zip(row) {
                        *g = *g + d;
                    }
                }
            }
            if l == 0 {
                break;
            }
            // dA = dZ · W[..width]ᵀ, then through the ReLU that produced A's first `width` columns.
            let width = model.layers[l - 1].n_out;
            let w = ArrayView2::from_shape((n_in, n_out), &p[layer.w..layer.w + n_in * n_out]).expect("layer shape");
            let w_top = w.slice(s![..width, ..]);
            {
                let mut da = ArrayViewMut2::from_shape((m, width), &mut self.d_next[..m * width]).expect("delta shape");
                general_mat_mul(T::one(), &dz, &w_top.t(), T::zero(), &mut da);
            }
            for (drow, arow) in self.d_next[..m * width].chunks_exact_mut(width).zip(self.acts[l].chunks_exact(n_in)) {
                for (d, &a) in drow.iter_mut().zip(&arow[..width]) {
                    if a <= T::zero() {
                        *d = T::zero();
                    }
                }
            }
            std::mem::swap(&mut self.d_cur, &mut self.d_next);
        }
    }
}
