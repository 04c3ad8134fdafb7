//! Tick placement for linear and logarithmic axes.
//!
//! All functions work in data space, never panic and always return a bounded number of
//! ticks, whatever the input (NaN, infinities, reversed or empty ranges).

/// Tick positions of one axis, in data space, ascending.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Ticks {
    /// Labelled ticks, each with a grid line.
    pub major: Vec<f64>,
    /// Unlabelled ticks, drawn as faint grid lines only (e.g. 2·10^k … 9·10^k on a log axis).
    pub minor: Vec<f64>,
}

/// How a tick is labelled.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Label {
    /// Ordinary text such as `0.05` or `2e-7`.
    Plain(String),
    /// `10^k`, drawn as 10 with a superscript exponent.
    Pow10(i32),
}

impl Label {
    /// A single-line ASCII form, `1e-3` style for powers of ten.
    #[cfg(test)]
    pub(crate) fn text(&self) -> String {
        match self {
            Label::Plain(s) => s.clone(),
            Label::Pow10(k) => format!("1e{k}"),
        }
    }
}

/// At most this many labelled decades on a log axis; wider ranges label every 2nd, 3rd, … decade.
const MAX_DECADES: i64 = 8;
/// A relative slack so that a range ending exactly on a tick (up to rounding) keeps that tick.
const SLACK: f64 = 1e-9;

/// `m·10^k` as the f64 nearest to the exact decimal (better than `m * 10f64.powi(k)`).
fn decimal(m: i64, k: i32) -> f64 {
    format!("{m}e{k}").parse().unwrap_or(f64::NAN)
}

/// Ticks for a logarithmic axis spanning `lo..=hi` (data space, both must be positive and
/// finite; otherwise no ticks).
///
/// When the range holds at least two powers of ten, the major ticks are decades (every
/// decade, or every n-th when more than 8 fit) and the minor ticks are the 2..9 multiples
/// (or the skipped decades). Narrower ranges fall back to 1-2-5 ticks and, below that, to
/// linear "nice" ticks.
///
/// ```
/// assert_eq!(plot::log_ticks(30.0, 3e5).major, vec![1e2, 1e3, 1e4, 1e5]);
/// ```
pub fn log_ticks(lo: f64, hi: f64) -> Ticks {
    let (major, minor) = log_ticks_labelled(lo, hi);
    Ticks { major: major.into_iter().map(|(v, _)| v).collect(), minor }
}

/// Ticks for a linear axis spanning `lo..=hi`: about 4 to 10 values on a 1-2-5 step.
/// Non-finite bounds give no ticks; an empty range gives the one value.
///
/// ```
/// assert_eq!(plot::linear_ticks(0.0, 1.0).major, vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
/// ```
pub fn linear_ticks(lo: f64, hi: f64) -> Ticks {
    Ticks { major: linear_ticks_labelled(lo, hi).into_iter().map(|(v, _)| v).collect(), minor: Vec::new() }
}

/// Ticks with labels for either axis kind.
pub(crate) fn axis_ticks(lo: f64, hi: f64, log: bool) -> (Vec<(f64, Label)>, Vec<f64>) {
    if log {
        log_ticks_labelled(lo, hi)
    } else {
        (linear_ticks_labelled(lo, hi), Vec::new())
    }
}

fn log_ticks_labelled(lo: f64, hi: f64) -> (Vec<(f64, Label)>, Vec<f64>) {
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && hi > 0.0) {
        return (Vec::new(), Vec::new());
    }
    log_ticks_exp(lo.log10(), hi.log10())
}

/// Log ticks for the range `10^a ..= 10^b` (exponents may lie outside f64's range; ticks
/// are only placed where `m·10^k` is a positive finite f64).
pub(crate) fn log_ticks_exp(a: f64, b: f64) -> (Vec<(f64, Label)>, Vec<f64>) {
    if !(a.is_finite() && b.is_finite()) {
        return (Vec::new(), Vec::new());
    }
    let (a, b) = if a <= b { (a, b) } else { (b, a) };
    // Only exponents where f64 has positive finite values.
    let (a, b) = (a.max(-324.0), b.min(309.0));
    if a > b {
        return (Vec::new(), Vec::new());
    }
    let inside = |v: f64| v > 0.0 && v.is_finite() && (a - SLACK..=b + SLACK).contains(&v.log10());
    let (lo, hi) = (10f64.powf(a), 10f64.powf(b));
    let k0 = (a - SLACK).ceil() as i64;
    let k1 = (b + SLACK).floor() as i64;
    let decades: Vec<i64> = (k0..=k1).filter(|&k| inside(decimal(1, k as i32))).collect();

    if decades.len() >= 2 {
        let n = decades.len() as i64;
        let step = (n + MAX_DECADES - 1) / MAX_DECADES;
        let mut major = Vec::new();
        let mut minor = Vec::new();
        for &k in &decades {
            if k.rem_euclid(step) == 0 {
                major.push((decimal(1, k as i32), Label::Pow10(k as i32)));
            } else {
                minor.push(decimal(1, k as i32));
            }
        }
        if step == 1 && n <= 7 {
            for k in (k0 - 1)..=k1 {
                for m in 2..=9 {
                    let v = decimal(m, k as i32);
                    if inside(v) {
                        minor.push(v);
                    }
                }
            }
        }
        minor.sort_by(f64::total_cmp);
        return (major, minor);
    }

    // Fewer than two decades: 1-2-5 multiples.
    let kf = a.floor() as i64;
    let kc = b.ceil() as i64;
    let mut major = Vec::new();
    let mut minor = Vec::new();
    for k in (kf - 1)..=kc {
        for m in 1..=9 {
            let v = decimal(m, k as i32);
            if !inside(v) {
                continue;
            }
            if matches!(m, 1 | 2 | 5) {
                let label = if m == 1 { Label::Pow10(k as i32) } else { Label::Plain(plain_mantissa(m, k as i32)) };
                major.push((v, label));
            } else {
                minor.push(v);
            }
        }
    }
    if major.len() >= 2 {
        // With 1-2-5 labels, write the decades as plain numbers too, so the labels read alike.
        for (_, label) in &mut major {
            if let Label::Pow10(k) = *label {
                *label = Label::Plain(plain_mantissa(1, k));
            }
        }
        return (major, minor);
    }
    let mut linear = linear_ticks_labelled(lo, hi);
    linear.retain(|&(v, _)| inside(v));
    (linear, Vec::new())
}

/// `m·10^k` written plainly (`0.002`, `50000`) for moderate exponents, else `2e-7`.
fn plain_mantissa(m: i64, k: i32) -> String {
    if (-4..=5).contains(&k) {
        let decimals = (-k).max(0) as usize;
        format!("{:.*}", decimals, decimal(m, k))
    } else {
        format!("{m}e{k}")
    }
}

fn linear_ticks_labelled(lo: f64, hi: f64) -> Vec<(f64, Label)> {
    if !(lo.is_finite() && hi.is_finite()) {
        return Vec::new();
    }
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let span = hi - lo;
    if span == 0.0 || !span.is_finite() {
        return vec![(lo, Label::Plain(format_plain(lo, lo.abs())))];
    }
    let raw = span / 6.0;
    let e = raw.log10().floor();
    let mag = 10f64.powf(e);
    let r = raw / mag;
    let (nice, e) = if r < 1.5 {
        (1, e)
    } else if r < 3.0 {
        (2, e)
    } else if r < 7.0 {
        (5, e)
    } else {
        (1, e + 1.0)
    };
    let e = e as i32;
    let step = decimal(nice, e);
    if !(step > 0.0 && step.is_finite()) {
        return Vec::new();
    }
    let start = (lo / step - SLACK).ceil();
    let end = (hi / step + SLACK).floor();
    if !(start.is_finite() && end.is_finite()) || end - start > 100.0 {
        return Vec::new();
    }
    let (start, end) = (start as i64, end as i64);
    let sci = lo.abs().max(hi.abs()) >= 1e6 || step < 1e-4;
    let decimals = (-e).max(0) as usize;
    (start..=end)
        .filter_map(|i| {
            let v = decimal(i.checked_mul(nice)?, e);
            let v = if v == 0.0 { 0.0 } else { v };
            let label = if sci { Label::Plain(format!("{v:e}")) } else { Label::Plain(format!("{:.*}", decimals, v)) };
            Some((v, label))
        })
        .collect()
}

fn format_plain(v: f64, scale: f64) -> String {
    if v == 0.0 {
        "0".to_string()
    } else if !(1e-4..1e6).contains(&scale) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(lo: f64, hi: f64, log: bool) -> Vec<String> {
        axis_ticks(lo, hi, log).0.iter().map(|(_, l)| l.text()).collect()
    }

    #[test]
    fn decade_labels() {
        assert_eq!(labels(30.0, 3e5, true), ["1e2", "1e3", "1e4", "1e5"]);
        assert_eq!(labels(0.001, 0.1, true), ["1e-3", "1e-2", "1e-1"]);
    }

    #[test]
    fn one_two_five_labels() {
        assert_eq!(labels(0.015, 0.12, true), ["0.02", "0.05", "0.1"]);
        assert_eq!(labels(1.5e-8, 1.2e-7, true), ["2e-8", "5e-8", "1e-7"]);
    }

    #[test]
    fn linear_labels() {
        assert_eq!(labels(0.0, 1.0, false), ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        assert_eq!(labels(-3.0, 7.0, false), ["-2", "0", "2", "4", "6"]);
        assert_eq!(labels(0.0, 3e6, false), ["0e0", "5e5", "1e6", "1.5e6", "2e6", "2.5e6", "3e6"]);
    }
}
