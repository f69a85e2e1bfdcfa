//! Data-driven stiction models: Stenman, He et al. (2007), Kano et al. (2004), Choudhury et al. (2005).
//!
//! Notation: `op` (u) is the controller output, the valve's command; `mv` (x) is the valve stem
//! position. Both are normally in % of valve span. Every model starts at rest with `x[0] = u[0]`
//! (Kano and Choudhury clamp the command to 0..100 first, so `x[0]` is the clamped command).
//!
//! Each model is a small `Copy` struct of validated parameters implementing [`StictionModel`]:
//! `start` gives the state after the first sample, `step` advances one sample. Simulation into a
//! caller's buffer and the fit error (SSE) are provided on top and never allocate.

use serde::{Deserialize, Serialize};
use std::fmt;

mod choudhury;
mod he;
mod kano;
mod kind;
mod model;
mod stenman;

pub use choudhury::{Choudhury, ChoudhuryState};
pub use he::He;
pub use kano::{Kano, KanoState};
pub use kind::ModelKind;
pub use model::{Model, ModelState};
pub use stenman::Stenman;

/// Errors raised when a model or its parameters are not valid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A model name that is not one of stenman, he, kano, choudhury.
    #[error("unknown model '{0}'; the models are stenman, he, kano, choudhury")]
    UnknownModel(String),
    /// A parameter name the model does not have.
    #[error("model {model} has no parameter '{name}'; its parameters are {known}")]
    UnknownParameter {
        /// The model's name.
        model: &'static str,
        /// The name given.
        name: String,
        /// The model's parameter names, comma-separated.
        known: String,
    },
    /// A parameter the model needs was not given.
    #[error("model {model} needs a value for parameter '{name}' ({description})")]
    MissingParameter {
        /// The model's name.
        model: &'static str,
        /// The parameter's name.
        name: &'static str,
        /// What the parameter is.
        description: &'static str,
    },
    /// A parameter value out of range.
    #[error("parameter {name} = {value} of model {model} is invalid: {why}")]
    InvalidParameter {
        /// The model's name.
        model: &'static str,
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// Why it is invalid.
        why: String,
    },
}

/// One named, bounded parameter of a model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ParamSpec {
    /// The parameter's name as written on a command line (`d`, `fs`, `S`, ...).
    pub name: &'static str,
    /// Its unit (`% of span`).
    pub unit: &'static str,
    /// What it is, in words.
    pub description: &'static str,
    /// Smallest valid value.
    pub min: f64,
    /// Default search range for estimators (the paper searches d in [0.01, 10]).
    pub search: (f64, f64),
}

/// The behaviour every stiction model shares.
pub trait StictionModel: Copy + Send + Sync {
    /// Whatever the recursion carries from one sample to the next.
    type State: Copy;

    /// State after the first sample and the first valve position `x[0]`.
    fn start(&self, u0: f64) -> (Self::State, f64);

    /// Advance one sample with command `u`; returns the valve position.
    fn step(&self, state: &mut Self::State, u: f64) -> f64;

    /// Simulate the valve position for a whole command sequence into `mv` (same length as `op`).
    fn simulate_into(&self, op: &[f64], mv: &mut [f64]) {
        assert_eq!(
            op.len(),
            mv.len(),
            "op and mv buffers must have the same length"
        );
        if op.is_empty() {
            return;
        }
        let (mut state, x0) = self.start(op[0]);
        mv[0] = x0;
        for (x, &u) in mv[1..].iter_mut().zip(&op[1..]) {
            *x = self.step(&mut state, u);
        }
    }

    /// Sum of squared errors between a measured valve position and this model's output.
    fn sse(&self, op: &[f64], mv_measured: &[f64]) -> f64 {
        if op.is_empty() {
            return 0.0;
        }
        let (mut state, x0) = self.start(op[0]);
        let e0 = mv_measured[0] - x0;
        let mut sum = e0 * e0;
        for (&u, &y) in op[1..].iter().zip(&mv_measured[1..]) {
            let e = y - self.step(&mut state, u);
            sum += e * e;
        }
        sum
    }
}

fn check_nonneg(model: &'static str, name: &'static str, value: f64) -> Result<(), ModelError> {
    if !value.is_finite() || value < 0.0 {
        return Err(ModelError::InvalidParameter {
            model,
            name,
            value,
            why: "it must be a finite number >= 0 (in % of valve span)".into(),
        });
    }
    Ok(())
}
