//! Fully connected ReLU networks in f32 with hand-written backpropagation on ndarray's
//! matrix products (matrixmultiply's sgemm).
//!
//! Why by hand: the networks here are plain stacks of linear layers (the encoder, the
//! Voronoi decoder) and a one-hidden-layer conditional MLP (the OccNet decoders), trained
//! with Adam; the workspace already does this for the sphere study's baselines
//! (`baselines`), and the Rust deep-learning frameworks (burn, candle, tch) would each add
//! hundreds of crates or a libtorch download to a build that must stay lean on a 2-core
//! machine. The gradients are checked against finite differences in the tests, and the
//! throughput against PyTorch in `benches/compare_mnist.py`.
//!
//! Initialisation: He (Kaiming) uniform weights, ±√(6/fan_in), which keep the activations'
//! scale through the ReLU layers (PyTorch's `nn.Linear` default, ±1/√fan_in, shrinks them
//! by about √6 a layer, so the code of a 5-layer encoder starts near zero and the decoders
//! first learn to ignore it), and PyTorch's biases, ±1/√fan_in; the benchmark's PyTorch
//! model does the same.

use ndarray::linalg::general_mat_mul;
use ndarray::{ArrayView2, ArrayViewMut2};
use vf_common::ChunkRng;

/// A stack of linear layers `sizes[0] → sizes[1] → … → sizes[L]`, ReLU after every layer
/// but the last. Parameters are flat: for each layer its weight (in × out, row-major) then
/// its bias (out).
#[derive(Clone, Debug, PartialEq)]
pub struct Dense {
    sizes: Vec<usize>,
    /// The parameters, flat.
    pub params: Vec<f32>,
}

/// The inputs of every layer for one batch (what backpropagation needs).
#[derive(Clone, Debug, Default)]
pub struct Tape {
    /// `acts[l]`: input of layer l (rows × sizes[l]); `acts[L]` is the output.
    acts: Vec<Vec<f32>>,
    rows: usize,
}

impl Tape {
    /// The output of the last forward pass (rows × out).
    pub fn output(&self) -> &[f32] {
        self.acts.last().map_or(&[], |v| v.as_slice())
    }
}

impl Dense {
    /// He-initialised layers of `sizes` (at least two entries, all ≥ 1), from `rng`.
    pub fn new(sizes: &[usize], rng: &mut ChunkRng) -> Self {
        assert!(sizes.len() >= 2 && sizes.iter().all(|&s| s > 0), "layer sizes {sizes:?}");
        let mut params = Vec::with_capacity(Self::count(sizes));
        for w in sizes.windows(2) {
            let bound = (6.0 / w[0] as f64).sqrt();
            for _ in 0..w[0] * w[1] {
                params.push(((2.0 * rng.uniform() - 1.0) * bound) as f32);
            }
            let bias = 1.0 / (w[0] as f64).sqrt();
            for _ in 0..w[1] {
                params.push(((2.0 * rng.uniform() - 1.0) * bias) as f32);
            }
        }
        Dense { sizes: sizes.to_vec(), params }
    }

    /// Parameter count of layers `sizes`.
    pub fn count(sizes: &[usize]) -> usize {
        sizes.windows(2).map(|w| (w[0] + 1) * w[1]).sum()
    }

    /// The layer sizes.
    pub fn sizes(&self) -> &[usize] {
        &self.sizes
    }

    /// Inputs per row.
    pub fn n_in(&self) -> usize {
        self.sizes[0]
    }

    /// Outputs per row.
    pub fn n_out(&self) -> usize {
        *self.sizes.last().expect("at least two sizes")
    }

    /// (weight offset, bias offset) of layer `l`.
    fn offsets(&self, l: usize) -> (usize, usize) {
        let w = Self::count(&self.sizes[..=l]);
        (w, w + self.sizes[l] * self.sizes[l + 1])
    }

    /// Forward pass of `rows` inputs `x` (rows × n_in); the output is
    /// [`Tape::output`].
    pub fn forward(&self, x: &[f32], rows: usize, tape: &mut Tape) {
        let nl = self.sizes.len() - 1;
        tape.rows = rows;
        tape.acts.resize(nl + 1, Vec::new());
        tape.acts[0].clear();
        tape.acts[0].extend_from_slice(&x[..rows * self.n_in()]);
        for l in 0..nl {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let (wo, bo) = self.offsets(l);
            let w = ArrayView2::from_shape((n_in, n_out), &self.params[wo..bo]).expect("weight shape");
            let b = &self.params[bo..bo + n_out];
            let (lo, hi) = tape.acts.split_at_mut(l + 1);
            let out = &mut hi[0];
            out.clear();
            out.resize(rows * n_out, 0.0);
            {
                let a = ArrayView2::from_shape((rows, n_in), &lo[l][..rows * n_in]).expect("input shape");
                let mut c = ArrayViewMut2::from_shape((rows, n_out), &mut out[..]).expect("output shape");
                general_mat_mul(1.0, &a, &w, 0.0, &mut c);
            }
            let relu = l + 1 < nl;
            for row in out.chunks_exact_mut(n_out) {
                for (z, &bj) in row.iter_mut().zip(b) {
                    let v = *z + bj;
                    *z = if relu && v < 0.0 { 0.0 } else { v };
                }
            }
        }
    }

    /// Backward pass of the last [`Dense::forward`] on `tape`: adds the gradient of the
    /// loss whose derivative with respect to the output is `d_out` (rows × n_out) into
    /// `grad` (flat like the parameters), and writes the derivative with respect to the
    /// input into `d_in` (rows × n_in) when given.
    pub fn backward(&self, tape: &Tape, d_out: &[f32], grad: &mut [f32], d_in: Option<&mut Vec<f32>>) {
        let rows = tape.rows;
        let nl = self.sizes.len() - 1;
        let mut d_cur = d_out[..rows * self.n_out()].to_vec();
        let mut d_next = Vec::new();
        let want_input = d_in.is_some();
        for l in (0..nl).rev() {
            let (n_in, n_out) = (self.sizes[l], self.sizes[l + 1]);
            let (wo, bo) = self.offsets(l);
            let a = ArrayView2::from_shape((rows, n_in), &tape.acts[l][..rows * n_in]).expect("input shape");
            let dz = ArrayView2::from_shape((rows, n_out), &d_cur[..]).expect("delta shape");
            {
                let (gw, gb) = grad[wo..bo + n_out].split_at_mut(n_in * n_out);
                let mut gw = ArrayViewMut2::from_shape((n_in, n_out), gw).expect("weight shape");
                general_mat_mul(1.0, &a.t(), &dz, 1.0, &mut gw);
                for row in d_cur.chunks_exact(n_out) {
                    for (g, &d) in gb.iter_mut().zip(row) {
                        *g += d;
                    }
                }
            }
            if l == 0 && !want_input {
                break;
            }
            let w = ArrayView2::from_shape((n_in, n_out), &self.params[wo..bo]).expect("weight shape");
            d_next.clear();
            d_next.resize(rows * n_in, 0.0);
            {
                let mut da = ArrayViewMut2::from_shape((rows, n_in), &mut d_next[..]).expect("delta shape");
                general_mat_mul(1.0, &dz, &w.t(), 0.0, &mut da);
            }
            if l > 0 {
                // Through the ReLU that produced this layer's input.
                for (d, &x) in d_next.iter_mut().zip(&tape.acts[l]) {
                    if x <= 0.0 {
                        *d = 0.0;
                    }
                }
            }
            std::mem::swap(&mut d_cur, &mut d_next);
        }
        if let Some(d_in) = d_in {
            d_in.clear();
            d_in.extend_from_slice(&d_cur);
        }
    }
}

/// The OccNet decoder: a conditional MLP f(z, x) = w₂ · ReLU(W [z; x] + b₁) + b₂ with one
/// hidden layer, on the concatenated latent code z and point x. Stored as the
/// [`Dense`] `[latent + 2, hidden, 1]` whose first weight rows belong to z, and evaluated
/// per image with W_z z + b₁ computed once for all of the image's points: the same
/// function and gradients as the concatenated MLP, at O(points × hidden) per image
/// instead of O(points × hidden × (latent + 2)).
pub struct OccNetScratch {
    base: Vec<f32>,
    d_sum: Vec<f32>,
}

impl OccNetScratch {
    /// Buffers for a decoder of `hidden` units.
    pub fn new(hidden: usize) -> Self {
        OccNetScratch { base: vec![0.0; hidden], d_sum: vec![0.0; hidden] }
    }
}

/// The decoder's input for a point of the unit square: its coordinates mapped to
/// [−1, 1] (centred inputs put the hidden units' ReLU kinks across the square from the
/// start; inputs in [0, 1] put them all through one corner).
#[inline]
pub fn point_input(p: [f64; 2]) -> [f32; 2] {
    [(2.0 * p[0] - 1.0) as f32, (2.0 * p[1] - 1.0) as f32]
}

/// Logits of the OccNet decoder `dec` (sizes `[L + 2, H, 1]`) for latent `z` (L) at
/// `points`, into `logits`.
pub fn occnet_logits(dec: &Dense, z: &[f32], points: &[[f64; 2]], s: &mut OccNetScratch, logits: &mut Vec<f32>) {
    occnet_base(dec, z, s);
    let inputs: Vec<[f32; 2]> = points.iter().map(|&p| point_input(p)).collect();
    tiled_logits(dec, &s.base, &inputs, logits);
}

fn dot(a: &[f32], b: &[f32]) -> f32 {
    // Eight partial sums: vectorises and keeps the f32 rounding error small.
    let mut acc = [0.0f32; 8];
    let (ca, ra) = a.split_at(a.len() / 8 * 8);
    let (cb, rb) = b.split_at(ca.len());
    for (x, y) in ca.chunks_exact(8).zip(cb.chunks_exact(8)) {
        for k in 0..8 {
            acc[k] += x[k] * y[k];
        }
    }
    let mut s: f32 = acc.iter().sum();
    for (x, y) in ra.iter().zip(rb) {
        s += x * y;
    }
    s
}

/// Hidden units per tile: small enough that a tile's vectors stay in L1 while every point
/// passes through it (a whole 16,384-unit row per point would stream ~1 MB a point).
const TILE: usize = 512;

/// Logits at `inputs` given the image's W_z z + b₁ (`base`), tile by tile.
fn tiled_logits(dec: &Dense, base: &[f32], inputs: &[[f32; 2]], logits: &mut Vec<f32>) {
    let l = dec.sizes[0] - 2;
    let h = dec.sizes[1];
    let (w1, _) = dec.offsets(0);
    let (w2o, b2o) = dec.offsets(1);
    let wx = &dec.params[w1 + l * h..w1 + (l + 1) * h];
    let wy = &dec.params[w1 + (l + 1) * h..w1 + (l + 2) * h];
    let w2 = &dec.params[w2o..w2o + h];
    logits.clear();
    logits.resize(inputs.len(), dec.params[b2o]);
    let mut row = [0.0f32; TILE];
    for t0 in (0..h).step_by(TILE) {
        let t1 = (t0 + TILE).min(h);
        let r = &mut row[..t1 - t0];
        for (lg, &[x, y]) in logits.iter_mut().zip(inputs) {
            relu_row(r, &base[t0..t1], &wx[t0..t1], &wy[t0..t1], x, y);
            *lg += dot(r, &w2[t0..t1]);
        }
    }
}

#[inline]
fn relu_row(row: &mut [f32], base: &[f32], wx: &[f32], wy: &[f32], x: f32, y: f32) {
    for (((r, &b), &a), &c) in row.iter_mut().zip(base).zip(wx).zip(wy) {
        let v = b + x * a + y * c;
        *r = if v > 0.0 { v } else { 0.0 };
    }
}

/// W_z z + b₁ of the decoder for code `z`, into `s.base`.
fn occnet_base(dec: &Dense, z: &[f32], s: &mut OccNetScratch) {
    let l = dec.sizes[0] - 2;
    let h = dec.sizes[1];
    let (w1, b1) = dec.offsets(0);
    let w = &dec.params[w1..b1];
    s.base.clear();
    s.base.extend_from_slice(&dec.params[b1..b1 + h]);
    for (k, &zk) in z[..l].iter().enumerate() {
        for (b, &wk) in s.base.iter_mut().zip(&w[k * h..(k + 1) * h]) {
            *b += zk * wk;
        }
    }
}

/// Forward and backward of the OccNet decoder for one image: binary cross-entropy with
/// logits against `occupancy`, averaged over the points and multiplied by `scale`. Adds
/// the parameter gradient into `grad` (flat like `dec.params`), writes ∂loss/∂z into
/// `d_z`, returns the (unscaled) mean loss.
///
/// Eight arguments: the hot loop's inputs and its three output buffers, passed apart so
/// a caller reuses the scratch and writes the gradients into slices of its own buffers.
#[allow(clippy::too_many_arguments)]
pub fn occnet_loss_grad(
    dec: &Dense,
    z: &[f32],
    points: &[[f64; 2]],
    occupancy: &[bool],
    scale: f32,
    s: &mut OccNetScratch,
    grad: &mut [f32],
    d_z: &mut [f32],
) -> f64 {
    let l = dec.sizes[0] - 2;
    let h = dec.sizes[1];
    let (w1, b1) = dec.offsets(0);
    let (w2o, b2o) = dec.offsets(1);
    // W_z z + b₁ once; then each point's hidden row is made, used and dropped while it is
    // in cache (one pass instead of writing and re-reading points × hidden floats).
    occnet_base(dec, z, s);
    let wx = &dec.params[w1 + l * h..w1 + (l + 1) * h];
    let wy = &dec.params[w1 + (l + 1) * h..w1 + (l + 2) * h];
    let n = points.len().max(1) as f32;
    let mut loss = 0.0f64;
    s.d_sum.clear();
    s.d_sum.resize(h, 0.0);
    let (g1, g2) = grad.split_at_mut(w2o);
    let (gw2, gb2) = g2.split_at_mut(b2o - w2o);
    let mut dx = vec![0.0f32; h];
    let mut dy = vec![0.0f32; h];
    let w2 = &dec.params[w2o..w2o + h];
    let inputs: Vec<[f32; 2]> = points.iter().map(|&p| point_input(p)).collect();
    let mut row = [0.0f32; TILE];
    // Pass 1: the logits.
    let mut logits = Vec::new();
    tiled_logits(dec, &s.base, &inputs, &mut logits);
    // The loss and its derivative per point.
    let mut dl = Vec::with_capacity(points.len());
    for (&logit, &o) in logits.iter().zip(occupancy) {
        let t = if o { 1.0 } else { 0.0 };
        let zl = f64::from(logit);
        loss += zl.max(0.0) + (-zl.abs()).exp().ln_1p() - t * zl;
        let sig = if zl >= 0.0 { 1.0 / (1.0 + (-zl).exp()) } else { zl.exp() / (1.0 + zl.exp()) };
        let d = ((sig - t) as f32) * scale / n;
        gb2[0] += d;
        dl.push(d);
    }
    // Pass 2: the gradients, tile by tile (the rows are recomputed: cheaper than storing).
    for t0 in (0..h).step_by(TILE) {
        let t1 = (t0 + TILE).min(h);
        let r = &mut row[..t1 - t0];
        let (gw, w, ds, gx, gy) =
            (&mut gw2[t0..t1], &w2[t0..t1], &mut s.d_sum[t0..t1], &mut dx[t0..t1], &mut dy[t0..t1]);
        for (&d, &[x, y]) in dl.iter().zip(&inputs) {
            relu_row(r, &s.base[t0..t1], &wx[t0..t1], &wy[t0..t1], x, y);
            // Branch-free so the loops vectorise: the ReLU's derivative as a 0/1 factor.
            for (((((g, &a), &wj), dsj), gxj), gyj) in
                gw.iter_mut().zip(r.iter()).zip(w).zip(ds.iter_mut()).zip(gx.iter_mut()).zip(gy.iter_mut())
            {
                *g += d * a;
                let da = if a > 0.0 { d * wj } else { 0.0 };
                *dsj += da;
                *gxj += x * da;
                *gyj += y * da;
            }
        }
    }
    // Hidden pre-activation gradients summed over the points: W_x, W_y from dx, dy; the
    // bias and W_z (and z) from their sum.
    let w = &dec.params[w1..b1];
    for j in 0..h {
        g1[w1 + l * h + j] += dx[j];
        g1[w1 + (l + 1) * h + j] += dy[j];
        g1[b1 + j] += s.d_sum[j];
    }
    for k in 0..l {
        let gz = &mut g1[w1 + k * h..w1 + (k + 1) * h];
        for (g, &ds) in gz.iter_mut().zip(&s.d_sum) {
            *g += z[k] * ds;
        }
        d_z[k] = dot(&w[k * h..(k + 1) * h], &s.d_sum);
    }
    loss / f64::from(n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use vf_common::Stream;

    fn loss_of(net: &Dense, x: &[f32], rows: usize, target: &[f32]) -> f64 {
        let mut t = Tape::default();
        net.forward(x, rows, &mut t);
        t.output().iter().zip(target).map(|(&o, &y)| 0.5 * f64::from(o - y).powi(2)).sum()
    }

    #[test]
    fn dense_gradients_match_finite_differences() {
        let mut rng = ChunkRng::for_chunk(1, Stream::Test, 41);
        let net = Dense::new(&[5, 7, 6, 3], &mut rng);
        let rows = 4;
        let x: Vec<f32> = (0..rows * 5).map(|_| (rng.uniform() * 2.0 - 1.0) as f32).collect();
        let y: Vec<f32> = (0..rows * 3).map(|_| rng.uniform() as f32).collect();
        let mut t = Tape::default();
        net.forward(&x, rows, &mut t);
        let d_out: Vec<f32> = t.output().iter().zip(&y).map(|(o, y)| o - y).collect();
        let mut grad = vec![0.0; net.params.len()];
        let mut d_in = Vec::new();
        net.backward(&t, &d_out, &mut grad, Some(&mut d_in));
        let h = 1e-2f32;
        for i in (0..net.params.len()).step_by(7) {
            let mut p = net.clone();
            p.params[i] += h;
            let up = loss_of(&p, &x, rows, &y);
            p.params[i] -= 2.0 * h;
            let down = loss_of(&p, &x, rows, &y);
            let fd = (up - down) / (2.0 * f64::from(h));
            assert!((fd - f64::from(grad[i])).abs() < 2e-3 * (1.0 + fd.abs()), "param {i}: {fd} vs {}", grad[i]);
        }
        // A smaller step for the inputs: a step of 1e-2 crosses ReLU kinks.
        let h = 1e-3f32;
        for i in 0..x.len() {
            let mut xp = x.clone();
            xp[i] += h;
            let up = loss_of(&net, &xp, rows, &y);
            xp[i] -= 2.0 * h;
            let down = loss_of(&net, &xp, rows, &y);
            let fd = (up - down) / (2.0 * f64::from(h));
            assert!((fd - f64::from(d_in[i])).abs() < 2e-3 * (1.0 + fd.abs()), "input {i}: {fd} vs {}", d_in[i]);
        }
    }

    #[test]
    fn occnet_decoder_is_the_concatenated_mlp_and_its_gradients_match() {
        let mut rng = ChunkRng::for_chunk(2, Stream::Test, 42);
        let dec = Dense::new(&[6, 9, 1], &mut rng);
        let z: Vec<f32> = (0..4).map(|_| (rng.uniform() * 2.0 - 1.0) as f32).collect();
        let pts: Vec<[f64; 2]> = (0..5).map(|_| [rng.uniform(), rng.uniform()]).collect();
        let occ = [true, false, true, true, false];
        let mut s = OccNetScratch::new(9);
        let mut logits = Vec::new();
        occnet_logits(&dec, &z, &pts, &mut s, &mut logits);
        // Same as the Dense on [z; x].
        let x: Vec<f32> = pts.iter().flat_map(|p| z.iter().copied().chain(point_input(*p))).collect();
        let mut t = Tape::default();
        dec.forward(&x, 5, &mut t);
        for (a, b) in logits.iter().zip(t.output()) {
            assert!((a - b).abs() < 1e-5);
        }
        let mut grad = vec![0.0; dec.params.len()];
        let mut dz = vec![0.0; 4];
        let loss = |d: &Dense, z: &[f32]| {
            let mut s = OccNetScratch::new(9);
            let mut g = vec![0.0; d.params.len()];
            let mut dz = vec![0.0; 4];
            occnet_loss_grad(d, z, &pts, &occ, 1.0, &mut s, &mut g, &mut dz)
        };
        occnet_loss_grad(&dec, &z, &pts, &occ, 1.0, &mut s, &mut grad, &mut dz);
        let h = 1e-2f32;
        for (i, &g) in grad.iter().enumerate() {
            let mut p = dec.clone();
            p.params[i] += h;
            let up = loss(&p, &z);
            p.params[i] -= 2.0 * h;
            let down = loss(&p, &z);
            let fd = (up - down) / (2.0 * f64::from(h));
            assert!((fd - f64::from(g)).abs() < 2e-3 * (1.0 + fd.abs()), "param {i}: {fd} vs {g}");
        }
        for k in 0..4 {
            let mut zp = z.clone();
            zp[k] += h;
            let up = loss(&dec, &zp);
            zp[k] -= 2.0 * h;
            let down = loss(&dec, &zp);
            let fd = (up - down) / (2.0 * f64::from(h));
            assert!((fd - f64::from(dz[k])).abs() < 2e-3 * (1.0 + fd.abs()), "z {k}: {fd} vs {}", dz[k]);
        }
    }
}
