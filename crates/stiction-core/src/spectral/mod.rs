//! Spectral tools for stiction diagnosis: FFT-based correlation functions, a zero-phase band-pass
//! filter, the bicoherence test of non-Gaussianity and non-linearity, and the PV-OP ellipse fit
//! that measures apparent stiction.
//!
//! - Correlations are computed through zero-padded FFTs (O(n log n)), so a whole record of
//!   routine data costs milliseconds; they equal the direct sums to rounding.
//! - [`band_pass`] is the frequency-domain "Wiener" filter of Choudhury, Shah and Thornhill
//!   (2004, 2008): every Fourier coefficient outside the band is set to zero. It has no phase
//!   shift, which the PV-OP plot needs (a causal filter would distort the ellipse).
//! - [`bicoherence`] follows Choudhury, Shah and Thornhill (2004), "Diagnosis of poor control-loop
//!   performance using higher-order statistics", Automatica 40, 1719-1728, and their 2008 book
//!   "Diagnosis of Process Nonlinearities and Valve Stiction" (Springer): a linear loop driven by
//!   Gaussian noise has zero bicoherence; a sticky valve couples the phases of the oscillation's
//!   harmonics, which shows as large squared bicoherence.
//! - [`fit_ellipse`] is the direct least-squares ellipse fit of Fitzgibbon, Pilu and Fisher (1999)
//!   in the numerically stable form of Halíř and Flusser (1998); [`apparent_stiction_ellipse`]
//!   applies it to the band-passed PV-OP plot as Choudhury et al. (2006, 2008) do to quantify
//!   apparent stiction.

// `!(x > 0.0)` and the like are deliberate: they reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::sync::Arc;

mod bicoherence;
mod correlation;
mod ellipse;
mod filter;
mod linalg;
mod spectrum;
#[cfg(test)]
mod tests;

pub(crate) use bicoherence::MIN_SEGMENTS;
pub use bicoherence::{bicoherence, Bicoherence, BicoherenceSettings};
pub use correlation::{autocorrelation, cross_correlation};
pub use ellipse::{apparent_stiction_ellipse, fit_ellipse, Ellipse};
pub use filter::band_pass;
use linalg::*;
pub use spectrum::{harmonic_distortion, welch_psd};

pub(super) fn mean(x: &[f64]) -> f64 {
    if x.is_empty() {
        0.0
    } else {
        x.iter().sum::<f64>() / x.len() as f64
    }
}

/// Plans each thread keeps at most.
const MAX_PLANS: usize = 32;

thread_local! {
    /// Each thread's forward plans by size, each made by a fresh planner (a planner that made
    /// other sizes can share their parts and round differently), so a diagnosis's many transforms
    /// of one size are planned once and every result is the same whatever ran before it.
    static PLANS: std::cell::RefCell<std::collections::HashMap<usize, Arc<dyn Fft<f64>>>> =
        std::cell::RefCell::new(std::collections::HashMap::new());
}

pub(super) fn forward(n: usize) -> Arc<dyn Fft<f64>> {
    PLANS.with(|plans| {
        let mut plans = plans.borrow_mut();
        // a batch of records of many lengths would keep plans without end: start again
        if plans.len() >= MAX_PLANS && !plans.contains_key(&n) {
            plans.clear();
        }
        plans
            .entry(n)
            .or_insert_with(|| FftPlanner::new().plan_fft_forward(n))
            .clone()
    })
}

/// Unnormalised inverse transform with the forward plan (`conj ∘ FFT ∘ conj`), so each call
/// plans once.
pub(super) fn inverse_with(fft: &dyn Fft<f64>, buf: &mut [Complex<f64>]) {
    for c in buf.iter_mut() {
        *c = c.conj();
    }
    fft.process(buf);
    for c in buf.iter_mut() {
        *c = c.conj();
    }
}

/// Mean-free copy of `x`, zero-padded to `len`, as complex numbers.
pub(super) fn centred_padded(x: &[f64], len: usize) -> Vec<Complex<f64>> {
    let m = mean(x);
    let mut buf = vec![Complex::new(0.0, 0.0); len];
    for (b, &v) in buf.iter_mut().zip(x) {
        b.re = v - m;
    }
    buf
}
