//! The process a valve drives, in deviation from the operating point, and its exact zero-order-hold
//! discretisation (the input is held over each simulation step).

use super::{require, SimError};
use serde::{Deserialize, Serialize};

/// The process the valve drives, in deviation from the operating point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Process {
    /// `K e^{-delay s} / (tau s + 1)`, discretised exactly with a zero-order hold.
    Foptd { k: f64, tau: f64, delay: f64 },
    /// `K e^{-delay s} / s` (a level loop), discretised with a zero-order hold.
    Integrating { k: f64, delay: f64 },
    /// `K e^{-delay s} / ((tau1 s + 1)(tau2 s + 1))`, two lags in series (slow temperature and
    /// analyser loops), discretised exactly with a zero-order hold; `tau1 = tau2` is allowed.
    Soptd {
        k: f64,
        tau1: f64,
        tau2: f64,
        delay: f64,
    },
}

impl Process {
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
    Lag {
        k: f64,
        a: f64,
        y: f64,
    },
    Integrator {
        k: f64,
        h: f64,
        y: f64,
    },
    TwoLags {
        k: f64,
        a1: f64,
        a2: f64,
        phi: f64,
        x1: f64,
        x2: f64,
    },
}

impl ProcessState {
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
