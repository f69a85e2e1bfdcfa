//! Oscillation detection in routine loop data.
//!
//! - Regularity (Thornhill, Huang and Zhang 2003): the zero crossings of the autocorrelation
//!   function of the (mean-free) control error give the oscillation period; with Tp the periods
//!   from successive pairs of crossings, `r = mean(Tp) / (3 std(Tp))`, and `r > 1` means a regular
//!   oscillation.
//! - IAE count (Hägglund 1995): the integrated absolute error between successive zero crossings of
//!   the control error; a half period whose IAE exceeds `2 a / ω` (that of a sine of amplitude `a`)
//!   is a load disturbance; `n_lim` of them within a supervision window mean an oscillation.

use serde::{Deserialize, Serialize};

/// What one index (or one family of evidence) says.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Vote {
    /// Evidence for stiction.
    Stiction,
    /// Evidence against stiction (an oscillation with another cause, or none).
    NoStiction,
    /// Neither way: too little to go on, or a value between the thresholds.
    Undetermined,
}

impl Vote {
    /// +1 for stiction, -1 against, 0 undetermined.
    pub fn sign(self) -> f64 {
        match self {
            Vote::Stiction => 1.0,
            Vote::NoStiction => -1.0,
            Vote::Undetermined => 0.0,
        }
    }
}

/// Thornhill's regularity of an oscillation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Regularity {
    /// Mean period, seconds (`None` with fewer than 3 zero crossings of the autocorrelation).
    pub period: Option<f64>,
    /// r = mean(Tp) / (3 std(Tp)); `REGULARITY_CAP` for perfectly regular periods.
    pub regularity: f64,
    /// The threshold: r above it means a regular oscillation.
    pub threshold: f64,
    /// Zero crossings of the autocorrelation used (at most `MAX_CROSSINGS`).
    pub zero_crossings: usize,
    /// Whether the oscillation is regular: at least two periods and r above the threshold.
    pub oscillating: bool,
}

impl Regularity {
    /// The regularity as an engineer reads it: its value, or what stands in for one that does not
    /// measure a spread (an autocorrelation that shows a single period, or periods alike to the last
    /// digit).
    pub fn shown(&self) -> String {
        if self.period.is_some() && self.zero_crossings < SPREAD_CROSSINGS {
            "not measured: the autocorrelation shows under two periods".into()
        } else if self.regularity >= REGULARITY_CAP {
            "perfectly regular".into()
        } else {
            format!("{:.2}", self.regularity)
        }
    }
}

/// Default threshold on Thornhill's r.
pub(super) const REGULARITY_THRESHOLD: f64 = 1.0;

/// The largest regularity reported (perfectly regular periods).
pub(super) const REGULARITY_CAP: f64 = 1e6;

/// Zero crossings of the autocorrelation used for the periods (about five periods).
const MAX_CROSSINGS: usize = 11;

/// The shortest period a sampled cycle can have, samples (the Nyquist limit).
const MIN_PERIOD_SAMPLES: f64 = 2.0;

/// Zero crossings of the autocorrelation that span two periods: a regularity from fewer
/// measures no spread of the periods.
pub(super) const SPREAD_CROSSINGS: usize = 5;

/// The standard deviation of white measurement noise on `x`, robustly: the smaller of the
/// estimates from first differences (MAD / 0.6745 / √2) and from second differences
/// (MAD / 0.6745 / √6). Differences take slow variations off; first differences overstate the
/// noise of a signal that moves a lot between samples (a ramp, a slow oscillation sampled fast),
/// second differences that of a signal that moves fast between samples. White noise gives the
/// same from both.
pub fn measurement_noise(x: &[f64]) -> f64 {
    let mad = |mut d: Vec<f64>| -> Option<f64> {
        if d.is_empty() {
            return None;
        }
        // the median's element, as a full sort would place it (selection: linear time)
        let mid = d.len() / 2;
        let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
        Some(*median / 0.6745)
    };
    let d1 = mad(x.windows(2).map(|w| (w[1] - w[0]).abs()).collect());
    let d2 = mad(x
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .collect());
    match (d1, d2) {
        (Some(a), Some(b)) => (a / 2f64.sqrt()).min(b / 6f64.sqrt()),
        (Some(a), None) => a / 2f64.sqrt(),
        _ => 0.0,
    }
}

/// A held signal repeats its value in at least this share of its samples (a controller slower
/// than the record, or a historian that stores a value only when it changes).
const HELD_SHARE: f64 = 0.3;

/// The noise of a signal that may be held between updates (OP recorded faster than the
/// controller runs): [`measurement_noise`], except that where at least `HELD_SHARE` of the
/// first differences are exactly zero it is taken from the changes between the held values alone
/// (a held signal's median change is zero, which would call it noise-free).
pub fn held_noise(x: &[f64]) -> f64 {
    let steps = x.len().saturating_sub(1);
    let held = x.windows(2).filter(|w| w[1] == w[0]).count();
    if steps == 0 || (held as f64) < HELD_SHARE * steps as f64 {
        return measurement_noise(x);
    }
    let mut changes: Vec<f64> = x
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0 && d.is_finite())
        .collect();
    if changes.is_empty() {
        return 0.0;
    }
    let mid = changes.len() / 2;
    let (_, median, _) = changes.select_nth_unstable_by(mid, f64::total_cmp);
    *median / 0.6745 / 2f64.sqrt()
}

/// Autocorrelation of a mean-free copy of `x` for lags `0..=max_lag` (biased estimator, so r(0) = 1;
/// all zeros for a constant). Computed by FFT.
pub fn autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    if x.is_empty() {
        return vec![0.0];
    }
    crate::spectral::autocorrelation(x, max_lag)
}

/// Regularity of the oscillation in `error` sampled every `ts` seconds.
pub fn regularity(error: &[f64], ts: f64) -> Regularity {
    regularity_of(&autocorrelation(error, error.len() / 2), ts)
}

/// [`regularity`] from the error's autocorrelation for lags up to half its length.
pub(crate) fn regularity_of(acf: &[f64], ts: f64) -> Regularity {
    let crossings = (1..acf.len())
        .filter_map(|k| zero_crossing(acf, k))
        .collect();
    regularity_from(crossings, ts)
}

/// The zero crossing of the autocorrelation between lags `k - 1` and `k`, interpolated, if any.
fn zero_crossing(acf: &[f64], k: usize) -> Option<f64> {
    let (a, b) = (acf[k - 1], acf[k]);
    ((a > 0.0 && b <= 0.0) || (a < 0.0 && b >= 0.0)).then(|| {
        let frac = if a != b { a / (a - b) } else { 0.0 };
        (k - 1) as f64 + frac
    })
}

/// [`regularity_of`] with the zero crossings read through a band of `band` either side of zero:
/// a crossing counts once the autocorrelation has gone past the band on the other side, at the
/// mean of the zero crossings it made on its way there. A cycle whose period wanders leaves its
/// autocorrelation flat near zero at some lags, where the estimate's own scatter crosses zero two
/// or three times in a row and breaks the periods up (fast-x1-0062 of the catalogue, a sticky He
/// valve's cycle in noise on a hold of the setpoint: regularity 0.77 read plainly, 2.87 through a
/// band of one standard error, 1/√n).
pub(crate) fn regularity_banded(acf: &[f64], ts: f64, band: f64) -> Regularity {
    let mut crossings = Vec::new();
    let mut pending: Vec<f64> = Vec::new();
    let mut above = true;
    for k in 1..acf.len() {
        pending.extend(zero_crossing(acf, k));
        let b = acf[k];
        if (above && b < -band) || (!above && b > band) {
            if !pending.is_empty() {
                crossings.push(pending.iter().sum::<f64>() / pending.len() as f64);
            }
            pending.clear();
            above = !above;
        }
    }
    regularity_from(crossings, ts)
}

/// Thornhill's regularity from the autocorrelation's zero crossings (lags, in samples).
fn regularity_from(mut crossings: Vec<f64>, ts: f64) -> Regularity {
    // Thornhill et al. use the first crossings only: deep into the lags the autocorrelation of
    // a noisy record wanders around zero and adds crossings that are not the oscillation's
    crossings.truncate(MAX_CROSSINGS);
    // each pair of crossings two apart spans one period
    let periods: Vec<f64> = crossings.windows(3).map(|w| (w[2] - w[0]) * ts).collect();
    let m = periods.iter().sum::<f64>() / periods.len().max(1) as f64;
    // a sampled cycle spans at least two samples (a faster one aliases to a slower one): a
    // "period" under two samples is the autocorrelation of noise changing sign from one lag to
    // the next (a held OP, PV's differences), no oscillation (on the catalogue's routine windows
    // of 1 s such records reported cycles of 1.2 to 1.9 s, "perfectly regular")
    let (period, r) = if periods.is_empty() || m < MIN_PERIOD_SAMPLES * ts {
        (None, 0.0)
    } else {
        let sd =
            (periods.iter().map(|p| (p - m) * (p - m)).sum::<f64>() / periods.len() as f64).sqrt();
        // capped: perfectly regular periods would give infinity, which JSON cannot carry
        let r = if sd > 0.0 {
            (m / (3.0 * sd)).min(REGULARITY_CAP)
        } else {
            REGULARITY_CAP
        };
        (Some(m), r)
    };
    Regularity {
        period,
        regularity: r,
        threshold: REGULARITY_THRESHOLD,
        zero_crossings: crossings.len(),
        oscillating: periods.len() >= 2 && r > REGULARITY_THRESHOLD,
    }
}

/// Hägglund's load-disturbance count.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IaeCount {
    /// Half periods whose IAE exceeded the limit, over the whole record.
    pub exceedances: usize,
    /// The largest number within any supervision window.
    pub most_in_window: usize,
    /// The IAE limit 2 a / ω used, in error units x seconds.
    pub iae_limit: f64,
    /// Exceedances within one supervision window that mean an oscillation.
    pub n_lim: usize,
    /// The supervision window, seconds.
    pub window: f64,
    /// Whether `most_in_window` reached `n_lim`.
    pub oscillating: bool,
}

/// Settings of the IAE count: acceptable amplitude `a`, the frequency scale `omega` (rad/s: the
/// ultimate frequency, or 2π over the period when it is unknown), `n_lim` exceedances within a
/// supervision window of `window` seconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct IaeSettings {
    /// Acceptable amplitude `a` of the control error, in error units.
    pub amplitude: f64,
    /// Frequency scale ω, rad/s.
    pub omega: f64,
    /// Exceedances within one window that mean an oscillation.
    pub n_lim: usize,
    /// The supervision window, seconds.
    pub window: f64,
}

/// Hägglund's count on the control `error` sampled every `ts` seconds: the IAE of each half period
/// (between crossings of the error's mean) against 2 a / ω, and the most exceedances within any
/// window.
pub fn iae_count(error: &[f64], ts: f64, s: &IaeSettings) -> IaeCount {
    let limit = 2.0 * s.amplitude / s.omega;
    let mean = error.iter().sum::<f64>() / error.len().max(1) as f64;
    let mut ends = Vec::new(); // time of each exceeding half period's end
    let mut iae = 0.0;
    let mut sign = 0.0f64;
    for (k, &e) in error.iter().enumerate() {
        let v = e - mean;
        let sv = v.signum();
        if sign != 0.0 && sv != sign && v != 0.0 {
            if iae > limit {
                ends.push(k as f64 * ts);
            }
            iae = 0.0;
        }
        if v != 0.0 {
            sign = sv;
        }
        iae += v.abs() * ts;
    }
    let mut most = 0;
    let mut first = 0;
    for (i, &t) in ends.iter().enumerate() {
        while t - ends[first] > s.window {
            first += 1;
        }
        most = most.max(i + 1 - first);
    }
    IaeCount {
        exceedances: ends.len(),
        most_in_window: most,
        iae_limit: limit,
        n_lim: s.n_lim,
        window: s.window,
        oscillating: most >= s.n_lim,
    }
}

/// Horch's cross-correlation test (self-regulating loops).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossCorrelation {
    /// First zero crossing of the OP-PV cross-correlation on the negative lag side, seconds.
    pub tau_left: Option<f64>,
    /// The same on the positive lag side (pv after op), seconds.
    pub tau_right: Option<f64>,
    /// |τr + τl| / (τr - τl): 0 for an even function (extremum at lag 0), 1 for an odd one (zero
    /// at lag 0).
    pub oddness: Option<f64>,
    /// Oddness above this votes stiction (odd: the sticky valve's signature).
    pub stiction_above: f64,
    /// Oddness below this votes no stiction (even).
    pub no_stiction_below: f64,
    /// Stiction when oddness is above `stiction_above`, no stiction below `no_stiction_below`,
    /// undetermined between or without both crossings.
    pub vote: Vote,
}

/// Cross-correlation of `op` with `pv` at lags `-max_lag..=max_lag` (index `max_lag` is lag 0;
/// positive lags: pv after op). Computed by FFT.
pub fn cross_correlation(op: &[f64], pv: &[f64], max_lag: usize) -> Vec<f64> {
    let n = op.len().min(pv.len());
    let lag = max_lag.min(n.saturating_sub(1));
    crate::spectral::cross_correlation(&op[..n], &pv[..n], lag)
}

/// Horch's test: the OP-PV cross-correlation is odd for a sticky valve in a self-regulating loop
/// and even otherwise. `max_lag` in samples should cover at least half an oscillation period.
pub fn horch(op: &[f64], pv: &[f64], ts: f64, max_lag: usize) -> CrossCorrelation {
    let ccf = cross_correlation(op, pv, max_lag);
    let mid = (ccf.len() - 1) / 2;
    let crossing = |range: Box<dyn Iterator<Item = usize>>, step: isize| {
        for i in range {
            let j = (i as isize + step) as usize;
            let (a, b) = (ccf[i], ccf[j]);
            if a == 0.0 {
                return Some(i as f64);
            }
            if (a > 0.0) != (b > 0.0) {
                return Some(i as f64 + step as f64 * a / (a - b));
            }
        }
        None
    };
    let right = crossing(Box::new(mid..ccf.len() - 1), 1).map(|i| (i - mid as f64) * ts);
    let left = crossing(Box::new((1..=mid).rev()), -1).map(|i| (i - mid as f64) * ts);
    let oddness = match (left, right) {
        (Some(l), Some(r)) if r - l > 0.0 => Some(((r + l) / (r - l)).abs()),
        _ => None,
    };
    let (hi, lo) = (2.0 / 3.0, 1.0 / 3.0);
    let vote = match oddness {
        Some(o) if o > hi => Vote::Stiction,
        Some(o) if o < lo => Vote::NoStiction,
        _ => Vote::Undetermined,
    };
    CrossCorrelation {
        tau_left: left,
        tau_right: right,
        oddness,
        stiction_above: hi,
        no_stiction_below: lo,
        vote,
    }
}

/// Half cycles of a signal: the stretches between its crossings of the mean, found with a
/// hysteresis band (a crossing counts once the signal is `hysteresis` past the mean on the other
/// side) so measurement noise does not chop them. Each as `[start, end)`.
pub fn half_cycles(x: &[f64], hysteresis: f64) -> Vec<(usize, usize)> {
    let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
    let mut out = Vec::new();
    let mut side = 0.0f64;
    let mut start: Option<usize> = None;
    for (k, &v) in x.iter().enumerate() {
        let d = v - mean;
        let now = if d > hysteresis {
            1.0
        } else if d < -hysteresis {
            -1.0
        } else {
            continue;
        };
        if now != side {
            // walk back to where the signal actually crossed the mean
            let mut c = k;
            while c > 0 && (x[c - 1] - mean) * now > 0.0 {
                c -= 1;
            }
            if let Some(s) = start {
                out.push((s, c));
            }
            if side != 0.0 || start.is_none() {
                start = Some(c);
            }
            side = now;
        }
    }
    // the first stretch starts wherever the record does, not at a crossing: drop it
    if !out.is_empty() {
        out.remove(0);
    }
    out
}

/// A shape index with its vote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShapeIndex {
    /// The index's value (NaN when no half cycle could be fitted).
    pub value: f64,
    /// Half cycles fitted (those of at least 4 samples).
    pub half_cycles: usize,
    /// The stiction threshold: the curve-fitting index votes stiction at or above it, the shape
    /// index above it.
    pub stiction_above: f64,
    /// A value at or below this votes no stiction.
    pub no_stiction_below: f64,
    /// Undetermined also when there are too few half cycles.
    pub vote: Vote,
}

fn vote(value: f64, half_cycles: usize, hi: f64, lo: f64) -> Vote {
    if half_cycles < 4 || !value.is_finite() {
        Vote::Undetermined
    } else if value >= hi {
        Vote::Stiction
    } else if value <= lo {
        Vote::NoStiction
    } else {
        Vote::Undetermined
    }
}

/// Residual sum of squares of the least-squares fit `x ≈ a φ`.
fn fit_rss(x: &[f64], phi: impl Fn(usize) -> f64) -> f64 {
    let (mut xp, mut pp, mut xx) = (0.0, 0.0, 0.0);
    for (k, &v) in x.iter().enumerate() {
        let p = phi(k);
        xp += v * p;
        pp += p * p;
        xx += v * v;
    }
    if pp > 0.0 {
        (xx - xp * xp / pp).max(0.0)
    } else {
        xx
    }
}

fn sine_rss(x: &[f64]) -> f64 {
    let m = x.len() as f64;
    fit_rss(x, |k| (std::f64::consts::PI * (k as f64 + 0.5) / m).sin())
}

/// The best triangle over every peak position.
fn triangle_rss(x: &[f64]) -> f64 {
    let m = x.len();
    (1..m)
        .map(|p| {
            fit_rss(x, |k| {
                let t = k as f64 + 0.5;
                if k < p {
                    t / p as f64
                } else {
                    (m as f64 - t) / (m - p) as f64
                }
            })
        })
        .fold(f64::INFINITY, f64::min)
}

fn half_cycle_fits(x: &[f64], hysteresis: f64, rss: [fn(&[f64]) -> f64; 2]) -> (f64, f64, usize) {
    let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
    let cycles = half_cycles(x, hysteresis);
    let (mut a, mut b) = (0.0, 0.0);
    let mut used = 0;
    for &(s, e) in &cycles {
        if e - s < 4 {
            continue;
        }
        let seg: Vec<f64> = x[s..e].iter().map(|v| v - mean).collect();
        a += rss[0](&seg);
        b += rss[1](&seg);
        used += 1;
    }
    (a, b, used)
}

/// He et al. (2007) curve-fitting index on a signal (OP for self-regulating loops, PV for
/// integrating ones): a sine and a triangle fitted to each half cycle;
/// SI = MSE_sine / (MSE_sine + MSE_triangle), stiction at 0.6 and above, none at 0.4 and below.
pub fn curve_fitting_index(x: &[f64], hysteresis: f64) -> ShapeIndex {
    let (sine, tri, used) = half_cycle_fits(x, hysteresis, [sine_rss, triangle_rss]);
    let value = if sine + tri > 0.0 {
        sine / (sine + tri)
    } else {
        f64::NAN
    };
    ShapeIndex {
        value,
        half_cycles: used,
        stiction_above: 0.6,
        no_stiction_below: 0.4,
        vote: vote(value, used, 0.6, 0.4),
    }
}

/// Hägglund (2011) shape index on the control error: a sine and a square wave fitted to each half
/// period; (V_sine - V_square) / (V_sine + V_square) > 0 means square-like, i.e. stiction.
pub fn shape_index(error: &[f64], hysteresis: f64) -> ShapeIndex {
    fn square_rss(x: &[f64]) -> f64 {
        fit_rss(x, |_| 1.0)
    }
    let (sine, square, used) = half_cycle_fits(error, hysteresis, [sine_rss, square_rss]);
    let value = if sine + square > 0.0 {
        (sine - square) / (sine + square)
    } else {
        f64::NAN
    };
    ShapeIndex {
        value,
        half_cycles: used,
        stiction_above: 0.0,
        no_stiction_below: 0.0,
        vote: vote(value, used, f64::MIN_POSITIVE, 0.0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::{gaussian, seeded};

    fn sine(n: usize, period: f64, ts: f64, noise: f64) -> Vec<f64> {
        let mut rng = seeded(3);
        (0..n)
            .map(|k| {
                (std::f64::consts::TAU * k as f64 * ts / period).sin() + noise * gaussian(&mut rng)
            })
            .collect()
    }

    #[test]
    fn a_signal_held_between_updates_has_the_noise_of_its_changes() {
        // OP of a controller that runs every other sample: white noise on a slow ramp, each
        // value recorded twice
        let mut rng = seeded(11);
        let updates: Vec<f64> = (0..1500)
            .map(|k| 40.0 + 0.001 * k as f64 + 0.1 * gaussian(&mut rng))
            .collect();
        let held: Vec<f64> = updates.iter().flat_map(|&v| [v, v]).collect();
        // half the changes are zero: the robust estimate calls the signal noise-free
        assert_eq!(measurement_noise(&held), 0.0);
        // from the changes between the held values: the updates' own noise
        let sd = held_noise(&held);
        assert!((sd - 0.1).abs() < 0.01, "held noise {sd}");
        // a signal that is not held keeps the usual estimate
        assert_eq!(held_noise(&updates), measurement_noise(&updates));
        assert_eq!(held_noise(&[1.0; 10]), 0.0);
    }

    #[test]
    fn a_noisy_sine_is_a_regular_oscillation_with_its_period() {
        let r = regularity(&sine(2000, 50.0, 1.0, 0.3), 1.0);
        assert!(r.oscillating, "{r:?}");
        assert!((r.period.unwrap() - 50.0).abs() < 2.0, "{r:?}");
    }

    /// Law (Nyquist): no sampled cycle is shorter than two samples, so an autocorrelation that
    /// changes sign from lag to lag is no oscillation, however evenly it does.
    #[test]
    fn an_autocorrelation_that_flips_sign_every_lag_is_no_cycle() {
        // a sign change in every lag interval, each 0.1 of a lag earlier than the one before
        // (crossings at 0.9, 1.8, 2.7, 3.6, 4.5): "periods" of 1.8 samples, all alike
        let mut acf = vec![1.0];
        for f in [0.9, 0.8, 0.7, 0.6, 0.5] {
            let a: f64 = *acf.last().unwrap();
            acf.push(a * (f - 1.0) / f);
        }
        let tail = acf[acf.len() - 1];
        acf.extend(std::iter::repeat_n(tail, 30));
        for ts in [1.0, 10.0] {
            let r = regularity_of(&acf, ts);
            assert_eq!(r.zero_crossings, 5, "{r:?}");
            assert_eq!(r.period, None, "{r:?}");
            assert_eq!(r.regularity, 0.0, "{r:?}");
            assert!(!r.oscillating, "{r:?}");
        }
        // a cycle of three samples is one
        let r = regularity(&sine(600, 3.0, 1.0, 0.05), 1.0);
        assert!(r.oscillating, "{r:?}");
        assert!((r.period.unwrap() - 3.0).abs() < 0.2, "{r:?}");
    }

    #[test]
    fn a_regularity_without_a_spread_is_shown_in_words() {
        let at = |crossings: Vec<f64>| regularity_from(crossings, 1.0).shown();
        assert_eq!(
            at(vec![2.0, 7.0, 12.0]),
            "not measured: the autocorrelation shows under two periods"
        );
        assert_eq!(at(vec![2.0, 7.0, 12.0, 17.0, 22.0]), "perfectly regular");
        assert_eq!(at(vec![2.0, 7.0, 12.0, 18.0, 22.0]), "7.31");
        assert_eq!(at(Vec::new()), "0.00");
    }

    #[test]
    fn white_noise_is_not() {
        let mut rng = seeded(5);
        let noise: Vec<f64> = (0..2000).map(|_| gaussian(&mut rng)).collect();
        let r = regularity(&noise, 1.0);
        assert!(!r.oscillating, "{r:?}");
        let c = iae_count(
            &noise,
            1.0,
            &IaeSettings {
                amplitude: 0.5,
                omega: std::f64::consts::TAU / 50.0,
                n_lim: 10,
                window: 2500.0,
            },
        );
        assert!(!c.oscillating, "{c:?}");
    }

    #[test]
    fn iae_count_sees_every_half_period_of_a_large_oscillation() {
        let e = sine(2000, 50.0, 1.0, 0.0);
        let s = IaeSettings {
            amplitude: 0.1,
            omega: std::f64::consts::TAU / 50.0,
            n_lim: 10,
            window: 2500.0,
        };
        let c = iae_count(&e, 1.0, &s);
        // 2000 s / 25 s half periods, less the unfinished first and last
        assert!((77..=80).contains(&c.exceedances), "{c:?}");
        assert!(c.oscillating);
        // an oscillation smaller than the acceptable amplitude raises no alarm
        let small: Vec<f64> = e.iter().map(|v| 0.05 * v).collect();
        assert_eq!(iae_count(&small, 1.0, &s).exceedances, 0);
    }

    #[test]
    fn horch_tells_odd_from_even() {
        let n = 2000;
        let w = std::f64::consts::TAU / 50.0;
        let op: Vec<f64> = (0..n).map(|k| (w * k as f64).sin()).collect();
        // PV a quarter period behind OP (integrating-like shape of a stick-slip cycle): odd
        let lagged: Vec<f64> = (0..n).map(|k| -(w * k as f64).cos()).collect();
        let odd = horch(&op, &lagged, 1.0, 60);
        assert_eq!(odd.vote, Vote::Stiction, "{odd:?}");
        // PV in antiphase with OP (a linear loop under a disturbance): even
        let anti: Vec<f64> = op.iter().map(|v| -v).collect();
        let even = horch(&op, &anti, 1.0, 60);
        assert_eq!(even.vote, Vote::NoStiction, "{even:?}");
        assert!((even.tau_right.unwrap() - 12.5).abs() < 0.5, "{even:?}");
    }

    fn wave(n: usize, period: f64, shape: fn(f64) -> f64, noise: f64) -> Vec<f64> {
        let mut rng = seeded(8);
        (0..n)
            .map(|k| shape((k as f64 / period).fract()) + noise * gaussian(&mut rng))
            .collect()
    }
    fn sin01(p: f64) -> f64 {
        (std::f64::consts::TAU * p).sin()
    }
    fn tri01(p: f64) -> f64 {
        if p < 0.25 {
            4.0 * p
        } else if p < 0.75 {
            2.0 - 4.0 * p
        } else {
            4.0 * p - 4.0
        }
    }
    fn sq01(p: f64) -> f64 {
        if p < 0.5 {
            1.0
        } else {
            -1.0
        }
    }

    #[test]
    fn half_cycles_of_a_noisy_sine() {
        let x = wave(1000, 50.0, sin01, 0.1);
        let h = half_cycles(&x, 0.3);
        assert!((36..=40).contains(&h.len()), "{}", h.len());
        for &(s, e) in &h {
            assert!((20..=30).contains(&(e - s)), "{s}..{e}");
        }
    }

    #[test]
    fn curve_fitting_tells_triangles_from_sines() {
        let tri = curve_fitting_index(&wave(2000, 60.0, tri01, 0.05), 0.3);
        assert_eq!(tri.vote, Vote::Stiction, "{tri:?}");
        let sine = curve_fitting_index(&wave(2000, 60.0, sin01, 0.05), 0.3);
        assert_eq!(sine.vote, Vote::NoStiction, "{sine:?}");
    }

    #[test]
    fn shape_index_tells_squares_from_sines() {
        let square = shape_index(&wave(2000, 60.0, sq01, 0.05), 0.3);
        assert_eq!(square.vote, Vote::Stiction, "{square:?}");
        let sine = shape_index(&wave(2000, 60.0, sin01, 0.05), 0.3);
        assert_eq!(sine.vote, Vote::NoStiction, "{sine:?}");
    }

    #[test]
    fn autocorrelation_of_a_constant_is_zero_not_nan() {
        assert!(autocorrelation(&[2.0; 20], 5).iter().all(|&v| v == 0.0));
    }
}
