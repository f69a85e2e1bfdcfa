//! Controller tuning for the catalogue: SIMC (lambda) rules and the ultimate gain of the linear loop.
//!
//! SIMC: S. Skogestad, "Simple analytic rules for model reduction and PID controller tuning",
//! J. Process Control 13 (2003) 291-309: for `K e^{-θs}/(τ s + 1)`, `Kc = τ / (K (λ + θ))`,
//! `Ti = min(τ, 4 (λ + θ))`; for an integrating `K e^{-θs}/s`, `Kc = 1 / (K (λ + θ))`,
//! `Ti = 4 (λ + θ)`; a second lag is halved into the first lag and the delay ("half rule").
//! The delay the controller sees also holds half a controller period (the zero-order hold) and
//! the actuator lag.

use std::f64::consts::PI;
use stiction_core::sim::{Pi, Process};

/// The linear loop apart from the controller's gain: process, actuator lag, controller period and
/// the local gain of the valve's characteristic.
#[derive(Debug, Clone, Copy)]
pub struct LinearLoop {
    /// The process.
    pub process: Process,
    /// First-order actuator lag, seconds.
    pub valve_lag: f64,
    /// Controller period, seconds.
    pub h: f64,
    /// d flow / d position where the valve works (1 for a linear valve).
    pub valve_gain: f64,
}

impl LinearLoop {
    /// The delay a tuning rule should see: dead time, half the controller period, the actuator
    /// lag and, for two lags, half the smaller one.
    pub fn effective_delay(&self) -> f64 {
        let extra = match self.process {
            Process::Soptd { tau1, tau2, .. } => tau1.min(tau2) / 2.0,
            _ => 0.0,
        };
        self.process.delay() + self.h / 2.0 + self.valve_lag + extra
    }

    /// SIMC PI settings for closed-loop time constant `lambda` seconds.
    pub fn simc(&self, lambda: f64) -> Pi {
        let theta = self.effective_delay();
        let k = self.process.gain() * self.valve_gain;
        match self.process {
            Process::Foptd { tau, .. } => Pi {
                kc: tau / (k * (lambda + theta)),
                ti: tau.min(4.0 * (lambda + theta)),
            },
            Process::Soptd { tau1, tau2, .. } => {
                let tau = tau1.max(tau2) + tau1.min(tau2) / 2.0;
                Pi {
                    kc: tau / (k * (lambda + theta)),
                    ti: tau.min(4.0 * (lambda + theta)),
                }
            }
            Process::Integrating { .. } => Pi {
                kc: 1.0 / (k * (lambda + theta)),
                ti: 4.0 * (lambda + theta),
            },
        }
    }

    /// Gain and phase (radians) of everything but `Kc` at frequency `w` rad/s, with integral time
    /// `ti`: `(1 + 1/(j w Ti)) * valve lag * process`, the hold as half a period of delay.
    fn response(&self, w: f64, ti: f64) -> (f64, f64) {
        let lag = |tau: f64| (1.0 / (1.0 + (w * tau).powi(2)).sqrt(), -(w * tau).atan());
        let (mut gain, mut phase) = lag(self.valve_lag);
        gain *= self.valve_gain * (1.0 + (w * ti).powi(2)).sqrt() / (w * ti);
        phase += (w * ti).atan() - PI / 2.0 - w * self.h / 2.0;
        let (g, p) = match self.process {
            Process::Foptd { k, tau, delay } => {
                let (g, p) = lag(tau);
                (k.abs() * g, p - w * delay)
            }
            Process::Soptd {
                k,
                tau1,
                tau2,
                delay,
            } => {
                let ((g1, p1), (g2, p2)) = (lag(tau1), lag(tau2));
                (k.abs() * g1 * g2, p1 + p2 - w * delay)
            }
            Process::Integrating { k, delay } => (k.abs() / w, -PI / 2.0 - w * delay),
        };
        (gain * g, phase + p)
    }

    /// The ultimate gain and period for integral time `ti`: the controller gain at which the
    /// linear loop reaches the stability limit, and the period it then oscillates with. Found at
    /// the highest frequency below Nyquist where the phase crosses -180°.
    pub fn ultimate(&self, ti: f64) -> Option<(f64, f64)> {
        let below = |w: f64| self.response(w, ti).1 + PI;
        let w_hi = PI / self.h;
        let steps = 600;
        let ratio: f64 = (1e-7f64).powf(1.0 / steps as f64);
        let mut w = w_hi;
        let mut prev = (w, below(w));
        for _ in 0..steps {
            w *= ratio;
            let b = below(w);
            if prev.1 < 0.0 && b >= 0.0 {
                // bisect between w (phase above -180°) and prev.0 (below)
                let (mut lo, mut hi) = (w, prev.0);
                for _ in 0..80 {
                    let mid = (lo * hi).sqrt();
                    if below(mid) >= 0.0 {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                let w180 = (lo * hi).sqrt();
                return Some((1.0 / self.response(w180, ti).0, 2.0 * PI / w180));
            }
            prev = (w, b);
        }
        None
    }
}
