//! Signals and loop simulation: open-loop command signals through a valve, and a closed PI loop
//! with a sticky valve, a process (first order, integrating or two lags, with dead time) and
//! measurement noise; around it the plant features routine historian data show (a controller
//! faster than the historian, actuator lag, installed characteristic, load and output
//! disturbances, quantisation, historian compression, a cascade).

mod closed_loop;
mod historian;
mod process;
mod signal;
mod stepping;
mod valve;

pub use closed_loop::{Cascade, ClosedLoop, LoopRun, Pi};
pub use historian::{
    Compression, CompressionMethod, Historian, Quantisation, QuantiseAt, Reconstruction,
};
pub use process::{Process, ProcessState};
pub use signal::Signal;
pub use stepping::Plan;
pub use valve::{backlash, Characteristic, ValveLag};

use crate::models::Model;
use crate::rng::{gaussian, seeded};
use serde::{Deserialize, Serialize};

/// A simulation setting out of range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A setting breaks its rule.
    #[error("{what} must be {rule}, got {value}")]
    Invalid {
        /// The setting, in words.
        what: &'static str,
        /// What it must be.
        rule: &'static str,
        /// The value given.
        value: f64,
    },
}

pub(crate) fn require(
    ok: bool,
    what: &'static str,
    rule: &'static str,
    value: f64,
) -> Result<(), SimError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(SimError::Invalid { what, rule, value })
    }
}

/// A simulated loop, one value per sample: time, setpoint, controller output, valve position,
/// process variable. Open-loop runs have no setpoint and no process: `sp` and `pv` are empty.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LoopData {
    /// Time of each sample, seconds.
    pub t: Vec<f64>,
    /// Setpoint (empty open loop).
    pub sp: Vec<f64>,
    /// Controller output: the valve's command, % of valve span.
    pub op: Vec<f64>,
    /// Valve position, % of valve span.
    pub mv: Vec<f64>,
    /// Process variable (empty open loop).
    pub pv: Vec<f64>,
}

/// Drive a valve open loop with a command signal. `mv` is the valve position as measured: the
/// model's output plus Gaussian noise of standard deviation `noise` (seeded). An open loop has no
/// setpoint and no process: `sp` and `pv` are empty.
pub fn simulate_open_loop(
    model: &Model,
    command: &Signal,
    ts: f64,
    samples: usize,
    noise: f64,
    seed: u64,
) -> Result<LoopData, SimError> {
    command.validate()?;
    require(ts > 0.0, "the sampling time ts", "> 0 seconds", ts)?;
    require(noise >= 0.0, "noise", ">= 0", noise)?;
    let op = command.generate(ts, samples);
    let mut mv = model.simulate(&op);
    if noise > 0.0 {
        let mut rng = seeded(seed);
        for x in &mut mv {
            *x += noise * gaussian(&mut rng);
        }
    }
    Ok(LoopData {
        t: (0..samples).map(|k| k as f64 * ts).collect(),
        sp: Vec::new(),
        op,
        mv,
        pv: Vec::new(),
    })
}
