//! Spectral tools for stiction diagnosis: FFT-based correlation functions, a zero-phase band-pass
//! filter and the bicoherence test of non-Gaussianity and non-linearity.
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

// `!(x > 0.0)` and the like are deliberate: they reject NaN along with the out-of-range values.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

use rustfft::num_complex::Complex;
use rustfft::{Fft, FftPlanner};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
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

// ---------------------------------------------------------------------------------------------
// Bicoherence

/// Settings of the bicoherence test (defaults from Choudhury, Shah and Thornhill 2004, 2008).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BicoherenceSettings {
    /// Samples per segment M (the FFT length). Default 128.
    pub segment_length: usize,
    /// Fraction of a segment shared with the next one, clamped to `[0, 0.9]`. Default 0.5.
    pub overlap: f64,
    /// Critical value of the chi-square distribution with 2 degrees of freedom: 5.99 is the 95 %
    /// point. A squared bicoherence is significant when it exceeds `alpha_chi2 / (2K)`.
    pub alpha_chi2: f64,
    /// The signal is non-Gaussian when NGI exceeds this. Default 0.001.
    pub ngi_threshold: f64,
    /// A non-Gaussian signal is non-linear when NLI exceeds this. Default 0.01.
    pub nli_threshold: f64,
}

impl Default for BicoherenceSettings {
    fn default() -> Self {
        Self {
            segment_length: 128,
            overlap: 0.5,
            alpha_chi2: 5.99,
            ngi_threshold: 0.001,
            nli_threshold: 0.01,
        }
    }
}

/// Result of the bicoherence test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bicoherence {
    /// Non-Gaussianity index (see [`bicoherence`]).
    pub ngi: f64,
    /// Non-linearity index (see [`bicoherence`]).
    pub nli: f64,
    /// Total non-linearity index: the sum of the significant squared bicoherence.
    pub tnli: f64,
    pub ngi_threshold: f64,
    pub nli_threshold: f64,
    /// Number of segments K averaged.
    pub segments: usize,
    /// Segment length M used (may be smaller than requested for short records).
    pub segment_length: usize,
    /// Bifrequency (f1, f2) of the largest squared bicoherence, cycles per sample.
    pub peak: [f64; 2],
    /// The largest squared bicoherence.
    pub peak_value: f64,
    pub non_gaussian: bool,
    pub non_linear: bool,
}

/// Fewest segments the bicoherence estimate is averaged over.
pub const MIN_SEGMENTS: usize = 4;
/// Shortest segment a short record may fall back to.
const MIN_FALLBACK_SEGMENT: usize = 64;
/// Shortest segment accepted at all (fewer bins leave too few bifrequencies).
const MIN_SEGMENT: usize = 16;
/// Fraction of the squared bicoherence values trimmed from each end for the robust statistics.
const TRIM: f64 = 0.1;
/// Denominator floor relative to its largest value: bins with only rounding-level power must not
/// produce bicoherence near 1 (or 0/0).
const DENOMINATOR_FLOOR: f64 = 1e-20;

/// Squared bicoherence over the principal domain, with the bookkeeping the indices need.
struct BicoherenceMap {
    /// (f1, f2) in bins and bic² for every bifrequency of the principal domain.
    values: Vec<(usize, usize, f64)>,
    segments: usize,
    segment_length: usize,
}

fn segment_count(n: usize, m: usize, overlap: f64) -> (usize, usize) {
    let step = ((m as f64 * (1.0 - overlap)).round() as usize).max(1);
    let k = if n >= m { (n - m) / step + 1 } else { 0 };
    (k, step)
}

fn bicoherence_map(x: &[f64], s: &BicoherenceSettings) -> Option<BicoherenceMap> {
    let n = x.len();
    let overlap = if s.overlap.is_finite() {
        s.overlap.clamp(0.0, 0.9)
    } else {
        0.0
    };
    let mut m = s.segment_length;
    if m < MIN_SEGMENT || x.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let centre = mean(x);
    let spread = x.iter().fold(0.0f64, |a, v| a.max((v - centre).abs()));
    if !(spread > 1e-12 * centre.abs()) {
        return None; // constant (to rounding): no spectrum to test
    }
    let (mut k, mut step) = segment_count(n, m, overlap);
    if k < MIN_SEGMENTS && m > MIN_FALLBACK_SEGMENT {
        m = MIN_FALLBACK_SEGMENT;
        (k, step) = segment_count(n, m, overlap);
    }
    if k < MIN_SEGMENTS {
        return None;
    }
    let half = m / 2;
    // principal domain: 0 < f2 <= f1, f1 + f2 < M/2 (bins)
    let pairs: Vec<(usize, usize)> = (1..half)
        .flat_map(|f1| (1..=f1.min(half - 1 - f1)).map(move |f2| (f1, f2)))
        .collect();
    if pairs.is_empty() {
        return None;
    }
    let window: Vec<f64> = (0..m)
        .map(|i| 0.5 * (1.0 - (TAU * i as f64 / m as f64).cos()))
        .collect();
    let fft = forward(m);
    let mut scratch = vec![Complex::new(0.0, 0.0); fft.get_inplace_scratch_len()];
    let mut buf = vec![Complex::new(0.0, 0.0); m];
    let mut bispectrum = vec![Complex::new(0.0, 0.0); pairs.len()];
    let mut power12 = vec![0.0; pairs.len()];
    let mut power = vec![0.0; half];
    for seg in 0..k {
        // removing each segment's mean also removes the record's
        let xs = &x[seg * step..seg * step + m];
        let sm = mean(xs);
        for ((b, &v), &w) in buf.iter_mut().zip(xs).zip(&window) {
            *b = Complex::new((v - sm) * w, 0.0);
        }
        fft.process_with_scratch(&mut buf, &mut scratch);
        for (p, b) in power.iter_mut().zip(&buf) {
            *p += b.norm_sqr();
        }
        for ((&(f1, f2), bs), p12) in pairs.iter().zip(&mut bispectrum).zip(&mut power12) {
            let x12 = buf[f1] * buf[f2];
            *bs += x12 * buf[f1 + f2].conj();
            *p12 += x12.norm_sqr();
        }
    }
    let denominators = pairs
        .iter()
        .zip(&power12)
        .map(|(&(f1, f2), p12)| p12 * power[f1 + f2]);
    let floor = DENOMINATOR_FLOOR * denominators.clone().fold(0.0, f64::max) + f64::MIN_POSITIVE;
    let values = pairs
        .iter()
        .zip(&bispectrum)
        .zip(denominators)
        .map(|((&(f1, f2), bs), d)| (f1, f2, (bs.norm_sqr() / (d + floor)).clamp(0.0, 1.0)))
        .collect();
    Some(BicoherenceMap {
        values,
        segments: k,
        segment_length: m,
    })
}

/// Mean and standard deviation of `v` after dropping the largest and smallest `TRIM` fraction.
fn robust_mean_std(v: &mut [f64]) -> (f64, f64) {
    v.sort_by(f64::total_cmp);
    let cut = (TRIM * v.len() as f64).floor() as usize;
    let kept = if v.len() > 2 * cut + 1 {
        &v[cut..v.len() - cut]
    } else {
        &v[..]
    };
    let m = mean(kept);
    let var = kept.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (kept.len().max(2) - 1) as f64;
    (m, var.sqrt())
}

/// Bicoherence test of non-Gaussianity and non-linearity (Choudhury, Shah and Thornhill 2004,
/// Automatica 40; book 2008), for the control error or PV of an oscillating loop: a sticky valve
/// makes the oscillation's harmonics phase-coupled, which a linear loop driven by Gaussian noise
/// cannot do.
///
/// Squared bicoherence by the direct (segment-averaging) method: the signal is cut into K
/// segments of M samples overlapping by `overlap`; each is made mean-free, Hann-windowed and
/// transformed; over the principal domain (0 < f2 <= f1, f1 + f2 < M/2 bins, no DC)
///
/// `bic²(f1,f2) = |Σ_k X_k(f1) X_k(f2) X_k*(f1+f2)|² / (Σ_k |X_k(f1) X_k(f2)|² Σ_k |X_k(f1+f2)|²)`,
///
/// which Cauchy-Schwarz keeps in [0, 1]; a floor 1e-20 times the largest denominator is added
/// so bins holding only rounding errors cannot give spurious values near 1 (or 0/0). For a
/// Gaussian signal `2K bic²` is asymptotically chi-square with 2 degrees of freedom, so `bic²` is
/// significant when it exceeds `c = alpha_chi2 / (2K)`.
///
/// Indices, with N the number of significant bifrequencies:
/// - NGI = (mean of the significant bic²) − c − (1 + 2/√N)/K; 0 if none is significant.
///   Choudhury et al. subtract only `c`, but under the chi-square law the significant values of
///   a Gaussian signal average `c + 1/K` (the excess of an exponential over a threshold is again
///   exponential), so with `c` alone white noise always scores NGI ≈ 1/K (0.016 for 4096
///   samples), far above the 0.001 threshold. Subtracting `1/K` centres NGI on 0 for Gaussian
///   signals and `2/(K√N)`, two standard errors of that mean, keeps chance fluctuations below the
///   threshold. Non-Gaussian when NGI > `ngi_threshold`.
/// - NLI = |bic²_max − (robust mean + 2 robust std of bic²)| (Choudhury et al. 2004), the robust
///   statistics over the whole principal domain without its largest and smallest 10 %
///   (standard deviation with n − 1). Non-linear when non-Gaussian and NLI > `nli_threshold`.
/// - TNLI = Σ significant bic² (total non-linearity index), a measure of how much
///   non-linearity there is.
///
/// A record too short for [`MIN_SEGMENTS`] segments of `segment_length` samples is retried with
/// 64-sample segments; `None` if it is still too short, if `segment_length < 16`, if the signal
/// holds non-finite values or is constant.
///
/// Caveat (of the segment-averaging estimator, not of this code): a sinusoid whose frequency is a
/// multiple of 1 / step (or very close to one; step = 64 samples with the defaults, so periods of
/// 64, 32, 21.3, ... samples) has the same phase in every segment, and the window's leakage into
/// the neighbouring bins then looks phase-coupled: bic² near 1 even from a linear loop. Noise
/// does not help (a unit sine of period 64 under noise of standard deviation 0.1 is flagged).
pub fn bicoherence(x: &[f64], s: &BicoherenceSettings) -> Option<Bicoherence> {
    let map = bicoherence_map(x, s)?;
    let mut values: Vec<f64> = map.values.iter().map(|v| v.2).collect();
    let (mut peak, mut peak_value) = ([0.0; 2], -1.0);
    for &(f1, f2, b) in &map.values {
        if b > peak_value {
            peak_value = b;
            let m = map.segment_length as f64;
            peak = [f1 as f64 / m, f2 as f64 / m];
        }
    }
    let k = map.segments as f64;
    let critical = s.alpha_chi2 / (2.0 * k);
    let (count, tnli) = values
        .iter()
        .filter(|&&b| b > critical)
        .fold((0usize, 0.0), |(c, t), &b| (c + 1, t + b));
    let ngi = if count > 0 {
        let n = count as f64;
        tnli / n - critical - (1.0 + 2.0 / n.sqrt()) / k
    } else {
        0.0
    };
    let (rm, rs) = robust_mean_std(&mut values);
    let nli = (peak_value - (rm + 2.0 * rs)).abs();
    let non_gaussian = ngi > s.ngi_threshold;
    Some(Bicoherence {
        ngi,
        nli,
        tnli,
        ngi_threshold: s.ngi_threshold,
        nli_threshold: s.nli_threshold,
        segments: map.segments,
        segment_length: map.segment_length,
        peak,
        peak_value,
        non_gaussian,
        non_linear: non_gaussian && nli > s.nli_threshold,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::{Model, Stenman};
    use crate::rng::{gaussian, seeded};
    use crate::sim::{ClosedLoop, LoopData, Signal};

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

    #[test]
    fn white_noise_is_not_non_linear() {
        let s = BicoherenceSettings::default();
        let flagged = (0..20)
            .filter(|&seed| bicoherence(&white(4096, seed), &s).unwrap().non_linear)
            .count();
        assert!(
            flagged <= 2,
            "{flagged} of 20 white-noise records flagged non-linear"
        );
    }

    #[test]
    fn quadratic_phase_coupling_is_non_linear() {
        let s = BicoherenceSettings::default();
        let noise = white(4096, 7);
        let x: Vec<f64> = (0..4096)
            .map(|t| {
                let t = t as f64;
                let v = (TAU * 0.06 * t).sin() + 0.8 * (TAU * 0.11 * t + 1.0).sin();
                v + 0.5 * v * v + 0.1 * noise[t as usize]
            })
            .collect();
        let b = bicoherence(&x, &s).unwrap();
        assert!(b.non_gaussian && b.non_linear, "{b:?}");
        assert!(b.peak_value > 0.9, "{b:?}");
        assert_eq!((b.segments, b.segment_length), (63, 128));
    }

    fn sticky_loop(d: f64, disturbance: Option<Signal>, seed: u64) -> LoopData {
        let mut cl = ClosedLoop::new(Model::Stenman(Stenman::new(d).unwrap()));
        cl.samples = 4096;
        cl.noise = 0.1;
        cl.seed = seed;
        cl.disturbance = disturbance;
        cl.run().unwrap()
    }

    fn control_error(data: &LoopData) -> Vec<f64> {
        // drop the start-up (the setpoint step at 10 s)
        data.sp
            .iter()
            .zip(&data.pv)
            .skip(200)
            .map(|(sp, pv)| sp - pv)
            .collect()
    }

    #[test]
    fn a_sticky_valve_limit_cycle_is_non_linear() {
        let s = BicoherenceSettings::default();
        for seed in 0..3 {
            let b = bicoherence(&control_error(&sticky_loop(2.0, None, seed)), &s).unwrap();
            assert!(b.non_linear, "seed {seed}: {b:?}");
        }
    }

    #[test]
    fn a_linear_loop_with_a_sinusoidal_disturbance_is_not() {
        let s = BicoherenceSettings::default();
        for (seed, period) in [(0, 50.0), (1, 100.0), (2, 37.0)] {
            let sine = Signal::Sine {
                amplitude: 1.0,
                period,
                offset: 0.0,
            };
            let b = bicoherence(&control_error(&sticky_loop(0.0, Some(sine), seed)), &s).unwrap();
            assert!(!b.non_linear, "seed {seed}, period {period}: {b:?}");
        }
    }

    #[test]
    fn bicoherence_degrades_gracefully_on_short_or_flat_records() {
        let s = BicoherenceSettings::default();
        // too short for 4 segments of 128 but enough for 64
        let b = bicoherence(&white(300, 1), &s).unwrap();
        assert_eq!((b.segment_length, b.segments), (64, 8));
        assert!(bicoherence(&white(150, 1), &s).is_none());
        assert!(bicoherence(&[], &s).is_none());
        assert!(bicoherence(&[4.2; 4096], &s).is_none());
        let mut x = white(4096, 2);
        x[100] = f64::NAN;
        assert!(bicoherence(&x, &s).is_none());
        let odd = BicoherenceSettings {
            segment_length: 8,
            ..s
        };
        assert!(bicoherence(&white(4096, 3), &odd).is_none());
        let odd = BicoherenceSettings {
            overlap: f64::NAN,
            ..s
        };
        assert_eq!(bicoherence(&white(4096, 3), &odd).unwrap().segments, 32);
    }
}
