//! Frequency responses of the identified loop and its stability margins.
//!
//! The process is an ARX fit ([`crate::identify::Fit`]) from the valve position to the PV:
//! `G(z) = z^-nk B(z) / A(z)` with `A(z) = 1 - a1 z^-1 - ...`, `B(z) = b0 + b1 z^-1 + ...`, and for
//! an integrating structure (which models the PV's change) one more `1 / (1 - z^-1)`. The PI
//! ([`PiFit`]) is `C(z) = z^-lag (Kc + Ki / (1 - z^-1))`. With the error SP - PV the loop is
//! `L = G C` under negative feedback; it is stable when the Nyquist curve of `L` does not encircle
//! -1 (the open loop has no pole outside the unit circle: a stable ARX fit and the PI's
//! integrator). Gain and phase margins are the classical ones (Åström and Murray 2008, "Feedback
//! systems", ch. 10); the modulus margin is the least distance of the Nyquist curve from -1.

use super::controller::PiFit;
use super::Complex64;
use crate::identify::Fit;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// `e^{-j k theta}`.
fn delay(k: f64, theta: f64) -> Complex64 {
    Complex64::from_polar(1.0, -k * theta)
}

/// The ARX process's frequency response at `theta` = ω Ts (radians per sample, 0..π).
pub fn process_response(fit: &Fit, theta: f64) -> Complex64 {
    let s = fit.structure;
    let mut a = Complex64::new(1.0, 0.0);
    for (i, ai) in fit.a.iter().enumerate() {
        a -= ai * delay(i as f64 + 1.0, theta);
    }
    let mut b = Complex64::new(0.0, 0.0);
    for (j, bj) in fit.b.iter().enumerate() {
        b += bj * delay(j as f64, theta);
    }
    let mut g = delay(s.nk as f64, theta) * b / a;
    if s.integrating {
        g /= Complex64::new(1.0, 0.0) - delay(1.0, theta);
    }
    g
}

/// The PI's frequency response at `theta`.
pub fn pi_response(pi: &PiFit, theta: f64) -> Complex64 {
    let integrator = Complex64::new(1.0, 0.0) / (Complex64::new(1.0, 0.0) - delay(1.0, theta));
    delay(pi.lag as f64, theta) * (pi.kc + pi.ki * integrator)
}

/// The identified open loop: process and PI.
#[derive(Debug, Clone)]
pub struct OpenLoop<'a> {
    /// The identified process (ARX, from the valve to PV).
    pub process: &'a Fit,
    /// The identified PI.
    pub pi: &'a PiFit,
}

/// Stability margins of a loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Margins {
    /// The factor by which the loop gain could grow before the loop oscillates on its own
    /// (1 / |L| where the Nyquist curve crosses the negative real axis farthest out); below 1 the
    /// linear loop is unstable. `None` when the curve never crosses it (below the Nyquist
    /// frequency).
    pub gain_margin: Option<f64>,
    /// The period, seconds, at that crossing: the period a linear loop at its stability limit
    /// oscillates with.
    pub critical_period: Option<f64>,
    /// Degrees, at the lowest frequency where |L| = 1.
    pub phase_margin: Option<f64>,
    /// The least distance of the Nyquist curve from -1.
    pub modulus_margin: f64,
}

/// Points of the frequency grid (log-spaced) the margins are searched on.
const GRID: usize = 600;

impl OpenLoop<'_> {
    /// `L` at `theta` = ω Ts.
    pub fn response(&self, theta: f64) -> Complex64 {
        process_response(self.process, theta) * pi_response(self.pi, theta)
    }

    /// The log-spaced grid of `theta` from `lowest` to just below π, with the responses.
    pub fn nyquist(&self, lowest: f64) -> Vec<(f64, Complex64)> {
        let lo = lowest.clamp(1e-6, 0.5);
        let hi = PI * (1.0 - 1e-9);
        (0..GRID)
            .map(|i| {
                let th = lo * (hi / lo).powf(i as f64 / (GRID - 1) as f64);
                (th, self.response(th))
            })
            .collect()
    }

    /// The margins, searched from `lowest` (radians per sample) up to the Nyquist frequency;
    /// `ts` turns the critical frequency into a period.
    pub fn margins(&self, lowest: f64, ts: f64) -> Margins {
        let curve = self.nyquist(lowest);
        let mut worst: Option<(f64, f64)> = None; // (|L|, theta) at negative-real-axis crossings
        let mut phase_margin = None;
        for w in curve.windows(2) {
            let ((t0, l0), (t1, l1)) = (w[0], w[1]);
            if l0.im.signum() != l1.im.signum() {
                let th = self.refine(t0, t1, |l| l.im);
                let l = self.response(th);
                if l.re < 0.0 && worst.is_none_or(|(m, _)| l.norm() > m) {
                    worst = Some((l.norm(), th));
                }
            }
            if phase_margin.is_none() && (l0.norm() - 1.0).signum() != (l1.norm() - 1.0).signum() {
                let th = self.refine(t0, t1, |l| l.norm() - 1.0);
                let arg = self.response(th).arg().to_degrees();
                // the phase of L measured from -180 degrees
                phase_margin = Some((arg + 360.0).rem_euclid(360.0) - 180.0);
            }
        }
        Margins {
            gain_margin: worst.map(|(m, _)| 1.0 / m),
            critical_period: worst.map(|(_, th)| 2.0 * PI * ts / th),
            phase_margin,
            modulus_margin: curve
                .iter()
                .map(|(_, l)| (l + 1.0).norm())
                .fold(f64::INFINITY, f64::min),
        }
    }

    /// Bisection for the zero of `f(L(theta))` between `a` and `b`, where it changes sign.
    fn refine(&self, mut a: f64, mut b: f64, f: impl Fn(Complex64) -> f64) -> f64 {
        let fa = f(self.response(a));
        for _ in 0..40 {
            let m = 0.5 * (a + b);
            if (f(self.response(m)) > 0.0) == (fa > 0.0) {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::Structure;
    use crate::loop_analysis::controller::Action;

    /// A first-order process with a dead time of `nk - 1` samples: a = e^{-Ts/τ}, b = K (1 - a).
    fn foptd(k: f64, tau: f64, nk: usize) -> Fit {
        let a = (-1.0 / tau).exp();
        Fit {
            structure: Structure {
                integrating: false,
                na: 1,
                nb: 1,
                nk,
            },
            a: vec![a],
            b: vec![k * (1.0 - a)],
            c: 0.0,
            sse_one_step: 0.0,
            sse_simulation: 0.0,
            sst: 1.0,
        }
    }

    fn pi(kc: f64, ti: f64) -> PiFit {
        PiFit {
            kc,
            ki: kc / ti,
            ti: Some(ti),
            kc_continuous: kc + kc / ti / 2.0,
            ti_continuous: Some(ti + 0.5),
            action: Action::Reverse,
            lag: 0,
            r2: 1.0,
            samples: 0,
        }
    }

    /// The closed loop's response to a setpoint step grows (true) or decays (false).
    fn grows(process: &Fit, p: &PiFit) -> bool {
        let (a, b, nk) = (process.a[0], process.b[0], process.structure.nk);
        let n = 6000;
        let (mut y, mut op, mut e_prev) = (vec![0.0; n], vec![0.0; n], 0.0);
        for t in 1..n {
            y[t] = a * y[t - 1] + if t >= nk { b * op[t - nk] } else { 0.0 };
            let e = 1.0 - y[t];
            op[t] = op[t - 1] + p.kc * (e - e_prev) + p.ki * e;
            e_prev = e;
        }
        let late = y[n - 500..]
            .iter()
            .map(|v| (v - 1.0).abs())
            .fold(0.0, f64::max);
        let early = y[500..1000]
            .iter()
            .map(|v| (v - 1.0).abs())
            .fold(0.0, f64::max);
        late > early
    }

    #[test]
    fn a_loop_made_marginal_has_a_gain_margin_of_one() {
        let g = foptd(2.0, 20.0, 8);
        let p = pi(0.5, 40.0);
        let m = OpenLoop {
            process: &g,
            pi: &p,
        }
        .margins(1e-3, 1.0);
        let gm = m.gain_margin.unwrap();
        assert!(gm > 1.0 && m.phase_margin.unwrap() > 0.0, "{m:?}");
        // scale the controller by the margin: the loop sits at its limit
        for (f, expect_growth) in [(0.97, false), (1.03, true)] {
            let q = pi(0.5 * gm * f, 40.0);
            let mq = OpenLoop {
                process: &g,
                pi: &q,
            }
            .margins(1e-3, 1.0);
            assert!((mq.gain_margin.unwrap() - 1.0 / f).abs() < 1e-6, "{mq:?}");
            assert_eq!(grows(&g, &q), expect_growth, "factor {f}");
        }
        // the critical period of a loop with a dead time: a few dead times
        let pc = m.critical_period.unwrap();
        assert!(pc > 2.0 * 7.0 && pc < 6.0 * 7.0, "{pc}");
    }

    #[test]
    fn responses_at_low_frequency() {
        // the process's steady-state gain, the PI's integrator
        let g = foptd(2.0, 20.0, 3);
        assert!((process_response(&g, 1e-7) - Complex64::new(2.0, 0.0)).norm() < 1e-4);
        let p = pi(0.5, 40.0);
        let c = pi_response(&p, 1e-4);
        assert!(
            c.im < -1e2 && (c.re - (0.5 + 0.5 * p.ki)).abs() < 1e-3,
            "{c}"
        );
        // an integrating process: phase -90 degrees at low frequency
        let mut gi = foptd(1.0, 1e9, 1);
        gi.structure.integrating = true;
        gi.structure.na = 0;
        gi.a.clear();
        gi.b = vec![0.1];
        let r = process_response(&gi, 1e-3);
        assert!((r.arg().to_degrees() + 90.0).abs() < 0.1 && (r.norm() - 100.0).abs() < 0.1);
    }
}
