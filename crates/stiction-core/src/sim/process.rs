//! The process a valve drives, in deviation from the operating point, and its exact zero-order-hold
//! discretisation (the input is held over each simulation step).

use super::{require, SimError};
use serde::{Deserialize, Serialize};

/// The process the valve drives, in deviation from the operating point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Process {
    /// `K e^{-delay s} / (tau s + 1)`, discretised exactly with a zero-order hold.
    Foptd {
        /// Gain K, PV units per % of flow.
        k: f64,
        /// Time constant, seconds.
        tau: f64,
        /// Dead time, seconds.
        delay: f64,
    },
    /// `K e^{-delay s} / s` (a level loop), discretised with a zero-order hold.
    Integrating {
        /// Rate K, PV units per second per % of flow.
        k: f64,
        /// Dead time, seconds.
        delay: f64,
    },
    /// `K e^{-delay s} / ((tau1 s + 1)(tau2 s + 1))`, two lags in series (slow temperature and
    /// analyser loops), discretised exactly with a zero-order hold; `tau1 = tau2` is allowed.
    Soptd {
        /// Gain K, PV units per % of flow.
        k: f64,
        /// First time constant, seconds.
        tau1: f64,
        /// Second time constant, seconds.
        tau2: f64,
        /// Dead time, seconds.
        delay: f64,
    },
}

impl Process {
    /// An error naming the first parameter out of range (K zero, a time constant not positive,
    /// a negative dead time).
    pub fn validate(&self) -> Result<(), SimError> {
        match *self {
            Process::Foptd { k, tau, delay } => {
                require(k != 0.0, "process gain K", "non-zero", k)?;
                require(tau > 0.0, "time constant tau", "> 0 seconds", tau)?;
                require(delay >= 0.0, "dead time delay", ">= 0 seconds", delay)
            }
            Process::Integrating { k, delay } => {
                require(k != 0.0, "process gain K", "non-zero", k)?;
                require(delay >= 0.0, "dead time delay", ">= 0 seconds", delay)
            }
            Process::Soptd {
                k,
                tau1,
                tau2,
                delay,
            } => {
                require(k != 0.0, "process gain K", "non-zero", k)?;
                require(tau1 > 0.0, "time constant tau1", "> 0 seconds", tau1)?;
                require(tau2 > 0.0, "time constant tau2", "> 0 seconds", tau2)?;
                require(delay >= 0.0, "dead time delay", ">= 0 seconds", delay)
            }
        }
    }

    /// Dead time, seconds.
    pub fn delay(&self) -> f64 {
        match *self {
            Process::Foptd { delay, .. }
            | Process::Integrating { delay, .. }
            | Process::Soptd { delay, .. } => delay,
        }
    }

    /// Steady-state gain (for an integrating process, its rate per unit input).
    pub fn gain(&self) -> f64 {
        match *self {
            Process::Foptd { k, .. }
            | Process::Integrating { k, .. }
            | Process::Soptd { k, .. } => k,
        }
    }

    /// Whether this is an integrating process.
    pub fn is_integrating(&self) -> bool {
        matches!(self, Process::Integrating { .. })
    }

    /// The process's state stepped every `h` seconds (the dead time is left to the caller).
    pub fn discretise(&self, h: f64) -> ProcessState {
        match *self {
            Process::Foptd { k, tau, .. } => ProcessState::Lag {
                k,
                a: (-h / tau).exp(),
                y: 0.0,
            },
            Process::Integrating { k, .. } => ProcessState::Integrator { k, h, y: 0.0 },
            Process::Soptd { k, tau1, tau2, .. } => {
                let (a1, a2) = ((-h / tau1).exp(), (-h / tau2).exp());
                // the first lag's effect on the second over one step (exact for ZOH input)
                let phi = if (tau1 - tau2).abs() <= 1e-9 * tau1.max(tau2) {
                    h / tau2 * a2
                } else {
                    tau1 * (a1 - a2) / (tau1 - tau2)
                };
                ProcessState::TwoLags {
                    k,
                    a1,
                    a2,
                    phi,
                    x1: 0.0,
                    x2: 0.0,
                }
            }
        }
    }
}

/// A discretised process and its state; `output` is the deviation now, `advance` applies the
/// input held over the next step.
#[derive(Debug, Clone, Copy)]
pub enum ProcessState {
    /// A first-order lag.
    Lag {
        /// Gain K.
        k: f64,
        /// Pole `exp(-h / tau)`.
        a: f64,
        /// Output, in deviation from the operating point.
        y: f64,
    },
    /// An integrator.
    Integrator {
        /// Rate K per second.
        k: f64,
        /// Step, seconds.
        h: f64,
        /// Output, in deviation from the operating point.
        y: f64,
    },
    /// Two first-order lags in series.
    TwoLags {
        /// Gain K.
        k: f64,
        /// Pole of the first lag, `exp(-h / tau1)`.
        a1: f64,
        /// Pole of the second lag, `exp(-h / tau2)`.
        a2: f64,
        /// The first lag's effect on the second over one step.
        phi: f64,
        /// State of the first lag.
        x1: f64,
        /// State of the second lag (the output is `k x2`).
        x2: f64,
    },
}

impl ProcessState {
    /// The output now, in deviation from the operating point.
    pub fn output(&self) -> f64 {
        match *self {
            ProcessState::Lag { y, .. } | ProcessState::Integrator { y, .. } => y,
            ProcessState::TwoLags { k, x2, .. } => k * x2,
        }
    }

    /// One step with input `u` held over it. The arithmetic of the first two kinds is the one
    /// `ClosedLoop` always used, so its results stay bit for bit the same.
    pub fn advance(&mut self, u: f64) {
        match self {
            ProcessState::Lag { k, a, y } => *y = *a * *y + *k * (1.0 - *a) * u,
            ProcessState::Integrator { k, h, y } => *y += *k * *h * u,
            ProcessState::TwoLags {
                a1,
                a2,
                phi,
                x1,
                x2,
                ..
            } => {
                *x2 = *a2 * *x2 + *phi * *x1 + (1.0 - *a2 - *phi) * u;
                *x1 = *a1 * *x1 + (1.0 - *a1) * u;
            }
        }
    }
}
