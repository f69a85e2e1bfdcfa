//! OP steps the control error did not provoke: a feed-forward, an override or an operator moves
//! OP while the loop sits at its setpoint.
//!
//! A controller that acts on the error alone moves OP by a large step only when the error is
//! large or jumps: a PI's move is `Kc Δe + Kc Ts / Ti e`. A sticky valve's OP is its controller's
//! too (while the valve sticks the error persists and OP winds up; when it slips, PV and then the
//! error jump). So an OP step far beyond OP's own noise while the error stays inside its noise
//! band, before and at the step, comes from an input the record does not hold. A feed-forward of
//! a measured load moves OP so with each change of the load while PV, the load compensated,
//! stays put: the closed-loop fit then explains PV's stillness through OP's steps by a valve that
//! sticks through them, and calls a healthy valve sticky. The model family withdraws its stiction
//! vote where such steps carry a share of OP's travel ([`MAX_UNPROVOKED_SHARE`]).

use serde::{Deserialize, Serialize};

/// An OP step: an increment beyond this many standard deviations of OP's increments (robustly:
/// 1.4826 times their median absolute deviation, held samples left out).
pub(crate) const STEP_SIGMAS: f64 = 6.0;
/// ... with the control error inside this many of PV's noise standard deviations at the step and
/// at every sample since OP's previous move (one sample before it where OP moves every sample; a
/// controller slower than the record acts on every error since it last ran).
const QUIET_SIGMAS: f64 = 3.0;
/// The share of OP's travel in unprovoked steps from which the model family's stiction vote is
/// withdrawn: no sticky loop of the catalogue's calibration and benchmark sets has a single
/// unprovoked step, where the false alarms it withdraws (fed-forward loads, quantised PVs, a load
/// step) hold 0.01 to 0.1 of OP's travel in them.
const MAX_UNPROVOKED_SHARE: f64 = 0.01;

/// OP's unprovoked steps on the analysed stretch.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Unprovoked {
    /// How many.
    pub steps: usize,
    /// Their share of OP's travel (the sum of the absolute increments).
    pub share: f64,
}

impl Unprovoked {
    /// Whether they carry enough of OP's travel to withdraw a stiction vote.
    pub fn withdraws(&self) -> bool {
        self.steps > 0 && self.share >= MAX_UNPROVOKED_SHARE
    }
}

/// 1.4826 times the median absolute deviation of `x` from its median (0 when empty).
pub fn robust_sd(mut x: Vec<f64>) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let mid = x.len() / 2;
    let median = *x.select_nth_unstable_by(mid, f64::total_cmp).1;
    let mut dev: Vec<f64> = x.iter().map(|v| (v - median).abs()).collect();
    1.4826 * *dev.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// OP's steps that the control error `error` did not provoke, PV's measurement noise standard
/// deviation `pv_noise` ([`crate::detect::measurement_noise`]) telling the error at rest. `None`
/// when OP's increments or PV's noise cannot be measured (a held OP, a PV that repeats).
pub fn unprovoked(op: &[f64], error: &[f64], pv_noise: f64) -> Option<Unprovoked> {
    let n = op.len().min(error.len());
    if n < 3 {
        return None;
    }
    let d_op: Vec<f64> = op[..n].windows(2).map(|w| w[1] - w[0]).collect();
    // a controller slower than the record holds OP between its moves: those are not its noise
    let moving: Vec<f64> = d_op.iter().copied().filter(|d| *d != 0.0).collect();
    let op_sd = robust_sd(moving);
    if !(op_sd > 0.0 && pv_noise > 0.0) {
        return None;
    }
    let quiet = |k: usize| error[k].abs() < QUIET_SIGMAS * pv_noise;
    let travel: f64 = d_op.iter().map(|d| d.abs()).sum();
    let (mut steps, mut unprovoked) = (0, 0.0);
    // the sample after OP's previous move: a controller slower than the record acts on the
    // errors since its last execution, all of them
    let mut since = 0;
    for (k, d) in d_op.iter().enumerate() {
        if d.abs() > STEP_SIGMAS * op_sd && (since..=k + 1).all(quiet) {
            steps += 1;
            unprovoked += d.abs();
        }
        if *d != 0.0 {
            since = k + 1;
        }
    }
    Some(Unprovoked {
        steps,
        share: if travel > 0.0 {
            unprovoked / travel
        } else {
            0.0
        },
    })
}

#[cfg(test)]
mod tests {
    use super::unprovoked;

    /// A PI's OP steps with its error; a step of OP with the error at rest is unprovoked.
    #[test]
    fn an_op_step_with_the_error_at_rest_is_unprovoked() {
        let n = 400;
        let noise = |k: usize| 0.05 * (k as f64 * 2.399_963).sin();
        let pv: Vec<f64> = (0..n).map(|k| 50.0 + noise(k)).collect();
        let error: Vec<f64> = pv.iter().map(|p| 50.0 - p).collect();
        let noise_sd = crate::detect::measurement_noise(&pv);
        let mut op: Vec<f64> = error.iter().map(|e| 40.0 + 0.5 * e).collect();
        let at_rest = unprovoked(&op, &error, noise_sd).unwrap();
        assert_eq!(at_rest.steps, 0);
        assert!(!at_rest.withdraws());
        for v in &mut op[200..] {
            *v += 3.0;
        }
        let stepped = unprovoked(&op, &error, noise_sd).unwrap();
        assert_eq!(stepped.steps, 1);
        assert!(stepped.share > 0.1 && stepped.withdraws(), "{stepped:?}");
        // the same step answering an error that jumped is the controller's
        let mut error = error;
        for e in &mut error[200..] {
            *e += 6.0;
        }
        assert_eq!(unprovoked(&op, &error, noise_sd).unwrap().steps, 0);
        // OP held throughout: nothing to measure
        assert_eq!(unprovoked(&[40.0; 50], &error[..50], noise_sd), None);
    }
}
