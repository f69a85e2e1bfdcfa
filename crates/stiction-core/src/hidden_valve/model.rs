//! The state-space loop both hypotheses share: a valve with a first-order lag, a first-order
//! process or an integrator behind a dead time, a load that drifts (random walk) and one that
//! cycles (a damped second-order resonance), white measurement noise. Linear and Gaussian given
//! the valve's input, so a Kalman filter gives the likelihood of PV.

#![allow(clippy::needless_range_loop)]

/// Parameters of the shared loop model (PV and OP units; times in seconds).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopModel {
    /// Process gain, PV units per OP unit (an integrator: per OP unit and time constant).
    pub gain: f64,
    /// Process time constant, s (an integrator: the time over which a unit OP step moves PV by
    /// `gain`).
    pub tau: f64,
    /// Dead time, s (rounded to whole samples).
    pub delay: f64,
    /// Valve lag, s (0: the valve follows its input within the sample).
    pub valve_lag: f64,
    /// The process integrates (a level).
    pub integrating: bool,
    /// Measurement noise standard deviation, PV units.
    pub noise: f64,
    /// The drifting load's step standard deviation, PV units per sample.
    pub drift: f64,
    /// The cycling load's innovation standard deviation, PV units.
    pub cycle: f64,
    /// The cycling load's pole radius (0-1: its damping) ...
    pub cycle_radius: f64,
    /// ... and angle, radians per sample (2 pi samples / period).
    pub cycle_angle: f64,
    /// Standard deviation of OP between the samples (what the controller did that the record
    /// does not hold), OP units.
    pub input_noise: f64,
}

/// Dimension of the state: valve, process output, drifting load, cycling load (two).
pub(super) const STATES: usize = 5;

/// The model's matrices at sampling time `ts`, s.
#[derive(Debug, Clone)]
pub(super) struct Matrices {
    pub f: [[f64; STATES]; STATES],
    pub b: [f64; STATES],
    pub q: [[f64; STATES]; STATES],
    pub r: f64,
    pub delay_samples: usize,
}

impl LoopModel {
    pub(super) fn matrices(&self, ts: f64) -> Matrices {
        let av = (-ts / self.valve_lag.max(1e-9)).exp();
        let ax = (-ts / self.tau.max(1e-9)).exp();
        let mut f = [[0.0; STATES]; STATES];
        f[0][0] = av;
        if self.integrating {
            f[1][0] = self.gain * ts / self.tau.max(1e-9);
            f[1][1] = 1.0;
        } else {
            f[1][0] = (1.0 - ax) * self.gain;
            f[1][1] = ax;
        }
        f[2][2] = 1.0;
        f[3][3] = 2.0 * self.cycle_radius * self.cycle_angle.cos();
        f[3][4] = -self.cycle_radius * self.cycle_radius;
        f[4][3] = 1.0;
        let b = [1.0 - av, 0.0, 0.0, 0.0, 0.0];
        let mut q = [[0.0; STATES]; STATES];
        q[0][0] = (b[0] * self.input_noise).powi(2);
        q[2][2] = self.drift * self.drift;
        q[3][3] = self.cycle * self.cycle;
        Matrices {
            f,
            b,
            q,
            r: self.noise * self.noise,
            delay_samples: (self.delay / ts).round().max(0.0) as usize,
        }
    }
}

/// PV is the process output plus both loads plus noise.
const H: [f64; STATES] = [0.0, 1.0, 1.0, 1.0, 0.0];

/// The Kalman gains and innovation variances of the model, step by step until they settle (the
/// covariance does not depend on the data, so every particle and every input shares them).
pub(super) struct Gains {
    pub gain: Vec<[f64; STATES]>,
    pub variance: Vec<f64>,
    /// `ln(2 pi variance)`, the log density's constant, once a stored step.
    pub log_variance: Vec<f64>,
}

impl Gains {
    /// Gains for `n` steps from the initial covariance `p0` (diagonal), stored until they change
    /// by less than a part in 1e9 (the rest repeat the last).
    pub fn of(m: &Matrices, p0: [f64; STATES], n: usize) -> Self {
        let mut p = [[0.0; STATES]; STATES];
        for i in 0..STATES {
            p[i][i] = p0[i];
        }
        let (mut gain, mut variance) = (Vec::new(), Vec::new());
        for _ in 0..n {
            // predict: P = F P F' + Q
            let fp = mul(&m.f, &p);
            let mut pp = m.q;
            for i in 0..STATES {
                for j in 0..STATES {
                    let mut s = 0.0;
                    for k in 0..STATES {
                        s += fp[i][k] * m.f[j][k];
                    }
                    pp[i][j] += s;
                }
            }
            // innovation variance and gain
            let ph: [f64; STATES] =
                std::array::from_fn(|i| (0..STATES).map(|k| pp[i][k] * H[k]).sum());
            let s = (0..STATES).map(|k| H[k] * ph[k]).sum::<f64>() + m.r;
            let k: [f64; STATES] = std::array::from_fn(|i| ph[i] / s);
            for i in 0..STATES {
                for j in 0..STATES {
                    p[i][j] = pp[i][j] - k[i] * ph[j];
                }
            }
            let settled = gain.last().is_some_and(|last: &[f64; STATES]| {
                last.iter()
                    .zip(&k)
                    .all(|(a, b)| (a - b).abs() <= 1e-9 * a.abs().max(1e-12))
            }) && variance
                .last()
                .is_some_and(|&v: &f64| (v - s).abs() <= 1e-9 * v);
            gain.push(k);
            variance.push(s);
            if settled {
                break;
            }
        }
        let log_variance = variance
            .iter()
            .map(|s| (std::f64::consts::TAU * s).ln())
            .collect();
        Self {
            gain,
            variance,
            log_variance,
        }
    }

    /// The gain, innovation variance and the log density's constant at step `t`.
    pub fn at(&self, t: usize) -> (&[f64; STATES], f64, f64) {
        let i = t.min(self.gain.len() - 1);
        (&self.gain[i], self.variance[i], self.log_variance[i])
    }
}

fn mul(a: &[[f64; STATES]; STATES], b: &[[f64; STATES]; STATES]) -> [[f64; STATES]; STATES] {
    let mut c = [[0.0; STATES]; STATES];
    for i in 0..STATES {
        for j in 0..STATES {
            c[i][j] = (0..STATES).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

/// The state mean's prediction, `F m + B u`, written out for the model's sparse `F`.
#[inline]
pub(super) fn predict(f: &[[f64; STATES]; STATES], b0: f64, m: &mut [f64; STATES], u: f64) {
    let v = f[0][0] * m[0] + b0 * u;
    let x = f[1][0] * m[0] + f[1][1] * m[1];
    let z = f[3][3] * m[3] + f[3][4] * m[4];
    m[4] = m[3];
    m[3] = z;
    m[1] = x;
    m[0] = v;
}

/// The innovation of PV `y` against the mean `m`.
#[inline]
pub(super) fn innovation(m: &[f64; STATES], y: f64) -> f64 {
    y - (m[1] + m[2] + m[3])
}

/// The mean's update by the gain `k` and innovation `e`.
#[inline]
pub(super) fn update(m: &mut [f64; STATES], k: &[f64; STATES], e: f64) {
    for i in 0..STATES {
        m[i] += k[i] * e;
    }
}

/// The log density of a Gaussian innovation `e` of variance `s`, `log_s` its constant
/// `ln(2 pi s)`.
#[inline]
pub(super) fn log_density(e: f64, s: f64, log_s: f64) -> f64 {
    -0.5 * (log_s + e * e / s)
}
