//! What lies between the stiction model and the process: the actuator's lag and the installed
//! characteristic (position to flow).
//!
//! A backlash-only valve (a dead band without slip jump) needs no model of its own: Kano's model
//! with `J = 0` is that valve once it has moved both ways (see [`backlash`]).

use super::{require, SimError};
use crate::models::{Kano, Model};
use serde::{Deserialize, Serialize};

/// The installed valve characteristic: valve position (0..100 % of travel) to the flow the process
/// sees (0..100 % of the maximum flow).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Characteristic {
    /// Flow equals position.
    #[default]
    Linear,
    /// Equal percentage, rescaled to pass through 0 and 100:
    /// `flow = 100 (R^{x/100} - 1) / (R - 1)`. The local gain grows by the factor `R` (the
    /// rangeability, typically 20..50) from closed to open, so the loop gain depends on where the
    /// valve works (ISA-75.11; Emerson, *Control Valve Handbook*, ch. 2).
    EqualPercentage {
        /// The rangeability R (> 1).
        rangeability: f64,
    },
}

impl Characteristic {
    /// An error unless an equal-percentage rangeability exceeds 1.
    pub fn validate(&self) -> Result<(), SimError> {
        match *self {
            Characteristic::Linear => Ok(()),
            Characteristic::EqualPercentage { rangeability } => {
                require(rangeability > 1.0, "rangeability", "> 1", rangeability)
            }
        }
    }

    /// Flow (% of the maximum) at valve position `x` (% of travel).
    #[inline]
    pub fn flow(&self, x: f64) -> f64 {
        match *self {
            // no arithmetic: a linear valve leaves the loop's numbers exactly as they were
            Characteristic::Linear => x,
            Characteristic::EqualPercentage { rangeability: r } => {
                100.0 * (r.powf(x / 100.0) - 1.0) / (r - 1.0)
            }
        }
    }

    /// Local gain d flow / d position at `x`.
    pub fn gain(&self, x: f64) -> f64 {
        match *self {
            Characteristic::Linear => 1.0,
            Characteristic::EqualPercentage { rangeability: r } => {
                r.ln() * r.powf(x / 100.0) / (r - 1.0)
            }
        }
    }
}

/// First-order actuator dynamics after the stiction model, time constant `tau` seconds, stepped
/// every `h` seconds: the position at the end of a step moves toward the stiction model's output
/// held over it, `x += (1 - e^{-h/tau}) (target - x)`. `tau = 0` passes the target through.
#[derive(Debug, Clone, Copy)]
pub struct ValveLag {
    a: f64,
    x: f64,
}

impl ValveLag {
    /// A lag of time constant `tau` seconds stepped every `h` seconds, starting at position `x0`.
    pub fn new(tau: f64, h: f64, x0: f64) -> Self {
        let a = if tau > 0.0 { (-h / tau).exp() } else { 0.0 };
        Self { a, x: x0 }
    }

    /// One step toward `target` (the stiction model's output); returns the position.
    #[inline]
    pub fn step(&mut self, target: f64) -> f64 {
        self.x = if self.a == 0.0 {
            target
        } else {
            self.a * self.x + (1.0 - self.a) * target
        };
        self.x
    }
}

/// A backlash-only valve of dead band `band` (% of span): Kano et al.'s model with no slip jump,
/// `S = band`, `J = 0`.
///
/// Checked against a plain play (dead band) model in `tests/plant_sim.rs`: while the command
/// travels one way the valve follows `band / 2` behind it; on a reversal it waits until the command
/// has come back by `band`, then follows `band / 2` behind on the other side; after a stop it
/// resumes at once in the same direction. Once the valve has moved both ways the two are the same
/// sample for sample. Only the start differs: Kano's state begins as if the valve had just stopped
/// moving down with the position equal to the command, so the first downward move jumps by
/// `band / 2` at once. Simulate a warm-up (`ClosedLoop::warmup`) before recording.
pub fn backlash(band: f64) -> Model {
    Model::Kano(Kano { s: band, j: 0.0 })
}
