//! The study's convergence criterion: when a training loss has stopped improving.
//!
//! The loss is averaged over consecutive windows of steps. A window *improves* when its
//! mean is below the best earlier window's mean by at least `min_improvement` (relative).
//! After `patience` windows in a row without improvement the loss has *plateaued*: the
//! caller lowers the learning rate (×`factor`) and goes on, and the run ends at the
//! plateau that follows the last allowed reduction (or at `max_steps`, which the results
//! then say). This is PyTorch's `ReduceLROnPlateau` (mode `min`, relative threshold) on
//! window means, with the stop rule added.

use serde::Serialize;

/// Settings of the plateau rule.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct PlateauRule {
    /// Steps per window.
    pub window: usize,
    /// Relative improvement a window needs over the best earlier one (e.g. 0.01).
    pub min_improvement: f64,
    /// Windows without improvement that make a plateau.
    pub patience: usize,
    /// Learning-rate factor applied at each plateau but the last.
    pub factor: f64,
    /// Reductions before the run may stop at a plateau.
    pub reductions: usize,
    /// Never stop before this many steps.
    pub min_steps: usize,
    /// Stop here whatever the loss does (the results flag the run as capped).
    pub max_steps: usize,
}

/// What [`Plateau::push`] tells the caller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Keep going at the current learning rate.
    Continue,
    /// The loss plateaued: multiply the learning rate by this factor (cumulative, from the
    /// start) and keep going.
    Reduce(f64),
    /// Converged (plateau after the last reduction): stop.
    Converged,
    /// `max_steps` reached before convergence: stop.
    Capped,
}

/// The rule's state over one run.
#[derive(Clone, Debug)]
pub struct Plateau {
    rule: PlateauRule,
    sum: f64,
    count: usize,
    steps: usize,
    best: f64,
    stale: usize,
    reductions: usize,
}

impl Plateau {
    /// A fresh run.
    pub fn new(rule: PlateauRule) -> Self {
        Plateau { rule, sum: 0.0, count: 0, steps: 0, best: f64::INFINITY, stale: 0, reductions: 0 }
    }

    /// Records one step's loss (non-finite losses count as no improvement).
    pub fn push(&mut self, loss: f64) -> Verdict {
        self.steps += 1;
        self.sum += loss;
        self.count += 1;
        let mut verdict = Verdict::Continue;
        if self.count == self.rule.window.max(1) {
            let mean = self.sum / self.count as f64;
            self.sum = 0.0;
            self.count = 0;
            if mean.is_finite() && mean < self.best * (1.0 - self.rule.min_improvement) {
                self.best = mean;
                self.stale = 0;
            } else {
                if mean.is_finite() {
                    self.best = self.best.min(mean);
                }
                self.stale += 1;
            }
            if self.stale >= self.rule.patience.max(1) {
                self.stale = 0;
                if self.reductions < self.rule.reductions {
                    self.reductions += 1;
                    verdict = Verdict::Reduce(self.rule.factor.powi(self.reductions as i32));
                } else if self.steps >= self.rule.min_steps {
                    return Verdict::Converged;
                }
            }
        }
        if self.steps >= self.rule.max_steps {
            return Verdict::Capped;
        }
        verdict
    }

    /// Learning-rate reductions so far.
    pub fn reductions(&self) -> usize {
        self.reductions
    }
}

/// Whether a finished run's loss curve had flattened: the mean over its last `window`
/// steps is not below the mean over the `window` steps before by more than
/// `min_improvement` (relative) or by more than two standard errors of the difference of
/// the two means, whichever is larger (the check for runs on a fixed schedule, the Voronoi
/// fits). The noise allowance matters where each step's loss is measured on a fresh random
/// batch: at K = 8,192 on the study's sphere the per-step loss scatters by about ±5%, so
/// two windows of 60 steps whose sites no longer move (Adam's largest step 2e-6, a
/// ten-thousandth of the site spacing) still differ by a percent by chance.
pub fn flattened(losses: &[f64], window: usize, min_improvement: f64) -> bool {
    if window == 0 || losses.len() < 2 * window {
        return false;
    }
    let n = losses.len();
    let stats = |s: &[f64]| {
        let m = s.iter().sum::<f64>() / s.len() as f64;
        let var =
            if s.len() > 1 { s.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (s.len() - 1) as f64 } else { 0.0 };
        (m, var / s.len() as f64)
    };
    let ((before, var_before), (last, var_last)) =
        (stats(&losses[n - 2 * window..n - window]), stats(&losses[n - window..]));
    let allowance = (min_improvement * before.abs()).max(2.0 * (var_before + var_last).sqrt());
    before - last <= allowance
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule() -> PlateauRule {
        PlateauRule {
            window: 10,
            min_improvement: 0.01,
            patience: 2,
            factor: 0.1,
            reductions: 2,
            min_steps: 0,
            max_steps: 10_000,
        }
    }

    #[test]
    fn a_falling_loss_never_plateaus_and_is_capped() {
        let mut p = Plateau::new(PlateauRule { max_steps: 500, ..rule() });
        let mut last = Verdict::Continue;
        for i in 0..500 {
            last = p.push(1.0 / (1.0 + i as f64));
            if i < 499 {
                assert_eq!(last, Verdict::Continue, "step {i}");
            }
        }
        assert_eq!(last, Verdict::Capped);
    }

    #[test]
    fn a_flat_loss_reduces_twice_then_converges() {
        let mut p = Plateau::new(rule());
        let mut verdicts = Vec::new();
        for _ in 0..1000 {
            match p.push(1.0) {
                Verdict::Continue => {}
                v => {
                    verdicts.push(v);
                    if matches!(v, Verdict::Converged | Verdict::Capped) {
                        break;
                    }
                }
            }
        }
        // First window sets the best; then 2 stale windows per plateau.
        assert_eq!(verdicts.len(), 3);
        assert!(matches!(verdicts[0], Verdict::Reduce(f) if (f - 0.1).abs() < 1e-12));
        assert!(matches!(verdicts[1], Verdict::Reduce(f) if (f - 0.01).abs() < 1e-12));
        assert_eq!(verdicts[2], Verdict::Converged);
        assert_eq!(p.reductions(), 2);
    }

    #[test]
    fn min_steps_holds_the_stop() {
        let mut p = Plateau::new(PlateauRule { min_steps: 400, ..rule() });
        let mut stop = None;
        for i in 0..1000 {
            if p.push(1.0) == Verdict::Converged {
                stop = Some(i + 1);
                break;
            }
        }
        let stop = stop.unwrap();
        assert!(stop >= 400 && stop % 10 == 0, "{stop}");
    }

    #[test]
    fn flattened_compares_the_last_two_windows() {
        let falling: Vec<f64> = (0..100).map(|i| 100.0 - i as f64).collect();
        assert!(!flattened(&falling, 10, 0.01));
        let flat = vec![2.0; 100];
        assert!(flattened(&flat, 10, 0.01));
        assert!(!flattened(&flat, 60, 0.01), "too short for two windows");
        // Noise around a level loss: flattened; the same noise on a clear fall: not.
        let noisy: Vec<f64> =
            (0..200).map(|i| 1.0 + 0.05 * if i % 2 == 0 { 1.0 } else { -1.0 } * ((i * 7 % 11) as f64 / 11.0)).collect();
        assert!(flattened(&noisy, 50, 0.001));
        let falling_noisy: Vec<f64> = noisy.iter().enumerate().map(|(i, x)| x - 0.002 * i as f64).collect();
        assert!(!flattened(&falling_noisy, 50, 0.001));
    }
}
