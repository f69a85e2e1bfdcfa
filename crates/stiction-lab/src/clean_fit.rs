//! A plain output-error test of "does this valve trajectory explain PV better than OP does?",
//! shared by the model-family studies (`model_ceiling`, `clean_walk`, `sampled_valve`).
//!
//! PV on its levels is regressed by least squares on a bank of first-order filters of the valve
//! position (each delayed a sample) and pure delays, for a level loop also the valve's running
//! sum, beside a piecewise-linear drift: `stiction_core::identify::levels` with white noise (the
//! levels test `diagnose --thorough` runs adds an AR noise model), on the study's own bank.

use std::cell::RefCell;
use stiction_core::identify::levels::{LevelsFit, Scratch};

pub use stiction_core::identify::levels::Bank;

/// One record's PV with its drift projected out.
pub struct CleanFit {
    fit: LevelsFit,
    scratch: RefCell<Scratch>,
}

impl CleanFit {
    pub fn new(pv: &[f64], integrating: bool, bank: Bank<'static>) -> Self {
        let fit = LevelsFit::plain(pv, integrating, bank);
        let scratch = RefCell::new(fit.scratch());
        Self { fit, scratch }
    }

    /// Residual sum of squares of PV explained by `valve` (beside the drift).
    pub fn sse(&self, valve: &[f64]) -> f64 {
        self.fit.sse(valve, &mut self.scratch.borrow_mut())
    }

    /// The log-likelihood ratio `n/2 ln(SSE with OP / SSE with the valve)`, given OP's SSE.
    pub fn llr(&self, with_op: f64, valve: &[f64]) -> f64 {
        self.fit.ratio(with_op, self.sse(valve))
    }
}
