//! Welch's power spectrum and the harmonic distortion of a cycle.

#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::*;

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
