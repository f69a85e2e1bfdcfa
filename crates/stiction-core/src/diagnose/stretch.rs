//! The usable stretches of a record: samples in automatic, with every signal present, OP and PV
//! off their limits, and a time axis without gaps. Setpoint changes do not split a stretch: they are the best
//! excitation a loop gets.

use super::request::DiagnoseRequest;
use crate::quality::Record;

/// Why samples were left out, counted.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Excluded {
    pub manual: usize,
    pub missing: usize,
    pub saturated: usize,
    /// Samples with PV held at its record's own extreme ([`pv_at_limit`]).
    pub pv_at_limit: usize,
    /// Samples in a spike of any signal ([`crate::quality::spikes`]).
    pub spikes: usize,
    /// Breaks of the time axis (gaps longer than the limit, or time not increasing).
    pub time_breaks: usize,
}

/// Runs of at least this many equal OP values at the record's own extreme count as OP held at a
/// limit we cannot see (a normalised or engineering-unit OP).
const PINNED_RUN: usize = 3;

/// A PV counts as held at a limit only where it otherwise repeats a value in at most this share
/// of its samples: a measurement with noise never repeats exactly, while a quantised PV or one
/// compressed by the historian repeats everywhere, its extremes too (their own gates and guards
/// take care of them).
const PV_REPEATS_ELSEWHERE: f64 = 0.05;

/// The usable stretches `[start, end)`, in order, and what was left out.
pub(super) fn usable(r: &Record, req: &DiagnoseRequest) -> (Vec<(usize, usize)>, Excluded) {
    let n = r.op.len();
    let mut excluded = Excluded::default();
    let saturated = saturated_samples(r.op, req.op_range);
    let pv_limited = pv_at_limit(r.pv);
    let spiked = spiked_samples(r);
    let breaks = time_breaks(r.time, n, req.limits.gap_steps);
    excluded.time_breaks = breaks.iter().filter(|&&b| b).count();
    let mut ok = vec![true; n];
    for k in 0..n {
        let present = r.op[k].is_finite()
            && r.pv[k].is_finite()
            && r.sp.is_none_or(|s| s[k].is_finite())
            && r.mv.is_none_or(|m| m[k].is_finite());
        if r.auto.is_some_and(|a| !a[k]) {
            excluded.manual += 1;
            ok[k] = false;
        } else if !present {
            excluded.missing += 1;
            ok[k] = false;
        } else if spiked[k] {
            excluded.spikes += 1;
            ok[k] = false;
        } else if saturated[k] {
            excluded.saturated += 1;
            ok[k] = false;
        } else if pv_limited[k] {
            excluded.pv_at_limit += 1;
            ok[k] = false;
        }
    }
    let mut out = Vec::new();
    let mut start = None;
    for k in 0..=n {
        let usable = k < n && ok[k];
        let broken = k < n && breaks[k];
        match start {
            Some(s) if !usable || broken => {
                out.push((s, k));
                start = usable.then_some(k);
            }
            None if usable => start = Some(k),
            _ => {}
        }
    }
    (out, excluded)
}

/// Samples in a spike of PV or MV (the measurements; OP's proportional kick at a setpoint step
/// is a few samples far beyond OP's usual range, and real).
fn spiked_samples(r: &Record) -> Vec<bool> {
    let mut out = crate::quality::spikes(r.pv);
    if let Some(mv) = r.mv {
        for (o, s) in out.iter_mut().zip(crate::quality::spikes(mv)) {
            *o |= s;
        }
    }
    out
}

/// Samples with OP at a limit: at the ends of `op_range` when OP stays within it, or held at the
/// record's own extreme for a while.
pub(super) fn saturated_samples(op: &[f64], [lo_range, hi_range]: [f64; 2]) -> Vec<bool> {
    let (lo, hi) = extremes(op);
    let within = lo >= lo_range && hi <= hi_range;
    let mut out = vec![false; op.len()];
    for (k, run) in runs(op) {
        let v = op[k];
        let at_range_limit = within && (v <= lo_range || v >= hi_range);
        let pinned = hi > lo && (v == lo || v == hi) && run >= PINNED_RUN;
        if at_range_limit || pinned {
            out[k..k + run].fill(true);
        }
    }
    out
}

/// The lowest and highest finite values of `x` (infinite the wrong way round without any).
fn extremes(x: &[f64]) -> (f64, f64) {
    let finite = x.iter().copied().filter(|v| v.is_finite());
    finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    })
}

/// The runs of equal values of `x`: each one's first sample and length, in order.
fn runs(x: &[f64]) -> impl Iterator<Item = (usize, usize)> + '_ {
    let mut k = 0;
    std::iter::from_fn(move || {
        let v = *x.get(k)?;
        let start = k;
        k += 1;
        while k < x.len() && x[k] == v {
            k += 1;
        }
        Some((start, k - start))
    })
}

/// Samples with PV held at its record's own extreme: runs of at least [`PINNED_RUN`] equal values
/// at the highest or lowest PV, in a PV that otherwise hardly repeats itself
/// ([`PV_REPEATS_ELSEWHERE`]). A transmitter at the end of its range (or a clamp in the control
/// system) reads the same value while the process goes on beyond it: OP winds up while PV stays
/// put and then moves OP's way, which is what a sticky valve's stick and slip look like, and no
/// linear loop explains the clipped PV, which a band then seems to.
pub(super) fn pv_at_limit(pv: &[f64]) -> Vec<bool> {
    let n = pv.len();
    let mut out = vec![false; n];
    let (lo, hi) = extremes(pv);
    if hi <= lo {
        return out;
    }
    let mut repeats_elsewhere = 0usize;
    for (k, run) in runs(pv) {
        if (pv[k] == lo || pv[k] == hi) && run >= PINNED_RUN {
            out[k..k + run].fill(true);
        } else {
            repeats_elsewhere += run - 1;
        }
    }
    if repeats_elsewhere as f64 > PV_REPEATS_ELSEWHERE * n as f64 {
        out.fill(false);
    }
    out
}

/// `true` at a sample that starts after a gap (a time step longer than `gap_steps` median steps)
/// or where time does not increase.
pub(super) fn time_breaks(time: Option<&[f64]>, n: usize, gap_steps: f64) -> Vec<bool> {
    let Some(t) = time else {
        return vec![false; n];
    };
    let mut steps: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|s| s.is_finite() && *s > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    let ts = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
    let mut out = vec![false; t.len()];
    for k in 1..t.len() {
        let step = t[k] - t[k - 1];
        out[k] = step.is_nan() || step <= 0.0 || (ts > 0.0 && step > gap_steps * ts);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record<'a>(op: &'a [f64], pv: &'a [f64]) -> Record<'a> {
        Record::new(op, pv)
    }

    #[test]
    fn gaps_manual_mode_and_saturation_split_the_record() {
        let n = 100;
        let mut op: Vec<f64> = (0..n).map(|k| 40.0 + (k % 7) as f64).collect();
        let mut pv = vec![1.0; n];
        pv[10] = f64::NAN;
        op[50..53].fill(100.0);
        let mut auto = vec![true; n];
        auto[80..85].fill(false);
        let mut t: Vec<f64> = (0..n).map(|k| k as f64).collect();
        for v in &mut t[90..] {
            *v += 50.0;
        }
        let r = Record {
            auto: Some(&auto),
            time: Some(&t),
            ..record(&op, &pv)
        };
        let (s, ex) = usable(&r, &DiagnoseRequest::default());
        assert_eq!(s, vec![(0, 10), (11, 50), (53, 80), (85, 90), (90, 100)]);
        assert_eq!(
            ex,
            Excluded {
                manual: 5,
                missing: 1,
                saturated: 3,
                pv_at_limit: 0,
                spikes: 0,
                time_breaks: 1
            }
        );
    }

    /// A PV held at its highest value (a transmitter at the end of its range) is left out and
    /// splits the record; a PV that repeats itself everywhere (quantised or compressed), or a
    /// noisy PV that touches its extreme once, is not held at a limit.
    #[test]
    fn a_pv_held_at_its_extreme_is_left_out() {
        let n = 60;
        let op: Vec<f64> = (0..n).map(|k| 50.0 + (k % 5) as f64).collect();
        let noisy = |k: usize| 40.0 + ((k * 37) % 17) as f64 * 0.1;
        let mut pv: Vec<f64> = (0..n).map(noisy).collect();
        pv[20..30].fill(100.0);
        let (s, ex) = usable(&record(&op, &pv), &DiagnoseRequest::default());
        assert_eq!(s, vec![(0, 20), (30, 60)]);
        assert_eq!(ex.pv_at_limit, 10);
        // at its lowest too
        pv[20..30].fill(0.0);
        assert_eq!(pv_at_limit(&pv).iter().filter(|&&l| l).count(), 10);
        // a single sample at the extreme is a measurement's peak, not a limit
        pv[20..30]
            .iter_mut()
            .enumerate()
            .for_each(|(i, v)| *v = noisy(i));
        pv[25] = 100.0;
        assert!(pv_at_limit(&pv).iter().all(|&l| !l));
        // a quantised PV repeats at every level, its extremes too
        let quantised: Vec<f64> = (0..n).map(|k| ((k / 4) % 3) as f64).collect();
        assert!(pv_at_limit(&quantised).iter().all(|&l| !l));
        assert!(pv_at_limit(&[1.0; 10]).iter().all(|&l| !l));
    }

    #[test]
    fn a_clean_record_is_one_stretch() {
        let op: Vec<f64> = (0..50).map(|k| 50.0 + (k as f64).sin()).collect();
        let pv = op.clone();
        let (s, _) = usable(&record(&op, &pv), &DiagnoseRequest::default());
        assert_eq!(s, vec![(0, 50)]);
    }
}
