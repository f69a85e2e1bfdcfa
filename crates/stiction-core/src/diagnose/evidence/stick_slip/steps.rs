//! PV cut into levels and the steps between them, and which steps end a stick.
//!
//! A sticky valve holds while the controller's integral action winds OP against the offset the
//! held valve leaves; PV sits at one level inside its noise; then the valve breaks free and PV
//! steps, quickly, the way OP pushed it (Kano et al. 2004, "stick, then jump"). So PV is fitted
//! by piecewise-constant levels (a penalised least-squares segmentation, PELT: Killick, Fearnhead
//! and Eckley 2012, "Optimal detection of changepoints with a linear computational cost"), and a
//! step between two levels ends a stick when, over the level before it:
//! - OP travelled at least `op_travel` of its noise standard deviations, and not all of it in the
//!   last samples (a healthy PV answering an OP step is not a stick);
//! - PV stayed level (no trend over the level of more than `flatness` of the step: a slow
//!   process still moving is not a stick);
//! - the control error held an offset the integral action winds OP against;
//! - the step went the way OP pushed (through the controller's sign), and came at least a few
//!   samples after any setpoint change (a setpoint step moves PV through a healthy valve too);
//! - PV landed: it holds at its new level (a slow process's rise after its dead time goes on).
//!
//! The share of PV's steps that end a stick is the family's statistic: a healthy valve's PV
//! steps follow loads and setpoint changes, a sticky valve's follow OP's winding.

use serde::{Deserialize, Serialize};

/// How levels and sticks are told.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StepSettings {
    /// The segmentation's penalty per level, in `noise² ln n` (a BIC-like penalty).
    pub penalty: f64,
    /// Fewest samples of a level a step is read between.
    pub min_level: usize,
    /// Most samples between two levels for the change to count as one step ...
    pub max_transition: usize,
    /// ... or this share of the level before, if longer: a slip is fast beside its stick.
    pub transition_share: f64,
    /// A step is at least this many PV noise standard deviations.
    pub min_step: f64,
    /// OP travels at least this many of its noise standard deviations over a stick.
    pub op_travel: f64,
    /// Samples before a step in which OP must not have made most of its travel, and in which the
    /// setpoint must not have changed.
    pub lead: usize,
    /// Share of the stick's OP travel OP may make in its last `lead` samples.
    pub late_share: f64,
    /// PV's trend over a stick at most this share of the step.
    pub flatness: f64,
    /// The control error's offset over a stick, in standard errors of its mean.
    pub offset: f64,
    /// Longest level the segmentation holds whole, samples (longer ones are cut, which keeps its
    /// cost linear in the record).
    pub max_level: usize,
}

impl Default for StepSettings {
    fn default() -> Self {
        Self {
            penalty: 3.0,
            min_level: 4,
            max_transition: 6,
            transition_share: 0.25,
            min_step: 3.0,
            op_travel: 5.0,
            lead: 3,
            late_share: 0.6,
            flatness: 0.3,
            offset: 3.0,
            max_level: 2000,
        }
    }
}

/// One level of PV: samples `[start, end)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// First sample.
    pub start: usize,
    /// One past the last sample.
    pub end: usize,
}

/// A stick ended by a step: OP's travel over it (OP units) and the step (PV units).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stick {
    /// First sample of the stick.
    pub start: usize,
    /// First sample after the step.
    pub end: usize,
    /// OP's travel over the stick, OP units (signed).
    pub travel: f64,
    /// PV's step at its end, PV units (signed).
    pub step: f64,
}

/// What the steps show.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Steps {
    /// Steps of PV between levels (at least `min_step` noise standard deviations).
    pub steps: usize,
    /// The steps that end a stick.
    pub sticks: Vec<Stick>,
}

/// PV's levels: the optimal partition under a penalty `beta` per level (PELT with pruning; a
/// candidate level start further back than `max_level` samples is dropped).
pub fn levels(pv: &[f64], beta: f64, max_level: usize) -> Vec<Level> {
    let n = pv.len();
    if n == 0 {
        return Vec::new();
    }
    let mut sum = vec![0.0; n + 1];
    let mut sum2 = vec![0.0; n + 1];
    for (i, &v) in pv.iter().enumerate() {
        sum[i + 1] = sum[i] + v;
        sum2[i + 1] = sum2[i] + v * v;
    }
    let cost = |a: usize, b: usize| {
        let m = (b - a) as f64;
        let s = sum[b] - sum[a];
        (sum2[b] - sum2[a] - s * s / m).max(0.0)
    };
    let mut best = vec![0.0; n + 1];
    best[0] = -beta;
    let mut last = vec![0usize; n + 1];
    let mut candidates: Vec<usize> = vec![0];
    let mut kept: Vec<usize> = Vec::new();
    // each candidate's cost to `t`, computed once for the minimum and the pruning
    let mut to_t: Vec<f64> = Vec::new();
    for t in 1..=n {
        let (mut f, mut arg) = (f64::INFINITY, 0);
        to_t.clear();
        for &c in &candidates {
            let v = best[c] + cost(c, t);
            to_t.push(v);
            if v + beta < f {
                (f, arg) = (v + beta, c);
            }
        }
        best[t] = f;
        last[t] = arg;
        kept.clear();
        kept.extend(
            candidates
                .iter()
                .zip(&to_t)
                .filter(|&(&c, &v)| v <= f && t - c < max_level)
                .map(|(&c, _)| c),
        );
        if kept.is_empty() {
            kept.push(arg);
        }
        kept.push(t);
        std::mem::swap(&mut candidates, &mut kept);
    }
    let mut out = Vec::new();
    let mut t = n;
    while t > 0 {
        out.push(Level {
            start: last[t],
            end: t,
        });
        t = last[t];
    }
    out.reverse();
    out
}

fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len() as f64
}

/// PV's trend over `x` (least-squares slope times its length).
fn trend(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let mt = (n - 1.0) / 2.0;
    let mx = mean(x);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (i, &v) in x.iter().enumerate() {
        let d = i as f64 - mt;
        sxy += d * (v - mx);
        sxx += d * d;
    }
    if sxx > 0.0 {
        sxy / sxx * n
    } else {
        0.0
    }
}

/// The signals the steps are read from.
pub struct Signals<'a> {
    /// Controller output.
    pub op: &'a [f64],
    /// Process variable.
    pub pv: &'a [f64],
    /// The control error, SP - PV (or PV's deviation from its mean without SP).
    pub error: &'a [f64],
    /// The recorded setpoint, if any.
    pub sp: Option<&'a [f64]>,
    /// The controller's sign: +1 where OP rises with the error (reverse action), -1 direct.
    pub sign: f64,
    /// PV's noise standard deviation.
    pub pv_noise: f64,
    /// OP's noise standard deviation.
    pub op_noise: f64,
}

/// PV's steps and the sticks they end.
pub fn steps(s: &Signals, set: &StepSettings) -> Steps {
    let n = s.pv.len();
    if n < 2 * set.min_level || s.pv_noise <= 0.0 || !s.pv_noise.is_finite() {
        return Steps::default();
    }
    let beta = set.penalty * s.pv_noise * s.pv_noise * (n as f64).ln();
    let all = levels(s.pv, beta, set.max_level);
    let means: Vec<f64> = all.iter().map(|l| mean(&s.pv[l.start..l.end])).collect();
    let long = |l: &Level| l.end - l.start >= set.min_level;
    let changed = |a: usize, b: usize| {
        s.sp.is_some_and(|sp| (a.max(1)..b.min(n)).any(|i| sp[i] != sp[i - 1]))
    };
    let mut out = Steps::default();
    let mut i = 0;
    while i < all.len() {
        let a = all[i];
        // the level PV lands on: the first long one a step away, reached quickly (within the
        // transition the settings allow, or a share of the level before: a slip is fast beside
        // the stick that leads to it; a slow process's rise is not)
        let limit = set
            .max_transition
            .max((set.transition_share * (a.end - a.start) as f64) as usize);
        let landing = long(&a).then(|| {
            (i + 1..all.len())
                .take_while(|&j| all[j].start - a.end <= limit)
                .find(|&j| {
                    long(&all[j]) && (means[j] - means[i]).abs() >= set.min_step * s.pv_noise
                })
        });
        let Some(j) = landing.flatten() else {
            i += 1;
            continue;
        };
        out.steps += 1;
        // a slip lands: PV holds at its new level (a slow process's rise goes on through it)
        let step = means[j] - means[i];
        let landed = trend(&s.pv[all[j].start..all[j].end]).abs() <= set.flatness * step.abs();
        if let Some(stick) = stick(s, set, a, all[j].start, step, &changed).filter(|_| landed) {
            out.sticks.push(stick);
        }
        i = j;
    }
    out
}

/// The stick before a step at `next` (the level `a` before it), if it is one.
fn stick(
    s: &Signals,
    set: &StepSettings,
    a: Level,
    next: usize,
    step: f64,
    changed: &dyn Fn(usize, usize) -> bool,
) -> Option<Stick> {
    if changed(a.end.saturating_sub(set.lead), next + 1) {
        return None;
    }
    // the stick starts at the level's start, or at the last setpoint change inside it
    let start = s.sp.map_or(a.start, |sp| {
        (a.start + 1..a.end)
            .rev()
            .find(|&i| sp[i] != sp[i - 1])
            .unwrap_or(a.start)
    });
    let end = a.end;
    if end - start < set.min_level {
        return None;
    }
    let travel = s.op[end - 1] - s.op[start];
    if travel.abs() < set.op_travel * s.op_noise.max(f64::MIN_POSITIVE) {
        return None;
    }
    let late = s.op[end - 1] - s.op[(end - 1 - set.lead).max(start)];
    let flat = trend(&s.pv[start..end]).abs() <= set.flatness * step.abs();
    let offset = mean(&s.error[start..end]);
    let held = offset.abs() / (s.pv_noise / ((end - start) as f64).sqrt()) >= set.offset;
    let winds = travel.signum() == s.sign * offset.signum();
    let slips = step.signum() == s.sign * travel.signum();
    (late.abs() <= set.late_share * travel.abs() && flat && held && winds && slips).then_some(
        Stick {
            start,
            end: next,
            travel,
            step,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, seed: u64) -> Vec<f64> {
        // a small deterministic generator: the tests need no distribution, only variation
        let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        (0..n)
            .map(|_| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.2
            })
            .collect()
    }

    #[test]
    fn levels_find_the_steps_of_a_staircase() {
        let mut pv = noise(300, 1);
        for (i, v) in pv.iter_mut().enumerate() {
            *v += if i < 100 {
                0.0
            } else if i < 200 {
                2.0
            } else {
                -1.0
            };
        }
        let l = levels(&pv, 3.0 * 0.06f64.powi(2) * 300f64.ln() * 10.0, 2000);
        let ends: Vec<usize> = l.iter().map(|l| l.end).collect();
        assert_eq!(ends, vec![100, 200, 300]);
    }

    /// A sticky valve's record: OP winds up over a held PV, then PV steps up.
    fn sticky() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = 200;
        let mut op = Vec::with_capacity(n);
        let mut pv = noise(n, 7);
        let sp = vec![1.0; n];
        for (i, v) in pv.iter_mut().enumerate() {
            let (o, p) = if i < 100 {
                (50.0 + 0.02 * i as f64, 0.0)
            } else {
                (52.0 - 0.01 * (i - 100) as f64, 1.5)
            };
            op.push(o);
            *v += p;
        }
        (op, pv, sp)
    }

    #[test]
    fn a_stick_ended_by_a_step_is_found() {
        let (op, pv, sp) = sticky();
        let error: Vec<f64> = sp.iter().zip(&pv).map(|(s, p)| s - p).collect();
        let s = Signals {
            op: &op,
            pv: &pv,
            error: &error,
            sp: Some(&sp),
            sign: 1.0,
            pv_noise: 0.06,
            op_noise: 0.01,
        };
        let st = steps(&s, &StepSettings::default());
        assert_eq!(st.steps, 1);
        assert_eq!(st.sticks.len(), 1);
        assert!((st.sticks[0].travel - 1.98).abs() < 0.01);
        // through a direct-acting controller the same step goes against OP's push
        let s = Signals { sign: -1.0, ..s };
        assert!(steps(&s, &StepSettings::default()).sticks.is_empty());
    }

    #[test]
    fn a_step_right_after_a_setpoint_change_is_not_a_stick() {
        let (op, pv, mut sp) = sticky();
        sp[99..].iter_mut().for_each(|v| *v = 2.0);
        let error: Vec<f64> = sp.iter().zip(&pv).map(|(s, p)| s - p).collect();
        let s = Signals {
            op: &op,
            pv: &pv,
            error: &error,
            sp: Some(&sp),
            sign: 1.0,
            pv_noise: 0.06,
            op_noise: 0.01,
        };
        let st = steps(&s, &StepSettings::default());
        assert_eq!(st.steps, 1);
        assert!(st.sticks.is_empty());
    }
}
