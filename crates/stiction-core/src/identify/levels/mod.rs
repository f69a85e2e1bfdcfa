//! The levels test: does a valve trajectory explain PV's *levels* better than OP does?
//!
//! PV is regressed by least squares on a bank of first-order filters of the valve position (each
//! delayed a sample) and two pure delays, for a level loop also the valve's running sum, beside a
//! piecewise-linear drift (a knot every `KNOT_EVERY` samples). The regressors hold only valve
//! positions from before each PV sample and the drift is smooth, so PV's measurement noise, which
//! the controller feeds back into OP at once, cannot favour OP, and the fit has no PV past among
//! its regressors (an ARX fit's bias towards the valve that follows OP).
//!
//! The residual is not white (load drift between the knots, an external cycle), so the fit is a
//! generalised least squares: an AR noise model of order `AR_ORDER`, estimated on the residual
//! with OP, whitens PV and every column. The log-likelihood ratio
//! `n/2 ln(SSE with OP / SSE with the valve)` then counts a coloured residual as fewer independent
//! samples, and an external cycle or a slow drift no longer passes for the valve.
//!
//! [`levels_walk`] scores every distinct Stenman valve trajectory from OP (the exact partition of
//! the band's range) and keeps the best; then He's valve (a slip that lands short of OP, as
//! Kano's slip jump below the band) at a few bands and landings around it. On the calibration
//! set the He valves found 15 more of the 240 sticky routine loops and 12 more of the 90 fast
//! ones, and one more of 159 healthy routine loops and one of 136 fast ones reached 50. It costs a fit per trajectory (a few thousand on 2,000
//! samples; the walk runs in fixed chunks in parallel, and its result is the walk in order's, on
//! any number of threads), so `diagnose` runs it only when asked (`thorough`).

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

use crate::estimate::exact::stenman_walk;
use crate::models::{He, Model};

mod linalg;
#[cfg(test)]
mod tests;
mod walk;

use linalg::*;
pub use walk::{levels_walk, LevelsWalk};

/// Time constants of the filter bank, samples.
const TAUS: [f64; 6] = [0.5, 2.0, 6.0, 18.0, 54.0, 160.0];
/// Pure delays of the bank, samples.
const DELAYS: [usize; 2] = [3, 8];
/// Samples between the drift's knots.
const KNOT_EVERY: usize = 150;
/// A filter bank: first-order filters (time constants, samples) and pure delays (samples).
#[derive(Debug, Clone, Copy)]
pub struct Bank<'a> {
    /// Time constants of the first-order filters, samples.
    pub taus: &'a [f64],
    /// Pure delays, samples.
    pub delays: &'a [usize],
}

/// The bank the levels test uses.
pub const BANK: Bank<'static> = Bank {
    taus: &TAUS,
    delays: &DELAYS,
};
/// Order of the AR noise model.
const AR_ORDER: usize = 4;
/// The smallest residual a fit reports, share of PV's sum of squares (the arithmetic's
/// resolution: below it two fits are alike).
const SSE_FLOOR: f64 = 1e-9;
/// Fewest samples the test runs on.
const MIN_SAMPLES: usize = 200;

/// One record's PV, whitened, with its drift projected out.
pub struct LevelsFit {
    integrating: bool,
    taus: Vec<f64>,
    delays: Vec<usize>,
    /// The whitening filter `A(q)`: coefficients of lags 1.. (empty: white noise).
    ar: Vec<f64>,
    /// Orthonormal basis of the (whitened) drift: a constant and hinges at the knots.
    drift: Vec<Vec<f64>>,
    /// PV, whitened, with the drift projected out, and its sum of squares.
    y: Vec<f64>,
    yy: f64,
}

/// Buffers reused from one valve trajectory to the next.
pub struct Scratch {
    cols: Vec<Vec<f64>>,
    u: Vec<f64>,
}

impl LevelsFit {
    /// The fit on `pv`, its noise model estimated on the residual with `op` as the valve.
    pub fn new(pv: &[f64], op: &[f64], integrating: bool) -> Self {
        let plain = Self::plain(pv, integrating, BANK);
        let mut scratch = plain.scratch();
        let r = plain.residual(op, &mut scratch);
        let ar = ar_fit(&r, AR_ORDER);
        Self::with_noise(pv, integrating, BANK, ar)
    }

    /// The fit with white noise (no AR model) on a bank of one's own: the plain output-error
    /// test of the model-family studies (`model_ceiling`, `clean_walk`, `sampled_valve`).
    pub fn plain(pv: &[f64], integrating: bool, bank: Bank) -> Self {
        Self::with_noise(pv, integrating, bank, Vec::new())
    }

    fn with_noise(pv: &[f64], integrating: bool, bank: Bank, ar: Vec<f64>) -> Self {
        let n = pv.len();
        let knots = (n / KNOT_EVERY).max(2);
        let mut cols = vec![vec![1.0; n]];
        for k in 0..knots {
            let at = k * n / knots;
            cols.push(
                (0..n)
                    .map(|t| t.saturating_sub(at) as f64 / n as f64)
                    .collect(),
            );
        }
        for c in cols.iter_mut() {
            whiten(&ar, c);
        }
        let drift = orthonormal(cols);
        let mut y = pv.to_vec();
        whiten(&ar, &mut y);
        project_out(&drift, &mut y);
        let yy = dot(&y, &y);
        Self {
            integrating,
            taus: bank.taus.to_vec(),
            delays: bank.delays.to_vec(),
            ar,
            drift,
            y,
            yy,
        }
    }

    /// Buffers for [`Self::sse`].
    pub fn scratch(&self) -> Scratch {
        let n = self.y.len();
        let p = self.taus.len() + self.delays.len() + usize::from(self.integrating);
        Scratch {
            cols: vec![vec![0.0; n]; p],
            u: vec![0.0; n],
        }
    }

    /// Residual sum of squares of PV explained by `valve` (beside the drift).
    pub fn sse(&self, valve: &[f64], s: &mut Scratch) -> f64 {
        self.columns(valve, s);
        for c in s.cols.iter_mut() {
            project_out(&self.drift, c);
        }
        let (a, b) = gram(&s.cols, &self.y);
        // a fit cannot explain PV past the arithmetic's resolution (a level loop's running
        // sum is large beside what is left of PV)
        (self.yy - explained(a, &b)).max(SSE_FLOOR * self.yy)
    }

    /// The log-likelihood ratio `n/2 ln(sse_op / sse)`.
    pub fn ratio(&self, sse_op: f64, sse: f64) -> f64 {
        self.y.len() as f64 / 2.0 * (sse_op / sse.max(f64::MIN_POSITIVE)).ln()
    }

    /// PV's residual after the least-squares fit on `valve`'s columns.
    fn residual(&self, valve: &[f64], s: &mut Scratch) -> Vec<f64> {
        self.columns(valve, s);
        for c in s.cols.iter_mut() {
            project_out(&self.drift, c);
        }
        let (a, b) = gram(&s.cols, &self.y);
        let beta = solve(a, &b);
        let mut r = self.y.clone();
        for (c, w) in s.cols.iter().zip(&beta) {
            for (x, v) in r.iter_mut().zip(c) {
                *x -= w * v;
            }
        }
        r
    }

    /// The bank's columns of `valve` (centred), whitened, into `s.cols`.
    fn columns(&self, valve: &[f64], s: &mut Scratch) {
        let n = valve.len();
        let mean = valve.iter().sum::<f64>() / n as f64;
        for (u, v) in s.u.iter_mut().zip(valve) {
            *u = v - mean;
        }
        let u = &s.u;
        let mut k = 0;
        for &tau in &self.taus {
            let a = (-1.0f64 / tau).exp();
            let c = &mut s.cols[k];
            let mut state = u[0];
            c[0] = 0.0;
            for t in 1..n {
                c[t] = state;
                state = a * state + (1.0 - a) * u[t];
            }
            k += 1;
        }
        for &d in &self.delays {
            let c = &mut s.cols[k];
            for t in 0..n {
                c[t] = if t >= d { u[t - d] } else { 0.0 };
            }
            k += 1;
        }
        if self.integrating {
            let c = &mut s.cols[k];
            let mut sum = 0.0;
            for t in 0..n {
                c[t] = sum;
                sum += u[t];
            }
        }
        for c in s.cols.iter_mut() {
            whiten(&self.ar, c);
        }
    }
}
