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
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2, checked just above.
            return unsafe { levels_avx2(pv, beta, max_level) };
        }
    }
    levels_in(pv, beta, max_level)
}

/// [`levels`] compiled for AVX2: the candidates' costs (a division each) four at a time where
/// SSE2 does two; the same operations in the same order, so the same levels bit for bit.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn levels_avx2(pv: &[f64], beta: f64, max_level: usize) -> Vec<Level> {
    levels_in(pv, beta, max_level)
}

#[inline(always)]
fn levels_in(pv: &[f64], beta: f64, max_level: usize) -> Vec<Level> {
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
    let mut best = vec![0.0; n + 1];
    best[0] = -beta;
    let mut last = vec![0usize; n + 1];
    let mut candidates = Candidates::default();
    candidates.push(0, best[0], 0.0, 0.0);
    // each candidate's cost to `t`, computed once for the minimum and the pruning
    let mut to_t: Vec<f64> = Vec::new();
    for t in 1..=n {
        candidates.costs_to(t, (sum[t], sum2[t]), &mut to_t);
        let (f, arg) = first_minimum(&to_t, beta);
        best[t] = f;
        last[t] = candidates.at(arg);
        candidates.prune(&to_t, f, t, max_level, arg);
        candidates.push(t, f, sum[t], sum2[t]);
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

/// The smallest `v + beta` of `costs` and the first candidate that has it (as a scan for the
/// first strict minimum finds them): the minimum over four running minima the compiler
/// vectorises, then the first candidate equal to it.
#[inline(always)]
fn first_minimum(costs: &[f64], beta: f64) -> (f64, usize) {
    let mut lanes = [f64::INFINITY; 4];
    let chunks = costs.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..4 {
            lanes[k] = lanes[k].min(c[k] + beta);
        }
    }
    let f = rest.iter().fold(
        lanes[0].min(lanes[1]).min(lanes[2].min(lanes[3])),
        |m, &v| m.min(v + beta),
    );
    let arg = costs.iter().position(|&v| v + beta == f).unwrap_or(0);
    (f, arg)
}

/// PELT's candidate level starts, side by side (so the cost of each to a sample is one pass the
/// compiler vectorises): where each starts, the best cost up to it, and the sums up to it. The
/// candidates are those from `head` on (those too far back leave from the front, without moving
/// the rest; the front is cut away now and then).
#[derive(Default)]
struct Candidates {
    head: usize,
    at: Vec<usize>,
    start: Vec<f64>,
    best: Vec<f64>,
    sum: Vec<f64>,
    sum2: Vec<f64>,
}

impl Candidates {
    #[inline(always)]
    fn push(&mut self, at: usize, best: f64, sum: f64, sum2: f64) {
        self.at.push(at);
        self.start.push(at as f64);
        self.best.push(best);
        self.sum.push(sum);
        self.sum2.push(sum2);
    }

    /// Where candidate `i` (counted from the head) starts.
    #[inline(always)]
    fn at(&self, i: usize) -> usize {
        self.at[self.head + i]
    }

    /// Each candidate's best cost plus its level's cost to `t` (the sums up to `t`): the sum of
    /// squares about the level's mean.
    #[inline(always)]
    fn costs_to(&self, t: usize, (sum_t, sum2_t): (f64, f64), out: &mut Vec<f64>) {
        let tf = t as f64;
        let h = self.head;
        out.clear();
        out.extend(
            self.start[h..]
                .iter()
                .zip(&self.best[h..])
                .zip(self.sum[h..].iter().zip(&self.sum2[h..]))
                .map(|((&c, &b), (&s0, &s20))| {
                    let m = tf - c;
                    let s = sum_t - s0;
                    b + (sum2_t - s20 - s * s / m).max(0.0)
                }),
        );
    }

    /// Keep the candidates that can still start the best level (cost to `t` at most `f`,
    /// started fewer than `max_level` samples before), or the best one (`arg`) if none can.
    #[inline(always)]
    fn prune(&mut self, to_t: &[f64], f: f64, t: usize, max_level: usize, arg: usize) {
        let (h, len) = (self.head, self.at.len());
        // those too far back are the oldest: a run from the head
        let mut first = h;
        while first < len && t - self.at[first] >= max_level {
            first += 1;
        }
        // (on a long level most candidates stay: whether any goes is one pass the compiler
        // vectorises, and the moves are made only where one does)
        let goes = to_t[first - h..].iter().fold(false, |g, &v| g | (v > f));
        let mut kept = len;
        if goes {
            kept = first;
            for i in first..len {
                if to_t[i - h] <= f {
                    // (most are kept: they move only after the first one dropped)
                    if i != kept {
                        self.move_to(i, kept);
                    }
                    kept += 1;
                }
            }
        }
        if kept == first {
            self.move_to(h + arg, first);
            kept = first + 1;
        }
        self.at.truncate(kept);
        self.start.truncate(kept);
        self.best.truncate(kept);
        self.sum.truncate(kept);
        self.sum2.truncate(kept);
        self.head = first;
        if self.head > 1024 && 2 * self.head > self.at.len() {
            let cut = self.head;
            self.at.drain(..cut);
            self.start.drain(..cut);
            self.best.drain(..cut);
            self.sum.drain(..cut);
            self.sum2.drain(..cut);
            self.head = 0;
        }
    }

    #[inline(always)]
    fn move_to(&mut self, from: usize, to: usize) {
        self.at[to] = self.at[from];
        self.start[to] = self.start[from];
        self.best[to] = self.best[from];
        self.sum[to] = self.sum[from];
        self.sum2[to] = self.sum2[from];
    }
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
    use proptest::prelude::*;

    /// The optimal partition's cost by dynamic programming over every level start (what PELT's
    /// pruning must not change), levels no longer than `max_level`.
    fn optimal_cost(pv: &[f64], beta: f64, max_level: usize) -> f64 {
        let n = pv.len();
        let sse = |a: usize, b: usize| {
            let x = &pv[a..b];
            let m = x.iter().sum::<f64>() / x.len() as f64;
            x.iter().map(|v| (v - m) * (v - m)).sum::<f64>()
        };
        let mut best = vec![f64::INFINITY; n + 1];
        best[0] = -beta;
        for t in 1..=n {
            for c in t.saturating_sub(max_level)..t {
                best[t] = best[t].min(best[c] + sse(c, t) + beta);
            }
        }
        best[n]
    }

    fn cost_of(pv: &[f64], levels: &[Level], beta: f64) -> f64 {
        levels
            .iter()
            .map(|l| {
                let x = &pv[l.start..l.end];
                let m = x.iter().sum::<f64>() / x.len() as f64;
                x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() + beta
            })
            .sum::<f64>()
            - beta
    }

    proptest! {
        /// The vectorised build (AVX2 where the CPU has it) cuts PV where the plain one does.
        #[test]
        fn levels_are_the_same_in_every_build(
            seed in 0u64..1000,
            n in 20usize..600,
            steps in proptest::collection::vec((0.0f64..1.0, -3.0f64..3.0), 0..8),
            beta in 0.01f64..5.0,
            max_level in 10usize..400,
        ) {
            let pv = stepped(n, seed, &steps);
            prop_assert_eq!(levels(&pv, beta, max_level), levels_in(&pv, beta, max_level));
        }

        #[test]
        fn levels_are_the_optimal_partition(
            seed in 0u64..1000,
            n in 20usize..160,
            steps in proptest::collection::vec((0.0f64..1.0, -3.0f64..3.0), 0..5),
            beta in 0.05f64..5.0,
            max_level in 10usize..200,
        ) {
            let pv = stepped(n, seed, &steps);
            let l = levels(&pv, beta, max_level);
            prop_assert_eq!(l.first().map(|l| l.start), Some(0));
            prop_assert_eq!(l.last().map(|l| l.end), Some(n));
            prop_assert!(l.windows(2).all(|w| w[0].end == w[1].start));
            let (got, want) = (cost_of(&pv, &l, beta), optimal_cost(&pv, beta, max_level));
            // the cut at max_level drops a start for good, so PELT may keep a level longer
            // than max_level only where no cut start was left; compare where the bound binds not
            if l.iter().all(|l| l.end - l.start <= max_level) {
                prop_assert!((got - want).abs() <= 1e-6 * (1.0 + want.abs()), "{} vs {}", got, want);
            }
        }
    }

    /// Noise with steps of PV: each `(at, size)` a step of `size` at that share of the record.
    fn stepped(n: usize, seed: u64, steps: &[(f64, f64)]) -> Vec<f64> {
        let mut pv = noise(n, seed);
        for &(at, size) in steps {
            let from = (at * n as f64) as usize;
            pv[from..].iter_mut().for_each(|v| *v += size);
        }
        pv
    }

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
