//! A long record judged at the loop's own time scale. A loop whose signals change over minutes,
//! recorded every second, holds the same evidence in means over a few seconds (as a plant
//! historian's averages do: the real records the verdict was trained on are 10-s means of 1-s
//! values), at a fraction of the cost. The means span a share of the time over which OP's and
//! PV's own variation (their noise set aside) loses half its correlation, so no change the
//! families read is averaged away; a record is never averaged below
//! [`AveragingSettings::min_samples`] means. A fast loop's record whose means still hold more than
//! [`AveragingSettings::max_time_scales`] of its half-decay times is judged on that many (never
//! fewer than `min_samples` means), where OP moves most: its evidence is there many times over,
//! and the fits' cost grows faster than the record.

use crate::quality::Record;
use serde::{Deserialize, Serialize};

/// How a long record is averaged before it is judged (part of [`super::Settings`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AveragingSettings {
    /// Fewest means a record is averaged to: a record shorter than twice this is judged sample
    /// by sample.
    pub min_samples: usize,
    /// Means per half-decay time: the time over which the slower-decorrelating of OP and PV (the
    /// faster of the two read) keeps half its correlation, noise set aside.
    pub per_time_scale: f64,
    /// Most half-decay times judged: a record of means that holds more is judged on this many
    /// (at least `min_samples` means), where OP moves most.
    pub max_time_scales: usize,
}

impl Default for AveragingSettings {
    fn default() -> Self {
        Self {
            min_samples: 2_000,
            per_time_scale: 8.0,
            max_time_scales: 2_000,
        }
    }
}

/// What of the analysed stretch was judged, at what resolution, where it was not every sample of
/// it ([`super::Diagnosis::judged_on`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JudgedOn {
    /// Samples a mean spans (1: every sample).
    pub over: usize,
    /// The means' spacing, seconds.
    pub ts: f64,
    /// Means judged.
    pub samples: usize,
    /// The half-decay time the means were sized to, samples of the record (0 where the record
    /// was too short to average).
    pub time_scale: usize,
    /// The record's samples `[start, end)` judged: the analysed stretch, or where its means hold
    /// more than `max_time_scales` half-decay times, the part of it where OP moves most.
    pub stretch: [usize; 2],
}

/// The start of the `len` samples of `op` where OP's variance is largest (searched in steps of a
/// quarter of `len`, the last `len` samples among them).
pub(super) fn most_moving(op: &[f64], len: usize) -> usize {
    let n = op.len();
    if len >= n {
        return 0;
    }
    let mut sum = vec![0.0; n + 1];
    let mut sum2 = vec![0.0; n + 1];
    for (i, &v) in op.iter().enumerate() {
        sum[i + 1] = sum[i] + v;
        sum2[i + 1] = sum2[i] + v * v;
    }
    let variance = |a: usize| {
        let m = (sum[a + len] - sum[a]) / len as f64;
        (sum2[a + len] - sum2[a]) / len as f64 - m * m
    };
    let step = (len / 4).max(1);
    (0..=n - len)
        .step_by(step)
        .chain([n - len])
        .fold((0, f64::NEG_INFINITY), |best, a| {
            let v = variance(a);
            if v > best.1 {
                (a, v)
            } else {
                best
            }
        })
        .0
}

/// The most means judged when a mean spans `over` samples of a loop whose half-decay time is
/// `time_scale` samples (0: unknown, no bound).
pub(super) fn most_judged(set: &AveragingSettings, over: usize, time_scale: usize) -> usize {
    if time_scale == 0 {
        return usize::MAX;
    }
    let held = set.max_time_scales.saturating_mul(time_scale) / over.max(1);
    held.max(set.min_samples)
}

/// The samples a mean spans for the stretch `r` (1: judged sample by sample), and the
/// half-decay time it was sized to (0 for a record too short to average).
pub(super) fn factor(r: &Record, set: &AveragingSettings) -> (usize, usize) {
    let n = r.op.len();
    let most = n / set.min_samples.max(1);
    if most < 2 {
        return (1, 0);
    }
    // look no further than the lag at which the means would reach their cap
    let reach = ((most + 1) as f64 * set.per_time_scale).ceil() as usize;
    // a signal of noise alone (a PV held at its setpoint) has no time scale to keep; where both
    // are, nothing is averaged away
    let tau = match (half_decay(r.op, reach), half_decay(r.pv, reach)) {
        (Some(a), Some(b)) => a.min(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => reach,
    };
    let over = ((tau as f64 / set.per_time_scale).floor() as usize).clamp(1, most);
    (over, tau)
}

/// The first lag (up to `reach`) at which `x`'s autocovariance falls under half its variance
/// above the noise (the noise's variance, from first differences, set aside); `None` for a
/// signal whose variance is noise's to within a tenth (no structure to keep).
fn half_decay(x: &[f64], reach: usize) -> Option<usize> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let centred: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let cov = |k: usize| -> f64 {
        centred[..n - k]
            .iter()
            .zip(&centred[k..])
            .map(|(a, b)| a * b)
            .sum::<f64>()
            / n as f64
    };
    let total = cov(0);
    let noise = crate::detect::measurement_noise(x);
    let signal = total - noise * noise;
    if signal.is_nan() || signal <= NOISE_ALONE * total {
        return None;
    }
    let decayed = |k: usize| cov(k) < 0.5 * signal;
    let reach = reach.min(n / 2).max(1);
    // doubling to the first lag past half, then halving the bracket
    let mut hi = 1;
    while hi < reach && !decayed(hi) {
        hi = (hi * 2).min(reach);
    }
    if !decayed(hi) {
        return Some(reach);
    }
    let mut lo = hi / 2;
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if decayed(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// A signal whose variance above its noise is under this share of its variance is noise alone.
const NOISE_ALONE: f64 = 0.1;

/// The means of the record's signals over `over` consecutive samples (a last, shorter run left
/// out).
pub(super) struct Means {
    op: Vec<f64>,
    pv: Vec<f64>,
    sp: Option<Vec<f64>>,
    mv: Option<Vec<f64>>,
}

impl Means {
    pub(super) fn of(r: &Record, over: usize) -> Self {
        let means = |x: &[f64]| -> Vec<f64> {
            x.chunks_exact(over)
                .map(|c| c.iter().sum::<f64>() / over as f64)
                .collect()
        };
        Self {
            op: means(r.op),
            pv: means(r.pv),
            sp: r.sp.map(means),
            mv: r.mv.map(means),
        }
    }

    /// The means as a record (every sample in automatic, no time column).
    pub(super) fn record(&self) -> Record<'_> {
        Record {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            mv: self.mv.as_deref(),
            time: None,
            auto: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record<'a>(op: &'a [f64], pv: &'a [f64]) -> Record<'a> {
        Record::new(op, pv)
    }

    #[test]
    fn a_slow_cycle_is_averaged_a_fast_one_is_not() {
        let set = AveragingSettings::default();
        let slow: Vec<f64> = (0..40_000).map(|k| (k as f64 / 600.0).sin()).collect();
        let (over, tau) = factor(&record(&slow, &slow), &set);
        // a sine's correlation halves a sixth of its period on (2π·600/6 ≈ 628 samples): past
        // the 168 the search goes to, where the means reach their cap of 40,000 / 2,000
        assert_eq!((over, tau), (20, 168));
        let (_, tau) = factor(
            &record(&slow, &slow[..]),
            &AveragingSettings {
                min_samples: 100,
                ..set
            },
        );
        assert!((600..660).contains(&tau), "{tau}");
        let fast: Vec<f64> = (0..40_000).map(|k| (k as f64 / 6.0).sin()).collect();
        let (over, _) = factor(&record(&fast, &fast), &set);
        assert!(over <= 2, "{over}");
    }

    #[test]
    fn a_short_record_is_judged_sample_by_sample_and_noise_has_no_time_scale() {
        let set = AveragingSettings::default();
        let slow: Vec<f64> = (0..3_000).map(|k| (k as f64 / 600.0).sin()).collect();
        assert_eq!(factor(&record(&slow, &slow), &set).0, 1);
        let mut rng = crate::rng::seeded(7);
        let noise: Vec<f64> = (0..40_000)
            .map(|_| crate::rng::gaussian(&mut rng))
            .collect();
        // a PV of noise alone leaves OP's time scale; a fast OP keeps every sample
        let fast: Vec<f64> = (0..40_000).map(|k| (k as f64 / 6.0).sin()).collect();
        assert!(factor(&record(&fast, &noise), &set).0 <= 2);
        assert_eq!(factor(&record(&slow[..0], &noise[..0]), &set).0, 1);
        assert_eq!(factor(&record(&noise, &noise), &set).0, 20);
    }

    #[test]
    fn the_window_where_op_moves_most() {
        let mut op = vec![0.0; 1_000];
        op[600..700]
            .iter_mut()
            .enumerate()
            .for_each(|(k, v)| *v = (k % 2) as f64);
        let a = most_moving(&op, 200);
        assert!(a <= 600 && a + 200 >= 700, "{a}");
        assert_eq!(most_moving(&op, 2_000), 0);
    }

    #[test]
    fn means_leave_out_a_last_shorter_run() {
        let x: Vec<f64> = (0..10).map(f64::from).collect();
        let m = Means::of(&record(&x, &x), 3);
        assert_eq!(m.record().op, &[1.0, 4.0, 7.0]);
    }
}
