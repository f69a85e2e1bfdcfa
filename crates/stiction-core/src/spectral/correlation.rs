//! Auto- and cross-correlation through zero-padded FFTs.

#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::*;

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
