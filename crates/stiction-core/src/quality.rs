//! Data-quality gates: before any verdict on a loop, check the record can carry one. A failed gate
//! means "insufficient data" with its reason, never a false "no stiction".

use serde::{Deserialize, Serialize};

/// The data-quality gates a record goes through (in JSON, the snake_case name).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Gate {
    /// Enough samples for a verdict (value and limit in samples).
    RecordLength,
    /// OP at 0 %, 100 % or pinned at its own extreme (value and limit: shares of the samples).
    OpSaturated,
    /// PV repeating its previous value exactly (value and limit: shares of the samples).
    PvFrozen,
    /// PV repeating itself or running in exactly straight lines, as a historian's compression
    /// leaves it (value and limit: shares of the samples).
    PvCompressed,
    /// Too few distinct PV levels (value: distinct levels; limit: levels per 100 samples).
    PvQuantised,
    /// PV held at its record's own extreme (a transmitter at the end of its range, or a clamp):
    /// those samples are left out (value and limit: shares of the samples).
    PvAtLimit,
    /// The controller in manual (value and limit: shares of the samples).
    ManualMode,
    /// Samples with a missing value (NaN), left out (value: share of the samples; limit 1, so it
    /// reports and never fails).
    MissingValues,
    /// Setpoint changes (value and limit: counts; `diagnose` keeps them and never fails on them).
    SetpointChanges,
    /// Gaps in the time axis or time not increasing (value: gaps or breaks; limit 0).
    TimeGaps,
    /// Spikes: one to three samples of PV (or MV) far beyond its own range and back (a historian
    /// or transmitter glitch), left out (value: share of the samples; limit 1, so it reports and
    /// never fails).
    Spikes,
}

impl Gate {
    /// The gate's name, as in JSON: `op_saturated`, `time_gaps`, ...
    pub fn name(self) -> &'static str {
        match self {
            Gate::RecordLength => "record_length",
            Gate::OpSaturated => "op_saturated",
            Gate::PvFrozen => "pv_frozen",
            Gate::PvCompressed => "pv_compressed",
            Gate::PvQuantised => "pv_quantised",
            Gate::PvAtLimit => "pv_at_limit",
            Gate::ManualMode => "manual_mode",
            Gate::MissingValues => "missing_values",
            Gate::SetpointChanges => "setpoint_changes",
            Gate::TimeGaps => "time_gaps",
            Gate::Spikes => "spikes",
        }
    }
}

impl std::fmt::Display for Gate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One gate's finding.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// Which gate.
    pub gate: Gate,
    /// Whether the record passed it.
    pub passed: bool,
    /// The measured quantity and the limit it is held to (units per gate, see [`Gate`]).
    pub value: f64,
    /// The limit `value` is held to.
    pub limit: f64,
    /// One sentence saying what was measured, for people.
    pub message: String,
}

/// Limits of the gates (named, documented conventions).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Limits {
    /// Largest share of samples with OP at 0 % or 100 % (or pinned at its own extreme).
    pub saturated_share: f64,
    /// Largest share of samples whose PV repeats the previous value exactly (frozen or compressed).
    pub repeated_share: f64,
    /// Fewest distinct PV levels per 100 samples, below which the PV counts as quantised.
    pub levels_per_100: f64,
    /// Largest share of samples in manual mode.
    pub manual_share: f64,
    /// Largest step of the time axis, in sampling times, before it counts as a gap.
    pub gap_steps: f64,
    /// Largest number of setpoint changes.
    pub setpoint_changes: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            saturated_share: 0.05,
            repeated_share: 0.5,
            levels_per_100: 5.0,
            manual_share: 0.0,
            gap_steps: 3.0,
            setpoint_changes: 0,
        }
    }
}

/// The signals a loop record may have.
#[derive(Debug, Clone, Copy)]
pub struct Record<'a> {
    /// The controller output (op): the valve's command, normally % of valve span.
    pub op: &'a [f64],
    /// The process variable (pv).
    pub pv: &'a [f64],
    /// The setpoint (sp), when recorded.
    pub sp: Option<&'a [f64]>,
    /// The recorded valve position, when there is one.
    pub mv: Option<&'a [f64]>,
    /// Seconds, one per sample.
    pub time: Option<&'a [f64]>,
    /// `true` where the controller is in automatic.
    pub auto: Option<&'a [bool]>,
}

impl<'a> Record<'a> {
    /// OP and PV alone: no setpoint, valve position, time or mode.
    pub fn new(op: &'a [f64], pv: &'a [f64]) -> Self {
        Record {
            op,
            pv,
            sp: None,
            mv: None,
            time: None,
            auto: None,
        }
    }

    /// Samples `[start, end)` of every signal.
    pub fn slice(&self, start: usize, end: usize) -> Record<'a> {
        Record {
            op: &self.op[start..end],
            pv: &self.pv[start..end],
            sp: self.sp.map(|v| &v[start..end]),
            mv: self.mv.map(|v| &v[start..end]),
            time: self.time.map(|v| &v[start..end]),
            auto: self.auto.map(|v| &v[start..end]),
        }
    }
}

fn finding(gate: Gate, passed: bool, value: f64, limit: f64, message: String) -> Finding {
    Finding {
        gate,
        passed,
        value,
        limit,
        message,
    }
}

/// Run every gate that the record's signals allow.
pub fn check(r: &Record, limits: &Limits) -> Vec<Finding> {
    let n = r.op.len().max(1) as f64;
    let mut out = Vec::new();

    let (lo, hi) =
        r.op.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
    // 0 % and 100 % are limits only for an OP in percent; normalised or engineering-unit OPs
    // (negative values, values above 100) are held to their own extremes alone
    let percent = lo >= 0.0 && hi <= 100.0;
    let mut at_limit = 0usize;
    let mut k = 0;
    while k < r.op.len() {
        let v = r.op[k];
        let mut run = 1;
        while k + run < r.op.len() && r.op[k + run] == v {
            run += 1;
        }
        let at_percent_limit = percent && (v <= 0.0 || v >= 100.0);
        // a value held at the record's own extreme for a while: pinned at a limit we cannot see
        let pinned = hi > lo && (v == lo || v == hi) && run >= 3;
        if at_percent_limit || pinned {
            at_limit += run;
        }
        k += run;
    }
    let share = if hi > lo { at_limit as f64 / n } else { 1.0 };
    out.push(finding(
        Gate::OpSaturated,
        share <= limits.saturated_share,
        share,
        limits.saturated_share,
        format!(
            "OP is at a limit (0 %, 100 % or pinned at its extreme) in {:.0} % of the samples",
            100.0 * share
        ),
    ));

    let repeats = r.pv.windows(2).filter(|w| w[1] == w[0]).count() as f64 / (n - 1.0).max(1.0);
    out.push(finding(
        Gate::PvFrozen,
        repeats <= limits.repeated_share,
        repeats,
        limits.repeated_share,
        format!(
            "PV repeats its previous value in {:.0} % of the samples (frozen or compressed by the historian)",
            100.0 * repeats
        ),
    ));

    let mut levels: Vec<u64> = r.pv.iter().map(|v| v.to_bits()).collect();
    levels.sort_unstable();
    levels.dedup();
    let per_100 = 100.0 * levels.len() as f64 / n;
    out.push(finding(
        Gate::PvQuantised,
        // fifty levels are enough to see a shape, however long the record
        per_100 >= limits.levels_per_100 || levels.len() >= 50,
        levels.len() as f64,
        limits.levels_per_100,
        format!("PV takes {} distinct values", levels.len()),
    ));

    if let Some(auto) = r.auto {
        let manual = auto.iter().filter(|&&a| !a).count() as f64 / n;
        out.push(finding(
            Gate::ManualMode,
            manual <= limits.manual_share,
            manual,
            limits.manual_share,
            format!(
                "the loop is in manual in {:.0} % of the samples",
                100.0 * manual
            ),
        ));
    }

    if let Some(sp) = r.sp {
        let changes = sp.windows(2).filter(|w| w[1] != w[0]).count();
        out.push(finding(
            Gate::SetpointChanges,
            changes <= limits.setpoint_changes,
            changes as f64,
            limits.setpoint_changes as f64,
            format!("the setpoint changes {changes} times"),
        ));
    }

    if let Some(t) = r.time {
        out.push(time_gaps(t, limits));
    }
    out
}

/// The time-axis gate: gaps longer than `limits.gap_steps` sampling times, or steps where time
/// does not increase.
pub fn time_gaps(t: &[f64], limits: &Limits) -> Finding {
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let backwards = steps.iter().filter(|&&s| s <= 0.0).count();
    steps.sort_by(f64::total_cmp);
    let ts = steps.get(steps.len() / 2).copied().unwrap_or(0.0);
    let gaps = if ts > 0.0 {
        t.windows(2)
            .filter(|w| w[1] - w[0] > limits.gap_steps * ts)
            .count()
    } else {
        0
    };
    finding(
        Gate::TimeGaps,
        gaps == 0 && backwards == 0 && ts > 0.0,
        gaps as f64,
        0.0,
        format!(
            "{gaps} gaps longer than {} sampling times, {backwards} steps where time does not increase",
            limits.gap_steps
        ),
    )
}

/// Samples that look not recorded: inside a run of at least `MIN_STRAIGHT` samples that lie on
/// one straight line (repeated values are a flat line). Historians store a value only when it
/// leaves a deviation band (deadband or swinging-door compression) and return repeated values or
/// straight-line interpolation in between; a frozen transmitter repeats its last value. Measured
/// signals carry noise, so a run of exactly straight samples is not a measurement.
pub fn unrecorded(x: &[f64]) -> Vec<bool> {
    let n = x.len();
    let mut out = vec![false; n];
    if n < MIN_STRAIGHT {
        return out;
    }
    let mut d1: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    // the median step, as a full sort would place it (selection: linear time)
    let mid = d1.len() / 2;
    let median = *d1.select_nth_unstable_by(mid, f64::total_cmp).1;
    let scale = x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // rounding of the export (a few decimals) bends a straight line by far less than noise does
    let tol = 0.01 * median + 1e-12 * scale;
    let straight = |k: usize| (x[k + 1] - 2.0 * x[k] + x[k - 1]).abs() <= tol;
    let mut k = 1;
    while k + 1 < n {
        if straight(k) {
            let start = k;
            while k + 1 < n && straight(k) {
                k += 1;
            }
            // interior points k in [start, k) are straight: the run spans start-1 ..= k
            if k - start + 2 >= MIN_STRAIGHT {
                out[start - 1..=k].fill(true);
            }
        } else {
            k += 1;
        }
    }
    out
}

/// A spike is at most this many samples long.
const SPIKE_RUN: usize = 3;
/// A spike leaves the signal's own range (1st to 99th percentile) by more than this many times
/// that range: historian junk (0, -9999, 1e6) does by far; a quantised PV's step to a level the
/// percentiles leave out, or a process's own peak, does not.
const SPIKE_RANGES: f64 = 3.0;
/// Spikes are rare: when more samples than this share would be spikes, the signal is taken as
/// it is (they are its own behaviour, not glitches) and none is marked.
const SPIKE_SHARE: f64 = 0.01;

/// The samples of `x` that are spikes: runs of at most `SPIKE_RUN` samples beyond the
/// signal's 1st to 99th percentile range by more than `SPIKE_RANGES` times that range, with
/// the samples either side back inside it. A single historian glitch (a PV of 1e6 in a loop
/// that runs between 48 and 52) otherwise dominates every fit and index. Non-finite samples are
/// not spikes (they are missing); none when the signal has no spread or spikes are not rare.
pub fn spikes(x: &[f64]) -> Vec<bool> {
    let n = x.len();
    let mut out = vec![false; n];
    let mut sorted: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.len() < 20 {
        return out;
    }
    sorted.sort_by(f64::total_cmp);
    let at = |p: f64| sorted[((sorted.len() - 1) as f64 * p).round() as usize];
    let (p1, p99) = (at(0.01), at(0.99));
    let range = p99 - p1;
    if range.is_nan() || range <= 0.0 {
        return out;
    }
    let far =
        |v: f64| v.is_finite() && (v > p99 + SPIKE_RANGES * range || v < p1 - SPIKE_RANGES * range);
    let mut k = 0;
    while k < n {
        if !far(x[k]) {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && far(x[k]) {
            k += 1;
        }
        if k - start <= SPIKE_RUN {
            out[start..k].fill(true);
        }
    }
    if out.iter().filter(|&&s| s).count() as f64 > SPIKE_SHARE * n as f64 {
        out.fill(false);
    }
    out
}

/// A value for a message about the data: four decimals in the usual magnitudes, else four
/// significant digits in exponent form (OP recorded in raw units of 1e7 reads 4.900e7).
pub(crate) fn readable(v: f64) -> String {
    if v != 0.0 && !(1e-3..1e6).contains(&v.abs()) {
        format!("{v:.3e}")
    } else {
        format!("{v:.4}")
    }
}

/// Runs of at least this many samples on one straight line count as not recorded.
const MIN_STRAIGHT: usize = 5;

/// The resolution of a quantised signal: the smallest step between consecutive samples, when at
/// least a third of the steps are zero and every other step is a whole multiple of it.
pub fn quantum(x: &[f64]) -> Option<f64> {
    let steps: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    if steps.is_empty() {
        return None;
    }
    let zeros = steps.iter().filter(|&&s| s == 0.0).count();
    let q = steps
        .iter()
        .copied()
        .filter(|&s| s > 0.0)
        .fold(f64::INFINITY, f64::min);
    if 3 * zeros < steps.len() || !q.is_finite() {
        return None;
    }
    let whole = steps
        .iter()
        .filter(|&&s| s > 0.0)
        .all(|&s| ((s / q) - (s / q).round()).abs() < 0.05);
    whole.then_some(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_glitch_is_a_spike_and_a_step_or_an_excursion_is_not() {
        let base: Vec<f64> = (0..400).map(|k| 50.0 + (k as f64 / 9.0).sin()).collect();
        // one glitch, and one of three samples
        let mut x = base.clone();
        x[100] = 1e6;
        x[200..203].fill(0.0);
        let s = spikes(&x);
        assert!(s[100] && s[200] && s[202], "{:?}", &s[98..104]);
        assert_eq!(s.iter().filter(|&&v| v).count(), 4);
        // a step that stays (a valve's slip) is no spike, however large
        let mut step = base.clone();
        for v in &mut step[300..] {
            *v += 30.0;
        }
        assert!(!spikes(&step).iter().any(|&v| v));
        // an excursion of more than three samples is the process's
        let mut long = base.clone();
        long[100..105].fill(1e3);
        assert!(!spikes(&long).iter().any(|&v| v));
        // a signal without spread, and one whose "spikes" are not rare, are taken as they are
        let mut flat = vec![50.0; 400];
        flat[10] = 51.0;
        assert!(!spikes(&flat).iter().any(|&v| v));
        let mut often = base;
        for k in (0..400).step_by(20) {
            often[k] = 1e3;
        }
        assert!(!spikes(&often).iter().any(|&v| v));
    }

    fn loop_record(n: usize) -> (Vec<f64>, Vec<f64>) {
        let op = (0..n)
            .map(|k| 50.0 + 5.0 * (k as f64 * 0.1).sin())
            .collect();
        let pv = (0..n)
            .map(|k| 20.0 + 2.0 * (k as f64 * 0.1 - 0.5).sin())
            .collect();
        (op, pv)
    }

    fn failed(f: &[Finding]) -> Vec<Gate> {
        f.iter().filter(|f| !f.passed).map(|f| f.gate).collect()
    }

    #[test]
    fn a_clean_record_passes_every_gate() {
        let (op, pv) = loop_record(1000);
        let sp = vec![20.0; 1000];
        let t: Vec<f64> = (0..1000).map(|k| k as f64).collect();
        let auto = vec![true; 1000];
        let r = Record {
            op: &op,
            pv: &pv,
            sp: Some(&sp),
            mv: None,
            time: Some(&t),
            auto: Some(&auto),
        };
        let f = check(&r, &Limits::default());
        assert_eq!(f.len(), 6);
        assert!(failed(&f).is_empty(), "{f:?}");
    }

    #[test]
    fn each_defect_fails_its_gate() {
        let (mut op, mut pv) = loop_record(1000);
        for v in &mut op[..200] {
            *v = 100.0;
        }
        for k in (0..1000).step_by(2) {
            pv[k + 1] = pv[k];
        }
        for v in &mut pv[..700] {
            *v = (*v * 2.0).round() / 2.0;
        }
        let mut sp = vec![20.0; 1000];
        sp[500..].fill(21.0);
        let mut t: Vec<f64> = (0..1000).map(|k| k as f64).collect();
        for v in &mut t[600..] {
            *v += 30.0;
        }
        let mut auto = vec![true; 1000];
        auto[100] = false;
        let r = Record {
            op: &op,
            pv: &pv,
            sp: Some(&sp),
            mv: None,
            time: Some(&t),
            auto: Some(&auto),
        };
        let f = failed(&check(&r, &Limits::default()));
        for gate in [
            Gate::OpSaturated,
            Gate::PvFrozen,
            Gate::ManualMode,
            Gate::SetpointChanges,
            Gate::TimeGaps,
        ] {
            assert!(f.contains(&gate), "{gate} not failed: {f:?}");
        }
    }

    #[test]
    fn straight_runs_and_repeats_are_not_recorded() {
        // noise-like values, then a straight line, then repeats
        // noise-like values (a linear congruential sequence), then a straight line, then repeats
        let mut state = 12345u64;
        let mut x: Vec<f64> = (0..40)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 33) as f64 / (1u64 << 31) as f64
            })
            .collect();
        for (k, v) in x.iter_mut().enumerate().take(20).skip(10) {
            *v = 3.0 + 0.25 * (k - 10) as f64;
        }
        for v in &mut x[25..32] {
            *v = 9.0;
        }
        let u = unrecorded(&x);
        assert!(u[10..20].iter().all(|&b| b), "{u:?}");
        assert!(u[25..32].iter().all(|&b| b), "{u:?}");
        assert!(!u[0..8].iter().any(|&b| b), "{u:?}");
        assert!(!u[34..].iter().any(|&b| b), "{u:?}");
    }

    #[test]
    fn the_quantum_of_a_quantised_signal() {
        let x: Vec<f64> = (0..200)
            .map(|k| (((k as f64) * 0.05).sin() * 20.0).round() * 0.5)
            .collect();
        let q = quantum(&x).unwrap();
        assert!((q - 0.5).abs() < 1e-12, "{q}");
        let noisy: Vec<f64> = (0..200)
            .map(|k| ((k * 7919) % 101) as f64 * 0.013)
            .collect();
        assert_eq!(quantum(&noisy), None);
    }

    #[test]
    fn a_quantised_pv_is_caught() {
        let (op, pv) = loop_record(1000);
        let coarse: Vec<f64> = pv.iter().map(|v| v.round()).collect();
        let r = Record {
            op: &op,
            pv: &coarse,
            sp: None,
            mv: None,
            time: None,
            auto: None,
        };
        assert!(failed(&check(&r, &Limits::default())).contains(&Gate::PvQuantised));
    }
}
