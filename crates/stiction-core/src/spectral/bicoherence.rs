//! The squared bicoherence test of non-Gaussianity and non-linearity (Choudhury, Shah and
//! Thornhill 2004).

#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::*;

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
    /// The NGI threshold used: non-Gaussian above it.
    pub ngi_threshold: f64,
    /// The NLI threshold used: a non-Gaussian signal is non-linear above it.
    pub nli_threshold: f64,
    /// Number of segments K averaged.
    pub segments: usize,
    /// Segment length M used (may be smaller than requested for short records).
    pub segment_length: usize,
    /// Bifrequency (f1, f2) of the largest squared bicoherence, cycles per sample.
    pub peak: [f64; 2],
    /// The largest squared bicoherence.
    pub peak_value: f64,
    /// Whether NGI exceeds its threshold.
    pub non_gaussian: bool,
    /// Whether the signal is non-Gaussian and NLI exceeds its threshold.
    pub non_linear: bool,
}

/// Fewest segments the bicoherence estimate is averaged over.
pub(crate) const MIN_SEGMENTS: usize = 4;
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
pub(super) struct BicoherenceMap {
    /// (f1, f2) in bins and bic² for every bifrequency of the principal domain.
    values: Vec<(usize, usize, f64)>,
    segments: usize,
    segment_length: usize,
}

pub(super) fn segment_count(n: usize, m: usize, overlap: f64) -> (usize, usize) {
    let step = ((m as f64 * (1.0 - overlap)).round() as usize).max(1);
    let k = if n >= m { (n - m) / step + 1 } else { 0 };
    (k, step)
}

pub(super) fn bicoherence_map(x: &[f64], s: &BicoherenceSettings) -> Option<BicoherenceMap> {
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
pub(super) fn robust_mean_std(v: &mut [f64]) -> (f64, f64) {
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
/// A record too short for `MIN_SEGMENTS` segments of `segment_length` samples is retried with
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
