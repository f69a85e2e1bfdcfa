//! The stick-slip family: a sticky valve that does not limit-cycle still shows itself in routine
//! data. While it holds, the controller's integral action winds OP against the offset the held
//! valve leaves and PV sits at one level inside its noise; then the valve breaks free and PV
//! steps the way OP pushed it (Kano et al. 2004's "stick, then jump"; Damarla et al. 2022's
//! windows of "PV steady while OP changes"). The family cuts PV into levels and reads which of
//! PV's steps end such a stick ([`steps`]), and the longest OP travel against an offset PV holds
//! without moving at all ([`stuck`]). The OP travel per stick is a model-free estimate of the
//! band.
//!
//! A healthy valve's PV steps too, after a setpoint change or a load, and a slow process holds PV
//! for its dead time after OP moves; those steps come right after a setpoint change, or after OP
//! moved at once, or out of a PV still moving, or against OP's push, and none of them ends a
//! stick. PV samples that look not recorded (historian compression, a frozen transmitter) are no
//! level: a stick made mostly of them is left out.

pub mod steps;
pub mod stuck;

use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::diagnose::result::Vote;
use serde::{Deserialize, Serialize};
pub use steps::StepSettings;
pub use stuck::StuckSettings;

/// The stick-slip family.
pub struct StickSlip;

/// A signal's noise is taken as at least this share of its range (5th to 95th percentile).
const NOISE_FLOOR: f64 = 1e-3;

/// The 5th to 95th percentile range of `x`.
fn range(x: &[f64]) -> f64 {
    let mut v: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let q = |p: f64| v[((v.len() - 1) as f64 * p).round() as usize];
    q(0.95) - q(0.05)
}

/// Steps added to the count the stick share is read over (see `StickSlipEvidence::stick_share`).
const SHARE_PRIOR: usize = 2;
/// A stick of which more than this share of PV looks not recorded is left out.
const MOST_UNRECORDED: f64 = 0.5;

/// What PV's steps and holds show.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StickSlipEvidence {
    /// PV's steps between levels (at least the settings' step in noise standard deviations).
    pub steps: usize,
    /// The steps that end a stick: OP wound while PV held, then PV stepped OP's way.
    pub sticks: usize,
    /// The share of PV's steps that end a stick, `sticks / (steps + 2)`: two steps more in the
    /// count, so one stick of one step (a third) says less than six of eight (0.6).
    pub stick_share: f64,
    /// Median OP travel per stick: a model-free estimate of the band, OP units.
    pub median_travel: Option<f64>,
    /// The same, % of valve span.
    pub median_travel_percent_of_span: Option<f64>,
    /// OP's longest travel, OP units, while PV held off the setpoint without moving towards it.
    pub stuck_travel: f64,
    /// The same, % of valve span.
    pub stuck_travel_percent_of_span: f64,
    /// That hold's samples `[start, end)` of the analysed stretch.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stuck_range: Option<[usize; 2]>,
    /// The controller's sign the pushes were read with: +1 reverse action (OP rises when PV is
    /// below the setpoint), -1 direct.
    pub controller_sign: f64,
    /// PV's and OP's noise standard deviations the levels and travels are held to.
    pub pv_noise: f64,
    /// OP's noise standard deviation, OP units.
    pub op_noise: f64,
    /// The sticks, as sample ranges `[start, end)` of the analysed stretch (the stick and its
    /// step).
    pub ranges: Vec<[usize; 2]>,
}

/// The controller's sign from routine data: the integral gain of a PI in velocity form
/// (`Δop = Kc Δe + Ki e`, a constant beside them where the setpoint is not recorded), or its
/// proportional gain where the integral's is nil.
pub(crate) fn controller_sign(op: &[f64], error: &[f64], setpoint_recorded: bool) -> f64 {
    let n = op.len().min(error.len());
    let k = if setpoint_recorded { 2 } else { 3 };
    let mut a = [[0.0; 3]; 3];
    let mut b = [0.0; 3];
    for t in 1..n {
        let x = [error[t] - error[t - 1], error[t], 1.0];
        let y = op[t] - op[t - 1];
        if !(y.is_finite() && x[0].is_finite() && x[1].is_finite()) {
            continue;
        }
        for i in 0..k {
            b[i] += x[i] * y;
            for j in 0..k {
                a[i][j] += x[i] * x[j];
            }
        }
    }
    match solve(a, b, k) {
        Some(c) if c[1] != 0.0 => c[1].signum(),
        Some(c) if c[0] != 0.0 => c[0].signum(),
        _ => 1.0,
    }
}

/// The first `k` unknowns of `a x = b` (Gaussian elimination with partial pivoting).
// small dense linear algebra reads best with the textbook's indices
#[allow(clippy::needless_range_loop)]
fn solve(mut a: [[f64; 3]; 3], mut b: [f64; 3], k: usize) -> Option<[f64; 3]> {
    for c in 0..k {
        let p = (c..k).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        if a[p][c].abs() < 1e-300 {
            return None;
        }
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..k {
            let f = a[r][c] / a[c][c];
            for j in c..k {
                a[r][j] -= f * a[c][j];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 3];
    for r in (0..k).rev() {
        let s: f64 = (r + 1..k).map(|j| a[r][j] * x[j]).sum();
        x[r] = (b[r] - s) / a[r][r];
    }
    Some(x)
}

impl EvidenceFamily for StickSlip {
    fn family(&self) -> Family {
        Family::StickSlip
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let settings = &ctx.req.settings;
        let sign = controller_sign(ctx.op, &ctx.error, ctx.setpoint.is_some());
        // a record without noise (a simulation, a PV stored to a few digits) still has levels: its
        // noise is taken as at least a thousandth of the signal's range
        let floor = |x: &[f64], noise: f64| noise.max(NOISE_FLOOR * range(x));
        let (pv_noise, op_noise) = (floor(ctx.pv, ctx.pv_noise), floor(ctx.op, ctx.op_noise));
        let signals = steps::Signals {
            op: ctx.op,
            pv: ctx.pv,
            error: &ctx.error,
            // a setpoint step, recorded or read off the record, moves PV through a healthy valve
            sp: ctx.setpoint,
            sign,
            pv_noise,
            op_noise,
        };
        let found = steps::steps(&signals, &settings.steps);
        let sticks: Vec<steps::Stick> = found
            .sticks
            .into_iter()
            .filter(|s| ctx.unrecorded_share(s.start, s.end) <= MOST_UNRECORDED)
            .collect();
        // (a hold needs no recorded noise: PV held far off the setpoint is a finding even where
        // the historian stored it flat, since a move towards the setpoint would have been stored)
        let hold = stuck::longest_hold(ctx.op, ctx.pv, &ctx.error, sign, pv_noise, &settings.stuck);
        let mut travels: Vec<f64> = sticks.iter().map(|s| s.travel.abs()).collect();
        travels.sort_by(f64::total_cmp);
        let median_travel = (!travels.is_empty()).then(|| travels[travels.len() / 2]);
        let stuck_travel = hold.map_or(0.0, |h| h.0);
        let e = StickSlipEvidence {
            steps: found.steps,
            sticks: sticks.len(),
            stick_share: sticks.len() as f64 / (found.steps + SHARE_PRIOR) as f64,
            median_travel,
            median_travel_percent_of_span: median_travel.map(|t| ctx.req.percent_of_span(t)),
            stuck_travel,
            stuck_travel_percent_of_span: ctx.req.percent_of_span(stuck_travel),
            stuck_range: hold.map(|h| h.1),
            controller_sign: sign,
            pv_noise,
            op_noise,
            ranges: sticks.iter().map(|s| [s.start, s.end]).collect(),
        };
        let note = note(&e, ctx.req.ts);
        FamilyEvidence {
            family: Family::StickSlip,
            vote: Vote::Undetermined,
            strength: 0.0,
            contribution: None,
            value: Some(e.stick_share),
            statistic: "the share of PV's steps that end a stick (OP wound while PV held, then PV stepped OP's way)".into(),
            threshold: "read by the verdict's model with the sticks' count and OP's longest travel against a held offset".into(),
            note,
            leans: None,
            model: None,
            stick_slip: Some(e),
            valve: None,
            limit_cycle: None,
            hidden_valve: None,
        }
    }
}

/// What the family measured, in one line.
fn note(e: &StickSlipEvidence, ts: f64) -> String {
    let mut s = if e.steps == 0 {
        "PV makes no step out of its noise between levels".to_string()
    } else {
        format!(
            "{} of PV's {} {} ended a stick{}",
            e.sticks,
            e.steps,
            if e.steps == 1 { "step" } else { "steps" },
            e.median_travel_percent_of_span
                .map_or(String::new(), |t| format!(
                    " (OP wound a median {t:.2} % of span while PV held, then PV stepped OP's way)"
                ))
        )
    };
    if let Some([a, b]) = e.stuck_range {
        s.push_str(&format!(
            "; OP travelled {:.2} % of span over {:.0} min while PV held off the setpoint",
            e.stuck_travel_percent_of_span,
            (b - a) as f64 * ts / 60.0
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_controller_sign_is_read_off_the_integral_action() {
        // a reverse-acting PI: OP rises while the error is positive
        let error: Vec<f64> = (0..300).map(|i| ((i as f64) / 20.0).sin()).collect();
        let mut op = vec![50.0];
        for t in 1..error.len() {
            let last = op[t - 1];
            op.push(last + 0.5 * (error[t] - error[t - 1]) + 0.05 * error[t]);
        }
        assert_eq!(controller_sign(&op, &error, true), 1.0);
        let direct: Vec<f64> = op.iter().map(|v| 100.0 - v).collect();
        assert_eq!(controller_sign(&direct, &error, false), -1.0);
    }
}
