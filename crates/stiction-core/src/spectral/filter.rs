//! The zero-phase frequency-domain band-pass filter of Choudhury, Shah and Thornhill.

#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop)]

use super::*;

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
