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
// Power spectrum and harmonic distortion

/// Welch's averaged periodogram of the mean-free `x`: Hann-windowed segments of `segment`
/// samples (at most `x.len()`), half overlapping. Returns the power at the frequencies
/// `j / segment` cycles per sample, `j = 0..=segment / 2` (one-sided, unnormalised: only ratios
/// are meaningful). Empty when `x` has fewer than 4 samples.
pub fn welch_psd(x: &[f64], segment: usize) -> Vec<f64> {
    let n = x.len();
    let m = segment.min(n);
    if m < 4 {
        return Vec::new();
    }
    let step = (m / 2).max(1);
    let window: Vec<f64> = (0..m)
        .map(|i| 0.5 - 0.5 * (TAU * i as f64 / m as f64).cos())
        .collect();
    let fft = forward(m);
    let mut psd = vec![0.0; m / 2 + 1];
    let mut buf = vec![Complex::new(0.0, 0.0); m];
    let mut start = 0;
    while start + m <= n {
        let seg = &x[start..start + m];
        let mu = mean(seg);
        for ((b, &v), w) in buf.iter_mut().zip(seg).zip(&window) {
            *b = Complex::new((v - mu) * w, 0.0);
        }
        fft.process(&mut buf);
        for (p, c) in psd.iter_mut().zip(&buf) {
            *p += c.norm_sqr();
        }
        start += step;
    }
    psd
}

/// Harmonic distortion of an oscillation of frequency `f0` (cycles per sample): the power in
/// the bands around its harmonics `2 f0 ..= harmonics f0`, less the white-noise floor (the median
/// of the spectrum above the highest band), over the power in the band around `f0` (each band
/// ±0.3 f0 wide), from a Welch spectrum with segments of 8 periods (at least 256
/// samples, at most the record). With `harmonics = 5`, a sinusoid gives about 0, a triangle wave
/// 0.014 (1/81 + 1/625), a square wave 0.15 (1/9 + 1/25). `None` when the record holds fewer
/// than 2 periods, the highest harmonic's band reaches the Nyquist frequency (periods shorter than
/// about `2 harmonics + 1` samples), or the fundamental band is empty.
pub fn harmonic_distortion(x: &[f64], f0: f64, harmonics: usize) -> Option<f64> {
    let n = x.len();
    // every harmonic's band must lie below the Nyquist frequency, or the missing ones would pass
    // for a sinusoid
    if !(f0 > 0.0) || (n as f64) * f0 < 2.0 || (harmonics as f64 + 0.3) * f0 > 0.5 {
        return None;
    }
    let segment = ((8.0 / f0).ceil() as usize).max(256).min(n);
    let psd = welch_psd(x, segment);
    if psd.is_empty() {
        return None;
    }
    let df = 1.0 / segment as f64;
    // white measurement noise is not harmonics: the median of the spectrum above the highest
    // band (where only noise is left) is taken off every harmonic bin
    let top = (harmonics as f64 + 1.0) * f0;
    let mut above: Vec<f64> = psd
        .iter()
        .enumerate()
        .filter(|(j, _)| *j as f64 * df > top)
        .map(|(_, &p)| p)
        .collect();
    let floor = if above.len() >= 8 {
        above.sort_by(f64::total_cmp);
        above[above.len() / 2]
    } else {
        0.0
    };
    let band = |k: f64| -> f64 {
        let (lo, hi) = ((k - 0.3) * f0, (k + 0.3) * f0);
        let floor = if k > 1.0 { floor } else { 0.0 };
        psd.iter()
            .enumerate()
            .filter(|(j, _)| {
                let f = *j as f64 * df;
                f > lo && f < hi && *j > 0
            })
            .map(|(_, p)| (p - floor).max(0.0))
            .sum()
    };
    let fundamental = band(1.0);
    if !(fundamental > 0.0) {
        return None;
    }
    let upper: f64 = (2..=harmonics).map(|k| band(k as f64)).sum();
    Some(upper / fundamental)
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

// ---------------------------------------------------------------------------------------------
// Ellipse fit

/// An ellipse fitted to a PV-OP plot (x = OP, y = PV), in the data's units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Ellipse {
    pub centre: [f64; 2],
    pub semi_major: f64,
    pub semi_minor: f64,
    /// Angle of the major axis from the x (OP) axis, radians, in (−π/2, π/2].
    pub angle: f64,
    /// The chord parallel to x through the centre, `2ab / sqrt(a² sin²α + b² cos²α)`: the apparent
    /// stiction when x is OP (Choudhury et al. 2006).
    pub width_along_x: f64,
    /// Root mean square of the points' (shortest, geometric) distance to the ellipse, data units.
    pub rms_residual: f64,
}

type Mat3 = [[f64; 3]; 3];

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut c = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    c
}

fn transpose(a: &Mat3) -> Mat3 {
    let mut t = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = a[j][i];
        }
    }
    t
}

/// Lower Cholesky factor of a symmetric positive-definite matrix; `None` if a pivot is not
/// clearly positive.
fn cholesky(a: &Mat3) -> Option<Mat3> {
    let scale = a[0][0].abs().max(a[1][1].abs()).max(a[2][2].abs());
    let mut l = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if !(s > 1e-13 * scale) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

/// Inverse of a lower-triangular matrix.
fn lower_inverse(l: &Mat3) -> Mat3 {
    let mut inv = [[0.0; 3]; 3];
    for j in 0..3 {
        inv[j][j] = 1.0 / l[j][j];
        for i in j + 1..3 {
            let s: f64 = (j..i).map(|k| l[i][k] * inv[k][j]).sum();
            inv[i][j] = -s / l[i][i];
        }
    }
    inv
}

/// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations: eigenvalues and the
/// eigenvectors as columns.
fn symmetric_eigen(mut a: Mat3) -> ([f64; 3], Mat3) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _sweep in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let diag = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if !(off > 1e-300 + 1e-16 * diag) {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            // signum(0) = 1: a 45° rotation for equal diagonal entries
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A <- Jᵀ A J and V <- V J: columns of A and V first, then rows p and q of A (p < q)
            for row in a.iter_mut().chain(v.iter_mut()) {
                let (rp, rq) = (row[p], row[q]);
                row[p] = c * rp - s * rq;
                row[q] = s * rp + c * rq;
            }
            let (top, bottom) = a.split_at_mut(q);
            for (ap, aq) in top[p].iter_mut().zip(bottom[0].iter_mut()) {
                let (rp, rq) = (*ap, *aq);
                *ap = c * rp - s * rq;
                *aq = s * rp + c * rq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

/// Inverse of a symmetric positive-definite 3x3 matrix via its Cholesky factor.
fn spd_inverse(a: &Mat3) -> Option<Mat3> {
    let li = lower_inverse(&cholesky(a)?);
    Some(mat_mul(&transpose(&li), &li))
}

/// Direct least-squares ellipse fit (Fitzgibbon, Pilu and Fisher 1999) in the numerically
/// stable form of Halíř and Flusser (1998): minimise the algebraic distance of the conic
/// `A x² + B xy + C y² + D x + E y + F = 0` under the constraint `4AC − B² = 1`, which makes an
/// ellipse the only possible answer, non-iteratively.
///
/// The data are centred and scaled to unit standard deviation first (the scatter matrix of raw
/// PV-OP data in % spans many orders of magnitude), the conic is mapped back. The linear part is
/// eliminated through `T = −S3⁻¹ S2ᵀ`, leaving the 3x3 generalised eigenproblem
/// `(S1 + S2 T) a = λ C a`, solved here as a symmetric one through the Cholesky factor of the
/// reduced scatter matrix (a tiny ridge keeps it definite when the points lie exactly on a
/// conic); the one eigenvector with `4AC − B² > 0` is the ellipse.
///
/// Pairs beyond the shorter slice are ignored. `None` with fewer than 6 points, non-finite values,
/// points on a line (or a point), or a conic that is not a real ellipse.
pub fn fit_ellipse(x: &[f64], y: &[f64]) -> Option<Ellipse> {
    let n = x.len().min(y.len());
    let (x, y) = (&x[..n], &y[..n]);
    if n < 6 || x.iter().chain(y).any(|v| !v.is_finite()) {
        return None;
    }
    let (mx, my) = (mean(x), mean(y));
    let sd =
        |v: &[f64], m: f64| (v.iter().map(|a| (a - m) * (a - m)).sum::<f64>() / n as f64).sqrt();
    let (sx, sy) = (sd(x, mx), sd(y, my));
    if !(sx > 1e-12 * mx.abs()) || !(sy > 1e-12 * my.abs()) {
        return None;
    }
    // scatter matrices of D1 = [u², uv, v²] and D2 = [u, v, 1]
    let (mut s1, mut s2, mut s3) = ([[0.0; 3]; 3], [[0.0; 3]; 3], [[0.0; 3]; 3]);
    for (&xi, &yi) in x.iter().zip(y) {
        let (u, v) = ((xi - mx) / sx, (yi - my) / sy);
        let d1 = [u * u, u * v, v * v];
        let d2 = [u, v, 1.0];
        for i in 0..3 {
            for j in 0..3 {
                s1[i][j] += d1[i] * d1[j];
                s2[i][j] += d1[i] * d2[j];
                s3[i][j] += d2[i] * d2[j];
            }
        }
    }
    let s3_inv = spd_inverse(&s3)?; // fails for collinear points
    let mut t = mat_mul(&s3_inv, &transpose(&s2));
    for row in &mut t {
        for v in row.iter_mut() {
            *v = -*v;
        }
    }
    let s2t = mat_mul(&s2, &t);
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = s1[i][j] + 0.5 * (s2t[i][j] + s2t[j][i]);
        }
    }
    let ridge = 1e-12 * (m[0][0] + m[1][1] + m[2][2]);
    for (i, row) in m.iter_mut().enumerate() {
        row[i] += ridge;
    }
    // M a = λ C a  <=>  (L⁻¹ C L⁻ᵀ) b = (1/λ) b with M = L Lᵀ, b = Lᵀ a; C has exactly one
    // positive eigenvalue, so (by Sylvester's law of inertia) has L⁻¹ C L⁻ᵀ, and its eigenvector
    // is the one with aᵀ C a = 4AC − B² > 0.
    let li = lower_inverse(&cholesky(&m)?);
    let c = [[0.0, 0.0, 2.0], [0.0, -1.0, 0.0], [2.0, 0.0, 0.0]];
    let k = mat_mul(&mat_mul(&li, &c), &transpose(&li));
    let (values, vectors) = symmetric_eigen(k);
    let best = (0..3).max_by(|&i, &j| values[i].total_cmp(&values[j]))?;
    if !(values[best] > 0.0) {
        return None;
    }
    let b = [vectors[0][best], vectors[1][best], vectors[2][best]];
    let lit = transpose(&li);
    let a1: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| lit[i][j] * b[j]).sum());
    let a2: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| t[i][j] * a1[j]).sum());
    // back to centred data coordinates (x - mx, y - my)
    let conic = [
        a1[0] / (sx * sx),
        a1[1] / (sx * sy),
        a1[2] / (sy * sy),
        a2[0] / sx,
        a2[1] / sy,
        a2[2],
    ];
    let mut e = ellipse_from_conic(conic)?;
    let (sin, cos) = e.angle.sin_cos();
    let sq: f64 = x
        .iter()
        .zip(y)
        .map(|(&xi, &yi)| {
            // in the ellipse's own axes
            let (u, v) = (xi - mx - e.centre[0], yi - my - e.centre[1]);
            let d = distance_to_ellipse(
                e.semi_major,
                e.semi_minor,
                u * cos + v * sin,
                v * cos - u * sin,
            );
            d * d
        })
        .sum();
    e.rms_residual = (sq / n as f64).sqrt();
    e.centre[0] += mx;
    e.centre[1] += my;
    Some(e)
}

/// Centre, axes and angle of the conic `a x² + b xy + c y² + d x + e y + f = 0`, if it is a real
/// ellipse. `rms_residual` is left at 0.
fn ellipse_from_conic([a, b, c, d, e, f]: [f64; 6]) -> Option<Ellipse> {
    let det = 4.0 * a * c - b * b;
    if !(det > 0.0) {
        return None;
    }
    let x0 = (b * e - 2.0 * c * d) / det;
    let y0 = (b * d - 2.0 * a * e) / det;
    // value at the centre; make the quadratic form positive definite
    let mut f0 = f + 0.5 * (d * x0 + e * y0);
    let (mut a, mut b, mut c) = (a, b, c);
    if a < 0.0 {
        (a, b, c, f0) = (-a, -b, -c, -f0);
    }
    if !(f0 < 0.0) {
        return None;
    }
    let mid = 0.5 * (a + c);
    let r = (0.25 * (a - c) * (a - c) + 0.25 * b * b).sqrt();
    let (small, large) = (mid - r, mid + r);
    if !(small > 0.0) {
        return None;
    }
    // 0.5 atan2(b, a - c) is the direction of the larger eigenvalue (the minor axis)
    let minor_dir = if r > 1e-15 * mid {
        0.5 * b.atan2(a - c)
    } else {
        0.0
    };
    let mut angle = minor_dir + std::f64::consts::FRAC_PI_2;
    if angle > std::f64::consts::FRAC_PI_2 {
        angle -= std::f64::consts::PI;
    }
    let semi_major = (-f0 / small).sqrt();
    let semi_minor = (-f0 / large).sqrt();
    Some(Ellipse {
        centre: [x0, y0],
        semi_major,
        semi_minor,
        angle,
        width_along_x: 2.0 * (-f0 / a).sqrt(),
        rms_residual: 0.0,
    })
}

/// Shortest distance from the point (p0, p1) to the ellipse `(x/a)² + (y/b)² = 1`, `a >= b > 0`
/// (Eberly, "Distance from a point to an ellipse": the closest point solves a monotone equation
/// in one unknown, found by bisection, which cannot fail).
fn distance_to_ellipse(a: f64, b: f64, p0: f64, p1: f64) -> f64 {
    let (y0, y1) = (p0.abs(), p1.abs());
    if y1 > 0.0 {
        if y0 > 0.0 {
            let (z0, z1) = (y0 / a, y1 / b);
            let g = z0 * z0 + z1 * z1 - 1.0;
            if g == 0.0 {
                return 0.0;
            }
            let r0 = (a / b) * (a / b);
            let n0 = r0 * z0;
            let (mut lo, mut hi) = (z1 - 1.0, if g < 0.0 { 0.0 } else { n0.hypot(z1) - 1.0 });
            let mut t = lo;
            for _ in 0..200 {
                t = 0.5 * (lo + hi);
                // a residual to a part in 1e10 is plenty for a goodness of fit
                if t == lo || t == hi || hi - lo <= 1e-10 * (1.0 + t.abs()) {
                    break;
                }
                let (q0, q1) = (n0 / (t + r0), z1 / (t + 1.0));
                let gt = q0 * q0 + q1 * q1 - 1.0;
                if gt > 0.0 {
                    lo = t;
                } else if gt < 0.0 {
                    hi = t;
                } else {
                    break;
                }
            }
            let (x0, x1) = (r0 * y0 / (t + r0), y1 / (t + 1.0));
            (x0 - y0).hypot(x1 - y1)
        } else {
            (y1 - b).abs()
        }
    } else {
        let (numer, denom) = (a * y0, a * a - b * b);
        if numer < denom {
            let xa = numer / denom;
            (a * xa - y0).hypot(b * (1.0 - xa * xa).sqrt())
        } else {
            (y0 - a).abs()
        }
    }
}

/// Apparent stiction from routine data (Choudhury, Shah, Thornhill and Shook 2006; book 2008):
/// band-pass OP and PV to the oscillation's band `[low, high]` (cycles per sample, with
/// [`band_pass`], which has no phase shift) and fit an ellipse to the PV-OP plot (x = OP,
/// y = PV). The ellipse's width along OP is the apparent stiction, in OP's units: the stiction as
/// the loop sees it, which with a PI controller is not the valve's `d` itself.
pub fn apparent_stiction_ellipse(op: &[f64], pv: &[f64], low: f64, high: f64) -> Option<Ellipse> {
    fit_ellipse(&band_pass(op, low, high), &band_pass(pv, low, high))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_distortion_of_sine_triangle_and_square() {
        let period = 50.0;
        let f0 = 1.0 / period;
        let n = 2000;
        let phase = |i: usize| (i as f64 / period).fract();
        let sine: Vec<f64> = (0..n).map(|i| (TAU * i as f64 / period).sin()).collect();
        let triangle: Vec<f64> = (0..n)
            .map(|i| {
                let p = phase(i);
                if p < 0.5 {
                    4.0 * p - 1.0
                } else {
                    3.0 - 4.0 * p
                }
            })
            .collect();
        let square: Vec<f64> = (0..n)
            .map(|i| if phase(i) < 0.5 { 1.0 } else { -1.0 })
            .collect();
        let hs = harmonic_distortion(&sine, f0, 5).unwrap();
        let ht = harmonic_distortion(&triangle, f0, 5).unwrap();
        let hq = harmonic_distortion(&square, f0, 5).unwrap();
        assert!(hs < 1e-6, "sine {hs}");
        assert!(
            (ht - (1.0 / 81.0 + 1.0 / 625.0)).abs() < 0.002,
            "triangle {ht}"
        );
        assert!((hq - (1.0 / 9.0 + 1.0 / 25.0)).abs() < 0.01, "square {hq}");
        // white measurement noise on a sinusoid is not harmonics
        let mut state = 3u64;
        let noisy: Vec<f64> = sine
            .iter()
            .map(|v| {
                let mut g = 0.0;
                for _ in 0..12 {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    g += (state >> 11) as f64 / (1u64 << 53) as f64;
                }
                v + 0.3 * (g - 6.0)
            })
            .collect();
        let hn = harmonic_distortion(&noisy, f0, 5).unwrap();
        assert!(hn < 0.01, "noisy sine {hn}");
        // fewer than two periods, or harmonics beyond the Nyquist frequency: no answer
        assert!(harmonic_distortion(&sine, 1.0 / 8.0, 5).is_none());
        assert!(harmonic_distortion(&sine, 1.0 / 12.0, 5).is_some());
        assert!(harmonic_distortion(&sine[..80], f0, 5).is_none());
    }
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

    fn ellipse_points(n: usize, noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let (a, b, alpha) = (5.0, 2.0, 0.5f64);
        let mut rng = seeded(seed);
        (0..n)
            .map(|i| {
                let t = TAU * i as f64 / n as f64;
                let (u, v) = (a * t.cos(), b * t.sin());
                (
                    50.0 + u * alpha.cos() - v * alpha.sin() + noise * gaussian(&mut rng),
                    20.0 + u * alpha.sin() + v * alpha.cos() + noise * gaussian(&mut rng),
                )
            })
            .unzip()
    }

    #[test]
    fn ellipse_fit_recovers_a_rotated_ellipse() {
        let (a, b, alpha) = (5.0f64, 2.0f64, 0.5f64);
        let width =
            2.0 * a * b / (a * a * alpha.sin().powi(2) + b * b * alpha.cos().powi(2)).sqrt();
        for (noise, tol) in [(0.0, 1e-9), (0.02, 0.01)] {
            let (x, y) = ellipse_points(400, noise, 3);
            let e = fit_ellipse(&x, &y).unwrap();
            let rel = |got: f64, want: f64| ((got - want) / want).abs();
            assert!(
                rel(e.centre[0], 50.0) < tol && rel(e.centre[1], 20.0) < tol,
                "{e:?}"
            );
            assert!(
                rel(e.semi_major, a) < tol && rel(e.semi_minor, b) < tol,
                "{e:?}"
            );
            assert!(rel(e.angle, alpha) < tol, "{e:?}");
            assert!(rel(e.width_along_x, width) < tol, "{e:?}");
            assert!(e.rms_residual < 2.0 * noise + 1e-9, "{e:?}");
        }
        // the same ellipse turned by -0.5 rad: the angle keeps its sign
        let (x, y) = ellipse_points(200, 0.0, 4);
        let y: Vec<f64> = y.iter().map(|v| 40.0 - v).collect();
        let e = fit_ellipse(&x, &y).unwrap();
        assert!((e.angle + alpha).abs() < 1e-9, "{e:?}");
    }

    #[test]
    fn distance_to_an_ellipse() {
        // brute force over a fine parametrisation
        let (a, b) = (5.0, 2.0);
        for (p0, p1) in [
            (0.0, 0.0),
            (6.0, 0.0),
            (1.0, 0.0),
            (0.0, -3.0),
            (3.0, 1.0),
            (-4.0, 2.5),
            (0.3, 0.1),
        ] {
            let brute = (0..200_000)
                .map(|i| {
                    let t = TAU * i as f64 / 200_000.0;
                    (a * t.cos() - p0).hypot(b * t.sin() - p1)
                })
                .fold(f64::INFINITY, f64::min);
            let d = distance_to_ellipse(a, b, p0, p1);
            assert!((d - brute).abs() < 1e-6, "({p0}, {p1}): {d} vs {brute}");
        }
    }

    #[test]
    fn ellipse_fit_rejects_degenerate_data() {
        let x: Vec<f64> = (0..50).map(|i| i as f64).collect();
        let line: Vec<f64> = x.iter().map(|v| 2.0 * v + 1.0).collect();
        assert!(fit_ellipse(&x, &line).is_none());
        // a noisy line: no ellipse, or a very thin one
        let noisy: Vec<f64> = line
            .iter()
            .zip(white(50, 5))
            .map(|(v, n)| v + 0.01 * n)
            .collect();
        if let Some(e) = fit_ellipse(&x, &noisy) {
            assert!(e.semi_minor < 0.01 * e.semi_major, "{e:?}");
        }
        assert!(fit_ellipse(&x, &[3.0; 50]).is_none());
        assert!(fit_ellipse(&[1.0, 2.0, 3.0], &[1.0, 0.0, 1.0]).is_none());
        assert!(fit_ellipse(&[], &[]).is_none());
        let (mut ex, ey) = ellipse_points(100, 0.0, 6);
        ex[3] = f64::INFINITY;
        assert!(fit_ellipse(&ex, &ey).is_none());
    }

    #[test]
    fn apparent_stiction_of_a_sticky_loop() {
        let data = sticky_loop(2.0, None, 1);
        let (op, pv) = (&data.op[200..], &data.pv[200..]);
        let period = crate::detect::regularity(&control_error(&data), 1.0)
            .period
            .unwrap();
        let f = 1.0 / period;
        let e = apparent_stiction_ellipse(op, pv, 0.5 * f, 1.5 * f).unwrap();
        // the apparent stiction is of the order of d (2.1-2.2 here for d = 2)
        assert!(e.width_along_x > 1.0 && e.width_along_x < 4.0, "{e:?}");
    }
}
