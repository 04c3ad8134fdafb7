//! Adam (Kingma & Ba, "Adam: A method for stochastic optimization", ICLR 2015), in
//! PyTorch's form of the bias-corrected update:
//!
//! ```text
//! m ← β₁ m + (1 − β₁) g        v ← β₂ v + (1 − β₂) g²
//! p ← p − lr/(1 − β₁ᵗ) · m / (√v / √(1 − β₂ᵗ) + ε)
//! ```
//!
//! One home for the settings ([`AdamParams`]) and the update ([`AdamStep`]): the
//! soft-Voronoi trainer runs it on the K×3 f64 site coordinates, the MLP baselines on
//! their f32 (or f64) weights, chunk by chunk in parallel.

use num_traits::Float;
use serde::{Deserialize, Serialize};

/// Adam's constants (PyTorch's defaults).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct AdamParams {
    /// First-moment decay β₁, in [0, 1).
    pub beta1: f64,
    /// Second-moment decay β₂, in [0, 1).
    pub beta2: f64,
    /// ε added to the bias-corrected √v, > 0.
    pub eps: f64,
}

impl Default for AdamParams {
    fn default() -> Self {
        AdamParams { beta1: 0.9, beta2: 0.999, eps: 1e-8 }
    }
}

impl AdamParams {
    /// Checks the constants; `Err` names the first one out of range.
    pub fn validate(&self) -> Result<(), String> {
        if !(0.0..1.0).contains(&self.beta1) {
            return Err(format!("adam.beta1 = {} must be in [0, 1)", self.beta1));
        }
        if !(0.0..1.0).contains(&self.beta2) {
            return Err(format!("adam.beta2 = {} must be in [0, 1)", self.beta2));
        }
        if !(self.eps.is_finite() && self.eps > 0.0) {
            return Err(format!("adam.eps = {} must be finite and positive", self.eps));
        }
        Ok(())
    }

    /// The update of 1-based step `t` at learning rate `lr`, in float type `T`.
    pub fn at<T: Float>(&self, t: u64, lr: f64) -> AdamStep<T> {
        let t = t.min(i32::MAX as u64) as i32;
        let bc1 = 1.0 - self.beta1.powi(t);
        let bc2 = 1.0 - self.beta2.powi(t);
        let of = |x: f64| T::from(x).expect("a finite f64 converts to any float type");
        AdamStep {
            b1: of(self.beta1),
            b2: of(self.beta2),
            ob1: of(1.0 - self.beta1),
            ob2: of(1.0 - self.beta2),
            step: of(lr / bc1),
            inv_sqrt_bc2: of(1.0 / bc2.sqrt()),
            eps: of(self.eps),
        }
    }
}

/// The coefficients of one Adam step, ready to apply to any slice of parameters.
#[derive(Clone, Copy, Debug)]
pub struct AdamStep<T> {
    b1: T,
    b2: T,
    ob1: T,
    ob2: T,
    step: T,
    inv_sqrt_bc2: T,
    eps: T,
}

impl<T: Float> AdamStep<T> {
    /// Updates `params` against `grad` and the moments `m`, `v` in place (all the same
    /// length). Returns the largest |move| of a parameter.
    pub fn apply(&self, params: &mut [T], grad: &[T], m: &mut [T], v: &mut [T]) -> T {
        debug_assert!(params.len() == grad.len() && grad.len() == m.len() && m.len() == v.len());
        let mut max_move = T::zero();
        for i in 0..params.len() {
            let g = grad[i];
            m[i] = self.b1 * m[i] + self.ob1 * g;
            v[i] = self.b2 * v[i] + self.ob2 * g * g;
            let mv = self.step * m[i] / (v[i].sqrt() * self.inv_sqrt_bc2 + self.eps);
            params[i] = params[i] - mv;
            max_move = max_move.max(mv.abs());
        }
        max_move
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first step moves every parameter by lr·sign(g) (up to ε), whatever |g|.
    #[test]
    fn first_step_moves_by_the_learning_rate() {
        let a = AdamParams::default();
        let mut p = vec![1.0f64, -2.0, 0.5];
        let g = [3.0, -1e-3, 10.0];
        let (mut m, mut v) = (vec![0.0; 3], vec![0.0; 3]);
        let mv = a.at::<f64>(1, 0.1).apply(&mut p, &g, &mut m, &mut v);
        assert!((p[0] - 0.9).abs() < 1e-6 && (p[1] + 1.9).abs() < 1e-4 && (p[2] - 0.4).abs() < 1e-6, "{p:?}");
        assert!((mv - 0.1).abs() < 1e-6);
    }

    /// Matches the textbook form lr · m̂ / (√v̂ + ε) over many steps.
    #[test]
    fn matches_the_textbook_form() {
        let a = AdamParams::default();
        let (mut p, mut m, mut v) = (vec![0.3f64], vec![0.0], vec![0.0]);
        let (mut q, mut mq, mut vq) = (0.3f64, 0.0f64, 0.0f64);
        for t in 1..=200u64 {
            let g = (t as f64 * 0.37).sin();
            a.at::<f64>(t, 1e-2).apply(&mut p, &[g], &mut m, &mut v);
            mq = a.beta1 * mq + (1.0 - a.beta1) * g;
            vq = a.beta2 * vq + (1.0 - a.beta2) * g * g;
            let (mh, vh) = (mq / (1.0 - a.beta1.powi(t as i32)), vq / (1.0 - a.beta2.powi(t as i32)));
            q -= 1e-2 * mh / (vh.sqrt() + a.eps);
        }
        assert!((p[0] - q).abs() < 1e-12, "{} vs {q}", p[0]);
    }

    #[test]
    fn validate_names_the_bad_constant() {
        let bad = AdamParams { beta2: 1.0, ..Default::default() };
        assert!(bad.validate().unwrap_err().contains("beta2"));
        assert!(AdamParams::default().validate().is_ok());
    }
}
