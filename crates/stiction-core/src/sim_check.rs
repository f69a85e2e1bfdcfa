//! Is a simulated closed loop fit to study? A loop tuned too tight oscillates with a growing
//! amplitude or runs away, and a controller output pinned at 0 or 100 % for a noticeable share
//! of the time is no longer a PI loop but a relay: data of either kind says little about a
//! valve's stiction. [`loop_health`] checks a [`LoopData`] for both.

use crate::sim::LoopData;
use serde::{Deserialize, Serialize};

/// The controller output's limits in the closed-loop simulation (% of span).
const OP_LIMITS: (f64, f64) = (0.0, 100.0);

/// The share of samples with OP at a limit from which a loop counts as saturated.
pub const SATURATION_LIMIT: f64 = 0.05;

/// How much larger the control error's RMS must be in the last quarter of the record than in the
/// second quarter for the loop to count as unstable.
const GROWTH_LIMIT: f64 = 2.0;

/// How the loop's control error evolves over the record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    /// The error does not grow.
    Stable,
    /// The error's RMS grows by more than `GROWTH_LIMIT` from the second to the last quarter:
    /// a growing oscillation or a PV drifting away.
    Growing,
    /// The PV is no longer a finite number of sensible size (beyond 1e6).
    RunningAway,
}

/// The health of a simulated closed loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoopHealth {
    /// Whether the loop is stable, growing or running away.
    pub stability: Stability,
    /// RMS of the control error (sp - pv) in the last quarter over that in the second quarter
    /// (`None` when either is not finite or the second is 0).
    pub growth: Option<f64>,
    /// Share of samples with OP at its lower limit ...
    pub saturated_low: f64,
    /// ... and at its upper limit.
    pub saturated_high: f64,
}

impl LoopHealth {
    /// Share of samples with OP at either limit.
    pub fn saturated(&self) -> f64 {
        self.saturated_low + self.saturated_high
    }

    /// Stable, and OP at a limit less than [`SATURATION_LIMIT`] of the time.
    pub fn is_healthy(&self) -> bool {
        self.stability == Stability::Stable && self.saturated() < SATURATION_LIMIT
    }
}

/// Check a closed-loop record (sp, op and pv of the same length, at least 8 samples); `None` for
/// an open-loop record (no pv) or one too short to judge.
pub fn loop_health(d: &LoopData) -> Option<LoopHealth> {
    let n = d.pv.len();
    if n < 8 || d.sp.len() != n || d.op.len() != n {
        return None;
    }
    let share =
        |hit: &dyn Fn(f64) -> bool| d.op.iter().filter(|&&v| hit(v)).count() as f64 / n as f64;
    let saturated_low = share(&|v| v <= OP_LIMITS.0);
    let saturated_high = share(&|v| v >= OP_LIMITS.1);
    let runaway = d.pv.iter().any(|v| !v.is_finite() || v.abs() > 1e6);
    let rms = |a: usize, b: usize| {
        let s: f64 = (a..b).map(|k| (d.sp[k] - d.pv[k]).powi(2)).sum();
        (s / (b - a) as f64).sqrt()
    };
    let q = n / 4;
    let (second, third, last) = (rms(q, 2 * q), rms(2 * q, 3 * q), rms(n - q, n));
    let growth = (second > 0.0 && second.is_finite() && last.is_finite()).then(|| last / second);
    // sustained growth: the third quarter above the second too, so one late setpoint step or
    // disturbance does not count
    let growing = growth.is_some_and(|g| g > GROWTH_LIMIT) && third > second;
    let stability = if runaway {
        Stability::RunningAway
    } else if growing {
        Stability::Growing
    } else {
        Stability::Stable
    };
    Some(LoopHealth {
        stability,
        growth,
        saturated_low,
        saturated_high,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::{Model, ModelKind};
    use crate::sim::{ClosedLoop, Pi};

    fn closed(kc: f64, ti: f64, d: f64) -> LoopData {
        let model: Model = ModelKind::Stenman.build(&[d]).unwrap();
        let mut cl = ClosedLoop::new(model);
        cl.pi = Pi { kc, ti };
        cl.samples = 1500;
        cl.run().unwrap()
    }

    #[test]
    fn the_default_loop_is_healthy() {
        let h = loop_health(&closed(0.2, 10.0, 0.5)).unwrap();
        assert!(h.is_healthy(), "{h:?}");
        // a stiction limit cycle is sustained, not growing
        let h = loop_health(&closed(0.2, 10.0, 3.0)).unwrap();
        assert_eq!(h.stability, Stability::Stable, "{h:?}");
    }

    #[test]
    fn a_loop_tuned_too_tight_is_flagged() {
        // the example: Kc = 5, Ti = 1 s on K = 3, tau = 10 s, delay = 10 s
        let h = loop_health(&closed(5.0, 1.0, 0.5)).unwrap();
        assert!(!h.is_healthy(), "{h:?}");
        assert!(h.saturated() > SATURATION_LIMIT, "{h:?}");
    }

    #[test]
    fn growth_and_runaway_from_the_data() {
        let n = 400;
        let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let sp = vec![50.0; n];
        let op = vec![50.0; n];
        let growing: Vec<f64> = t
            .iter()
            .map(|&k| 50.0 + (k / 60.0).exp() * 0.01 * (k / 5.0).sin())
            .collect();
        let data = |pv: Vec<f64>| LoopData {
            t: t.clone(),
            sp: sp.clone(),
            op: op.clone(),
            mv: op.clone(),
            pv,
        };
        let h = loop_health(&data(growing)).unwrap();
        assert_eq!(h.stability, Stability::Growing, "{h:?}");
        let mut away = vec![50.0; n];
        away[n - 1] = f64::INFINITY;
        assert_eq!(
            loop_health(&data(away)).unwrap().stability,
            Stability::RunningAway
        );
        let open = LoopData {
            t: t.clone(),
            sp: vec![],
            op: op.clone(),
            mv: op.clone(),
            pv: vec![],
        };
        assert!(loop_health(&open).is_none());
    }
}
