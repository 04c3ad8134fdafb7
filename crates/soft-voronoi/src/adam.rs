//! Adam (Kingma & Ba 2015) on the K×3 site positions, with bias correction.

/// Adam's moment estimates for K×3 parameters.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AdamParams {
    /// First-moment decay β₁.
    pub beta1: f64,
    /// Second-moment decay β₂.
    pub beta2: f64,
    /// ε added to √v̂.
    pub eps: f64,
}

impl Default for AdamParams {
    fn default() -> Self {
        AdamParams { beta1: 0.9, beta2: 0.999, eps: 1e-8 }
    }
}

/// One Adam update at 1-based step `t` with learning rate `lr`: moves `params` against
/// `grad` and updates the moments `m`, `v` in place. Returns the largest coordinate move.
pub fn step(
    p: &AdamParams,
    t: u64,
    lr: f64,
    params: &mut [[f64; 3]],
    grad: &[[f64; 3]],
    m: &mut [[f64; 3]],
    v: &mut [[f64; 3]],
) -> f64 {
    let c1 = 1.0 - p.beta1.powf(t as f64);
    let c2 = 1.0 - p.beta2.powf(t as f64);
    let mut max_move: f64 = 0.0;
    for (((x, g), m), v) in params.iter_mut().zip(grad).zip(m.iter_mut()).zip(v.iter_mut()) {
        for c in 0..3 {
            m[c] = p.beta1 * m[c] + (1.0 - p.beta1) * g[c];
            v[c] = p.beta2 * v[c] + (1.0 - p.beta2) * g[c] * g[c];
            let mv = lr * (m[c] / c1) / ((v[c] / c2).sqrt() + p.eps);
            x[c] -= mv;
            max_move = max_move.max(mv.abs());
        }
    }
    max_move
}
