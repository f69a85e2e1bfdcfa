//! Spectral tools for stiction diagnosis: FFT-based correlation functions and a zero-phase
//! band-pass filter.
//!
//! - Correlations are computed through zero-padded FFTs (O(n log n)), so a whole record of
//!   routine data costs milliseconds; they equal the direct sums to rounding.
//! - [`band_pass`] is the frequency-domain "Wiener" filter of Choudhury, Shah and Thornhill
//!   (2004, 2008): every Fourier coefficient outside the band is set to zero. It has no phase
//!   shift, which the PV-OP plot needs (a causal filter would distort the ellipse).

// `!(x > 0.0)` and the like are deliberate: they reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

fn mean(x: &[f64]) -> f64 {
    if x.is_empty() {
        0.0
    } else {
        x.iter().sum::<f64>() / x.len() as f64
    }
}

fn forward(n: usize) -> Arc<dyn Fft<f64>> {
    FftPlanner::new().plan_fft_forward(n)
}

/// Unnormalised inverse transform with the forward plan (`conj ∘ FFT ∘ conj`), so each call
/// plans once.
fn inverse_with(fft: &dyn Fft<f64>, buf: &mut [Complex<f64>]) {
    for c in buf.iter_mut() {
        *c = c.conj();
    }
    fft.process(buf);
    for c in buf.iter_mut() {
        *c = c.conj();
    }
}

/// Mean-free copy of `x`, zero-padded to `len`, as complex numbers.
fn centred_padded(x: &[f64], len: usize) -> Vec<Complex<f64>> {
    let m = mean(x);
    let mut buf = vec![Complex::new(0.0, 0.0); len];
    for (b, &v) in buf.iter_mut().zip(x) {
        b.re = v - m;
    }
    buf
}

// ---------------------------------------------------------------------------------------------
// Correlation functions

/// Autocorrelation of the mean-free `x` for lags `0..=max_lag.min(n - 1)`: the biased estimator
/// `r(k) = Σ_t c[t] c[t+k] / Σ_t c[t]²` (c = x - mean), so `r(0) = 1`.
///
/// Computed by FFT (Wiener-Khinchin) on a copy zero-padded to at least `n + max_lag` samples,
/// so no lag wraps around: the result equals the direct O(n²) sum to rounding. A constant signal
/// (zero variance) gives all zeros, an empty one an empty vector.
pub fn autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let lags = max_lag.min(n - 1);
    let len = (n + lags).next_power_of_two();
    let mut buf = centred_padded(x, len);
    let var: f64 = buf[..n].iter().map(|c| c.re * c.re).sum();
    if !(var > 0.0) || !var.is_finite() {
        return vec![0.0; lags + 1];
    }
    let fft = forward(len);
    fft.process(&mut buf);
    for c in &mut buf {
        *c = Complex::new(c.norm_sqr(), 0.0);
    }
    inverse_with(&*fft, &mut buf);
    let scale = 1.0 / (len as f64 * var);
    let mut r: Vec<f64> = buf[..=lags].iter().map(|c| c.re * scale).collect();
    r[0] = 1.0;
    r
}

/// Cross-correlation of the mean-free `a` and `b` for lags `-L..=L` with `L = max_lag.min(n-1)`:
/// element `L + k` is `Σ_t a[t] b[t+k] / sqrt(Σ a² Σ b²)` (means removed; the biased estimator,
/// i.e. normalised by `n sqrt(var_a var_b)`), so a positive lag `k` means `b` follows `a` by `k`
/// samples. Signals of different lengths use their first `n = min(len_a, len_b)` samples.
///
/// FFT-based on zero-padded copies (no circular wrap); equals the direct sum to rounding. All
/// zeros if either signal is constant, empty if either is empty.
pub fn cross_correlation(a: &[f64], b: &[f64], max_lag: usize) -> Vec<f64> {
    let n = a.len().min(b.len());
    if n == 0 {
        return Vec::new();
    }
    let (a, b) = (&a[..n], &b[..n]);
    let lags = max_lag.min(n - 1);
    let len = (n + lags).next_power_of_two();
    let mut fa = centred_padded(a, len);
    let mut fb = centred_padded(b, len);
    let va: f64 = fa[..n].iter().map(|c| c.re * c.re).sum();
    let vb: f64 = fb[..n].iter().map(|c| c.re * c.re).sum();
    let norm = (va * vb).sqrt();
    if !(norm > 0.0) || !norm.is_finite() {
        return vec![0.0; 2 * lags + 1];
    }
    let fft = forward(len);
    fft.process(&mut fa);
    fft.process(&mut fb);
    // Σ_t a[t] b[t+k] is the inverse transform of conj(A) B at index k (mod len)
    for (x, y) in fa.iter_mut().zip(&fb) {
        *x = x.conj() * y;
    }
    inverse_with(&*fft, &mut fa);
    let scale = 1.0 / (len as f64 * norm);
    (0..=2 * lags)
        .map(|i| {
            let idx = if i >= lags { i - lags } else { len + i - lags };
            fa[idx].re * scale
        })
        .collect()
}

// ---------------------------------------------------------------------------------------------
// Band-pass filter

/// Zero-phase band-pass filter (Choudhury's frequency-domain "Wiener" filter): remove the mean,
/// transform, set every Fourier coefficient whose frequency lies outside `[low, high]` (cycles
/// per sample, 0..0.5, mirrored for the negative frequencies) to zero, transform back.
///
/// To avoid the end effects of treating the record as periodic, the record is extended by its
/// mirror image (x followed by x reversed, length 2n, period 2n): the extension is continuous at
/// both ends, so a record that does not hold a whole number of periods does not leak a jump into
/// the band. Returns the filtered signal, same length as `x`; all zeros if the band is empty
/// (`low > high` after clamping to `[0, 0.5]`, or not a number).
pub fn band_pass(x: &[f64], low: f64, high: f64) -> Vec<f64> {
    let n = x.len();
    let (low, high) = (low.max(0.0), high.min(0.5));
    if n < 2 || !(low <= high) {
        return vec![0.0; n];
    }
    let len = 2 * n;
    let m = mean(x);
    let mut buf: Vec<Complex<f64>> = x
        .iter()
        .chain(x.iter().rev())
        .map(|&v| Complex::new(v - m, 0.0))
        .collect();
    let fft = forward(len);
    fft.process(&mut buf);
    for (j, c) in buf.iter_mut().enumerate() {
        let f = j.min(len - j) as f64 / len as f64;
        if f < low || f > high {
            *c = Complex::new(0.0, 0.0);
        }
    }
    inverse_with(&*fft, &mut buf);
    buf[..n].iter().map(|c| c.re / len as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::{gaussian, seeded};
    use std::f64::consts::TAU;

    fn white(n: usize, seed: u64) -> Vec<f64> {
        let mut rng = seeded(seed);
        (0..n).map(|_| gaussian(&mut rng)).collect()
    }

    fn direct_autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
        let m = mean(x);
        let c: Vec<f64> = x.iter().map(|v| v - m).collect();
        let var: f64 = c.iter().map(|v| v * v).sum();
        (0..=max_lag.min(x.len() - 1))
            .map(|k| (0..x.len() - k).map(|t| c[t] * c[t + k]).sum::<f64>() / var)
            .collect()
    }

    fn direct_cross_correlation(a: &[f64], b: &[f64], max_lag: usize) -> Vec<f64> {
        let n = a.len();
        let (ma, mb) = (mean(a), mean(b));
        let ca: Vec<f64> = a.iter().map(|v| v - ma).collect();
        let cb: Vec<f64> = b.iter().map(|v| v - mb).collect();
        let norm =
            (ca.iter().map(|v| v * v).sum::<f64>() * cb.iter().map(|v| v * v).sum::<f64>()).sqrt();
        let lags = max_lag.min(n - 1) as i64;
        (-lags..=lags)
            .map(|k| {
                (0..n as i64)
                    .filter(|&t| t + k >= 0 && t + k < n as i64)
                    .map(|t| ca[t as usize] * cb[(t + k) as usize])
                    .sum::<f64>()
                    / norm
            })
            .collect()
    }

    fn max_diff(a: &[f64], b: &[f64]) -> f64 {
        assert_eq!(a.len(), b.len());
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn autocorrelation_equals_the_direct_sum() {
        for (n, lag, seed) in [(500, 60, 1), (333, 400, 2), (7, 3, 3), (2, 5, 4), (1, 0, 5)] {
            let x: Vec<f64> = white(n, seed).iter().map(|v| 3.0 + 2.0 * v).collect();
            let r = autocorrelation(&x, lag);
            assert_eq!(r.len(), lag.min(n - 1) + 1);
            if n > 1 {
                assert!(max_diff(&r, &direct_autocorrelation(&x, lag)) < 1e-12);
                assert_eq!(r[0], 1.0);
            }
        }
        assert_eq!(autocorrelation(&[2.5; 50], 10), vec![0.0; 11]);
        assert!(autocorrelation(&[], 10).is_empty());
    }

    #[test]
    fn cross_correlation_equals_the_direct_sum_and_its_lag_convention() {
        for (n, lag) in [(400, 50), (37, 100), (2, 1)] {
            let a = white(n, 10);
            let b: Vec<f64> = white(n, 11).iter().map(|v| 1.0 - 0.5 * v).collect();
            let r = cross_correlation(&a, &b, lag);
            assert_eq!(r.len(), 2 * lag.min(n - 1) + 1);
            assert!(max_diff(&r, &direct_cross_correlation(&a, &b, lag)) < 1e-12);
        }
        // b follows a by 5 samples: the peak is at lag +5
        let a = white(300, 12);
        let b: Vec<f64> = (0..300)
            .map(|t| if t >= 5 { a[t - 5] } else { 0.0 })
            .collect();
        let r = cross_correlation(&a, &b, 20);
        let best = (0..r.len()).max_by(|&i, &j| r[i].total_cmp(&r[j])).unwrap();
        assert_eq!(best, 20 + 5);
        assert_eq!(cross_correlation(&a, &[1.0; 300], 3), vec![0.0; 7]);
        assert!(cross_correlation(&a, &[], 3).is_empty());
    }

    /// Amplitude and phase of the sine at frequency `f` (cycles per sample) in `x`, by projection.
    fn sine_component(x: &[f64], f: f64) -> (f64, f64) {
        let (c, s) = x.iter().enumerate().fold((0.0, 0.0), |(c, s), (t, v)| {
            let w = TAU * f * t as f64;
            (c + v * w.cos(), s + v * w.sin())
        });
        let n = x.len() as f64;
        (2.0 * c.hypot(s) / n, c.atan2(s))
    }

    #[test]
    fn band_pass_keeps_the_band_and_removes_the_rest() {
        for (n, phase) in [(1000, 0.3), (1003, 1.2), (517, 2.0)] {
            let slow: Vec<f64> = (0..n)
                .map(|t| (TAU * 0.02 * t as f64 + phase).sin())
                .collect();
            let x: Vec<f64> = (0..n)
                .map(|t| 5.0 + slow[t] + 0.7 * (TAU * 0.2 * t as f64).sin())
                .collect();
            let y = band_pass(&x, 0.01, 0.05);
            assert_eq!(y.len(), n);
            // the slow sine survives with its amplitude and phase...
            let inner = n / 10..n - n / 10;
            let (amp, ph) = sine_component(&y[inner.clone()], 0.02);
            let (_, ph0) = sine_component(&slow[inner.clone()], 0.02);
            assert!((amp - 1.0).abs() < 0.03, "n {n}: amplitude {amp}");
            assert!(
                (ph - ph0).abs() < 0.02,
                "n {n}: phase {ph} instead of {ph0}"
            );
            // ...to within the ringing a brick-wall filter has near the ends
            let err = max_diff(&y[inner.clone()], &slow[inner]);
            assert!(err < 0.1, "n {n}: error {err}");
            // and nothing is left of the fast one
            assert!(sine_component(&y, 0.2).0 < 0.01);
        }
        assert!(band_pass(&[], 0.1, 0.2).is_empty());
        assert_eq!(band_pass(&[3.0], 0.1, 0.2), vec![0.0]);
        assert_eq!(band_pass(&[1.0, 2.0, 3.0, 4.0], 0.3, 0.1), vec![0.0; 4]);
        assert_eq!(band_pass(&[1.0, 2.0, 3.0], f64::NAN, 0.1), vec![0.0; 3]);
    }
}
