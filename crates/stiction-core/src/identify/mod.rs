//! Linear identification of the process from the valve position to the PV: ARX models fitted by
//! least squares, orders and delay chosen by an information criterion, and output-error simulation.
//!
//! ```text
//! y[t] = a_1 y[t-1] + ... + a_na y[t-na] + b_0 mv[t-nk] + ... + b_{nb-1} mv[t-nk-nb+1] + c
//! ```
//!
//! For a self-regulating process `y` is the PV; for an integrating one (level loops) it is the PV's
//! change `pv[t] - pv[t-1]`. Both are centred first (the constant `c` takes up the rest), which keeps
//! the normal equations well conditioned. Every structure of a search is fitted on the same samples,
//! so their criteria compare fairly.

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

use serde::{Deserialize, Serialize};

pub mod levels;
mod output_error;
mod pair;
mod physical;
mod prepared;
mod select;
mod simulate;

use output_error::*;
pub use output_error::{polish_output_error, refine_output_error};
pub use physical::{physical, Physical};
pub(crate) use prepared::costs_from_sums;
pub use prepared::{Prepared, ValveSums};
pub use select::{bic, level_simulation_bic, select, simulation_bic, Selection};
pub use simulate::simulate_pv;
use simulate::*;

/// Which linear structure: family, orders and delay (in samples, `nk >= 1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Structure {
    /// Integrating (the output is the PV's change per sample) rather than self-regulating (the PV).
    pub integrating: bool,
    /// Output lags na (the a coefficients).
    pub na: usize,
    /// Input terms nb (the b coefficients).
    pub nb: usize,
    /// Delay nk, samples (at least 1).
    pub nk: usize,
}

/// The ranges a structure search covers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchRange {
    /// Orders of the output lags tried for self-regulating processes (integrating: `na - 1`).
    pub na: Vec<usize>,
    /// Largest number of input terms tried.
    pub nb_max: usize,
    /// Largest delay tried, samples.
    pub nk_max: usize,
    /// Try self-regulating structures, integrating ones, or both.
    pub self_regulating: bool,
    /// Try integrating structures.
    pub integrating: bool,
}

impl SearchRange {
    /// The default range (na 1 and 2, nb up to 2, both families) with delays up to `nk_max` samples
    /// (at least 1).
    pub fn new(nk_max: usize) -> Self {
        Self {
            na: vec![1, 2],
            nb_max: 2,
            nk_max: nk_max.max(1),
            self_regulating: true,
            integrating: true,
        }
    }

    fn na_max(&self) -> usize {
        self.na.iter().copied().max().unwrap_or(1)
    }

    /// First sample index every structure of the range can use (the integrating family needs one
    /// more sample for the difference).
    pub fn t0(&self) -> usize {
        (self.na_max() + 1).max(self.nk_max + self.nb_max)
    }

    fn structures(&self) -> Vec<Structure> {
        let mut out = Vec::new();
        for integrating in [false, true] {
            if (integrating && !self.integrating) || (!integrating && !self.self_regulating) {
                continue;
            }
            for &na in &self.na {
                let na = if integrating { na - 1 } else { na };
                for nb in 1..=self.nb_max {
                    for nk in 1..=self.nk_max {
                        out.push(Structure {
                            integrating,
                            na,
                            nb,
                            nk,
                        });
                    }
                }
            }
        }
        out
    }
}

/// The signals prepared once: centred output for each family and centred valve position.
pub struct Data<'a> {
    /// The PV as recorded.
    pub pv: &'a [f64],
    /// First sample index the fits use (see [`SearchRange::t0`]).
    pub t0: usize,
    y_level: Vec<f64>,
    y_diff: Vec<f64>,
    mean_level: f64,
    mean_diff: f64,
    /// Smallest error sum of squares the criteria distinguish.
    floor: f64,
}

impl<'a> Data<'a> {
    /// Centre the PV and its change per sample, for fits from sample `t0` on.
    pub fn new(pv: &'a [f64], t0: usize) -> Self {
        let n = pv.len();
        let mean_level = pv.iter().sum::<f64>() / n as f64;
        let mut diff = vec![0.0; n];
        for t in 1..n {
            diff[t] = pv[t] - pv[t - 1];
        }
        let mean_diff = if n > 1 {
            diff[1..].iter().sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        let y_level: Vec<f64> = pv.iter().map(|v| v - mean_level).collect();
        let floor = 1e-10
            * y_level
                .iter()
                .map(|v| v * v)
                .sum::<f64>()
                .max(f64::MIN_POSITIVE);
        Self {
            pv,
            t0,
            floor,
            y_level,
            y_diff: diff.iter().map(|v| v - mean_diff).collect(),
            mean_level,
            mean_diff,
        }
    }

    fn y(&self, integrating: bool) -> &[f64] {
        if integrating {
            &self.y_diff
        } else {
            &self.y_level
        }
    }

    /// Samples used by every fit.
    pub fn used(&self) -> usize {
        self.pv.len().saturating_sub(self.t0)
    }
}

/// A fitted ARX model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    /// The structure fitted.
    pub structure: Structure,
    /// Output coefficients a_1 .. a_na.
    pub a: Vec<f64>,
    /// Input coefficients b_0 .. b_{nb-1}.
    pub b: Vec<f64>,
    /// Constant, in the units of the centred output.
    pub c: f64,
    /// One-step prediction error sum of squares.
    pub sse_one_step: f64,
    /// Simulation (output-error) sum of squares.
    pub sse_simulation: f64,
    /// Sum of squares of the centred output over the samples used (for R²).
    pub sst: f64,
}

impl Fit {
    /// Whether the fitted A(q) is stable (every pole inside the unit circle): an unstable fit's
    /// simulation runs away, and its R² says nothing but that.
    pub fn stable(&self) -> bool {
        match *self.a.as_slice() {
            [] => true,
            [a1] => a1.abs() < 1.0,
            // z^2 - a1 z - a2 (the Jury conditions)
            [a1, a2] => a2.abs() < 1.0 && a1.abs() < 1.0 - a2,
            _ => false,
        }
    }

    /// R² of the one-step prediction.
    pub fn r2_one_step(&self) -> f64 {
        1.0 - self.sse_one_step / self.sst
    }
    /// R² of the simulation (output error).
    pub fn r2_simulation(&self) -> f64 {
        1.0 - self.sse_simulation / self.sst
    }
}

/// Centre the valve position (the constant term absorbs the mean).
pub fn centred(mv: &[f64]) -> Vec<f64> {
    let m = mv.iter().sum::<f64>() / mv.len().max(1) as f64;
    mv.iter().map(|v| v - m).collect()
}

/// Fit one structure by least squares and simulate it. `mv` must be centred (any constant offset
/// works: the constant term takes it up). `None` when the normal equations are singular (e.g. a
/// valve that never moves).
pub fn fit(data: &Data, mv: &[f64], s: Structure) -> Option<Fit> {
    Prepared::new(data, s).fit(mv)
}
