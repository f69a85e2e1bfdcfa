//! The controller from routine data: a PI in velocity form,
//!
//! ```text
//! op[t] - op[t-1] = Kc (e[t] - e[t-1]) + Kc Ts / Ti e[t] + c,
//! ```
//!
//! fitted by least squares on the OP increments (the constant `c` takes up a setpoint that is not
//! recorded, when the error is the PV's deviation from its mean). The velocity form is the one
//! industrial controllers run (Åström and Hägglund 2006, "Advanced PID control", ISA, ch. 13) and
//! needs no initial integral state. The error may lead OP by one sample (a controller that
//! executes between samples, or a historian that stamps OP late): both alignments are fitted and
//! the better kept.
//!
//! A controller that executes between samples, and PV noise the recorder and the controller read
//! at different instants, blur the relation sample by sample; [`identify_pi_below`] fits it on
//! both signals low-passed alike (a linear controller maps filtered error to filtered OP), so
//! the frequencies that matter for the loop's cycle decide.

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

use serde::{Deserialize, Serialize};

/// Which way the controller acts, with the error taken as SP - PV.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Action {
    /// OP rises when PV falls below SP (a positive Kc): the usual action on a process whose PV
    /// rises with OP.
    Reverse,
    /// OP rises when PV rises (a negative Kc).
    Direct,
}

/// The identified PI.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PiFit {
    /// Proportional gain, OP units per PV unit (negative for direct action).
    pub kc: f64,
    /// The integral gain per sample, `Kc Ts / Ti` (the increment's coefficient of `e[t]`).
    pub ki: f64,
    /// Integral time in seconds, when the integral gain has Kc's sign.
    pub ti: Option<f64>,
    /// Kc read as a continuous controller, one that runs many times between the samples (a DCS
    /// under a slower historian): `kc + ki / 2`, the sampled law's integral taken over the sample
    /// as a trapezoid. `kc` and `ti` are exact for a controller that runs once a sample; a faster
    /// one puts part of its proportional action into the sampled law's integral term. On the
    /// plant catalogue's calibration draws (loops whose identified PI explains OP to R² 0.9),
    /// where the controller runs faster than the samples this reading is within 20 % of the
    /// controller's Kc in 98-99 % of the loops (`kc`: 58-67 %); where it runs once a sample, in
    /// 86-96 % (`kc`: 99-100 %).
    #[serde(default)]
    pub kc_continuous: f64,
    /// Ti read so, seconds: `kc_continuous Ts / ki`, when the signs agree.
    #[serde(default)]
    pub ti_continuous: Option<f64>,
    /// Reverse or direct action (the sign of Kc).
    pub action: Action,
    /// Samples by which the error leads OP (0 or 1).
    pub lag: usize,
    /// R² of the OP increments.
    pub r2: f64,
    /// Increments fitted.
    pub samples: usize,
}

/// Fit a PI to OP and the control error `error` (same length, sampled every `ts` seconds).
/// `None` when the record is shorter than 10 samples or the error or OP does not move.
pub fn identify_pi(op: &[f64], error: &[f64], ts: f64) -> Option<PiFit> {
    let n = op.len().min(error.len());
    if n < 10 {
        return None;
    }
    [0, 1]
        .into_iter()
        .filter_map(|lag| fit_lag(&op[..n], &error[..n], ts, lag))
        .max_by(|a, b| a.r2.total_cmp(&b.r2))
}

/// As [`identify_pi`], on OP and the error both low-passed (zero phase) below `cutoff` cycles
/// per sample.
pub fn identify_pi_below(op: &[f64], error: &[f64], ts: f64, cutoff: f64) -> Option<PiFit> {
    if cutoff >= 0.5 {
        return identify_pi(op, error, ts);
    }
    let f = |x: &[f64]| crate::spectral::band_pass(x, 0.0, cutoff);
    identify_pi(&f(op), &f(error), ts)
}

fn fit_lag(op: &[f64], e: &[f64], ts: f64, lag: usize) -> Option<PiFit> {
    let n = op.len();
    // regressors: Δe[t - lag], e[t - lag], 1; output Δop[t]
    let mut g = [[0.0f64; 3]; 3];
    let mut h = [0.0f64; 3];
    let (mut sy, mut syy, mut count) = (0.0, 0.0, 0.0);
    for t in 1 + lag..n {
        let x = [e[t - lag] - e[t - lag - 1], e[t - lag], 1.0];
        let y = op[t] - op[t - 1];
        for i in 0..3 {
            h[i] += x[i] * y;
            for j in 0..3 {
                g[i][j] += x[i] * x[j];
            }
        }
        sy += y;
        syy += y * y;
        count += 1.0;
    }
    let theta = solve3(g, h)?;
    let sst = syy - sy * sy / count;
    if !(sst > 0.0) {
        return None;
    }
    let sse = (syy - (0..3).map(|i| theta[i] * h[i]).sum::<f64>()).max(0.0);
    let (kc, ki) = (theta[0], theta[1]);
    let kc_continuous = kc + ki / 2.0;
    Some(PiFit {
        kc,
        ki,
        ti: (ki * kc > 0.0).then(|| ts * kc / ki),
        kc_continuous,
        ti_continuous: (ki * kc_continuous > 0.0).then(|| ts * kc_continuous / ki),
        action: if kc >= 0.0 {
            Action::Reverse
        } else {
            Action::Direct
        },
        lag,
        r2: 1.0 - sse / sst,
        samples: count as usize,
    })
}

/// Solve the 3 x 3 normal equations by Gaussian elimination with partial pivoting; `None` when
/// they are singular (a regressor that never moves).
pub(super) fn solve3(mut g: [[f64; 3]; 3], mut h: [f64; 3]) -> Option<[f64; 3]> {
    let scale = (0..3).map(|i| g[i][i].abs()).fold(0.0, f64::max);
    for c in 0..3 {
        let p = (c..3).max_by(|&a, &b| g[a][c].abs().total_cmp(&g[b][c].abs()))?;
        if !(g[p][c].abs() > 1e-12 * scale) {
            return None;
        }
        g.swap(c, p);
        h.swap(c, p);
        for r in c + 1..3 {
            let f = g[r][c] / g[c][c];
            for k in c..3 {
                g[r][k] -= f * g[c][k];
            }
            h[r] -= f * h[c];
        }
    }
    let mut x = [0.0; 3];
    for c in (0..3).rev() {
        let s: f64 = (c + 1..3).map(|k| g[c][k] * x[k]).sum();
        x[c] = (h[c] - s) / g[c][c];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::{Model, Stenman};
    use crate::sim::{ClosedLoop, Pi, Process, Signal};

    fn run(kc: f64, ti: f64, k: f64) -> (Vec<f64>, Vec<f64>) {
        let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 1.0 }));
        cl.pi = Pi { kc, ti };
        cl.process = Process::Foptd {
            k,
            tau: 20.0,
            delay: 5.0,
        };
        cl.noise = 0.1;
        cl.seed = 4;
        cl.setpoint = Signal::Steps {
            amplitude: 2.0,
            hold: 200.0,
            offset: 50.0,
            seed: 9,
        };
        let d = cl.run().unwrap();
        let e = d.sp.iter().zip(&d.pv).map(|(s, p)| s - p).collect();
        (d.op, e)
    }

    #[test]
    fn a_pi_you_set_is_identified_back() {
        for (kc, ti) in [(0.3, 15.0), (1.2, 60.0), (0.05, 400.0)] {
            let (op, e) = run(kc, ti, 2.0);
            let f = identify_pi(&op, &e, 1.0).unwrap();
            assert!((f.kc - kc).abs() < 1e-9 * kc.max(1.0), "{f:?}");
            assert!((f.ti.unwrap() - ti).abs() < 1e-6 * ti, "{f:?}");
            assert_eq!((f.action, f.lag), (Action::Reverse, 0));
            assert!(f.r2 > 0.999_999);
            // read as a continuous controller: half a sample's integral action more
            assert!(
                (f.kc_continuous - kc * (1.0 + 0.5 / ti)).abs() < 1e-9,
                "{f:?}"
            );
            assert!(
                (f.ti_continuous.unwrap() - (ti + 0.5)).abs() < 1e-6,
                "{f:?}"
            );
        }
    }

    #[test]
    fn a_controller_faster_than_the_samples_reads_true_as_a_continuous_one() {
        // the controller runs ten times a sample: PV and OP recorded every 10th step
        let (op, e) = run(0.8, 15.0, 2.0);
        let every = |x: &[f64]| x.iter().step_by(10).copied().collect::<Vec<f64>>();
        let f = identify_pi(&every(&op), &every(&e), 10.0).unwrap();
        let (kc, ti) = (f.kc_continuous, f.ti_continuous.unwrap());
        assert!((kc / 0.8 - 1.0).abs() < 0.1, "{f:?}");
        assert!((ti / 15.0 - 1.0).abs() < 0.1, "{f:?}");
        // the reading for a controller that runs once a sample is far off
        assert!(f.kc < 0.8 * 0.8, "{f:?}");
    }

    #[test]
    fn direct_action_and_a_late_op() {
        let (op, e) = run(-0.4, 30.0, -1.5);
        let f = identify_pi(&op, &e, 1.0).unwrap();
        assert_eq!(f.action, Action::Direct);
        assert!((f.kc + 0.4).abs() < 1e-9 && (f.ti.unwrap() - 30.0).abs() < 1e-6);
        // OP stamped one sample late: the error leads by one sample
        let late: Vec<f64> = std::iter::once(op[0])
            .chain(op[..op.len() - 1].iter().copied())
            .collect();
        let f = identify_pi(&late, &e, 1.0).unwrap();
        assert_eq!(f.lag, 1);
        assert!((f.kc + 0.4).abs() < 1e-6, "{f:?}");
    }

    #[test]
    fn an_unrelated_op_fits_badly_and_a_still_one_not_at_all() {
        let (op, _) = run(0.3, 15.0, 2.0);
        let (_, e) = run(0.3, 15.0, -2.0);
        let noise: Vec<f64> = e.iter().rev().copied().collect();
        assert!(identify_pi(&op, &noise, 1.0).unwrap().r2 < 0.2);
        assert!(identify_pi(&vec![5.0; 100], &noise[..100], 1.0).is_none());
    }
}
