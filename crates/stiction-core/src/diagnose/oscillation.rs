//! Does the loop oscillate, and of what period? Thornhill's regularity (a regular period) and
//! Hägglund's IAE count (repeated large half periods, also when the period wanders), each held
//! well above the noise. Plus the small robust statistics the families share.

use super::result::Oscillation;
use crate::detect::{self, IaeSettings};

pub(crate) fn mean(x: &[f64]) -> f64 {
    x.iter().sum::<f64>() / x.len().max(1) as f64
}

pub(crate) fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let i = (p * (sorted.len() - 1) as f64).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// Robust noise standard deviation from first differences (MAD / 0.6745 / √2): jumps and slow
/// oscillations barely move the median of the differences.
pub fn noise_std(x: &[f64]) -> f64 {
    let mut d: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    percentile(&d, 0.5) / 0.6745 / std::f64::consts::SQRT_2
}

/// Half the peak-to-peak amplitude (5th to 95th percentile).
pub(crate) fn amplitude(x: &[f64]) -> f64 {
    let mut s = x.to_vec();
    s.sort_by(f64::total_cmp);
    0.5 * (percentile(&s, 0.95) - percentile(&s, 0.05))
}

/// Moving average over `w` samples (centred), to take measurement noise off shape-based indices.
pub(crate) fn smooth(x: &[f64], w: usize) -> Vec<f64> {
    let n = x.len();
    if w <= 1 || n == 0 {
        return x.to_vec();
    }
    let h = w / 2;
    let mut prefix = vec![0.0; n + 1];
    for (i, v) in x.iter().enumerate() {
        prefix[i + 1] = prefix[i] + v;
    }
    (0..n)
        .map(|i| {
            let a = i.saturating_sub(h);
            let b = (i + h + 1).min(n);
            (prefix[b] - prefix[a]) / (b - a) as f64
        })
        .collect()
}

/// The longest stretch of `[start, end)` over which the setpoint stays constant (the whole stretch
/// without a setpoint).
pub(super) fn constant_setpoint(
    sp: Option<&[f64]>,
    (start, end): (usize, usize),
) -> (usize, usize) {
    let Some(sp) = sp else {
        return (start, end);
    };
    let (mut best, mut s) = ((start, start), start);
    for k in start + 1..=end {
        if k == end || sp[k] != sp[k - 1] {
            if k - s > best.1 - best.0 {
                best = (s, k);
            }
            s = k;
        }
    }
    best
}

/// The oscillation of the control error `error` (sampled every `ts` s) over `stretch`.
pub(super) fn oscillation(error: &[f64], ts: f64, stretch: (usize, usize)) -> Oscillation {
    let regularity = detect::regularity(error, ts);
    let noise = crate::detect::measurement_noise(error);
    let amp = amplitude(error);
    let period = regularity.period;
    let omega = period.map_or(
        2.0 * std::f64::consts::PI / (error.len() as f64 * ts),
        |p| 2.0 * std::f64::consts::PI / p,
    );
    // Hägglund's acceptable amplitude: well above the noise, so noise alone never counts
    let settings = IaeSettings {
        amplitude: 3.0 * noise,
        omega,
        n_lim: 10,
        window: 50.0 * period.unwrap_or(error.len() as f64 * ts),
    };
    let iae = detect::iae_count(error, ts, &settings);
    let periods = period.map(|p| error.len() as f64 * ts / p);
    // an oscillation that stands out of the noise, found by either detector (a regular period
    // stands out of noise at a smaller amplitude than a count of large areas)
    let oscillating = (regularity.oscillating && iae.exceedances >= 4 && amp > 1.5 * noise)
        || (iae.oscillating && amp > 3.0 * noise);
    Oscillation {
        oscillating,
        period,
        periods_in_record: periods,
        regularity,
        iae,
        noise_std: noise,
        amplitude: amp,
        stretch: [stretch.0, stretch.1],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_constant_setpoint_stretch() {
        let mut sp = vec![1.0; 100];
        sp[30..].fill(2.0);
        sp[40..].fill(3.0);
        assert_eq!(constant_setpoint(Some(&sp), (0, 100)), (40, 100));
        assert_eq!(constant_setpoint(Some(&sp), (0, 35)), (0, 30));
        assert_eq!(constant_setpoint(None, (5, 9)), (5, 9));
    }

    #[test]
    fn noise_std_of_white_noise_and_a_step() {
        // alternating ±1 has first differences of 2: sigma = 2 / 0.6745 / sqrt 2
        let mut x: Vec<f64> = (0..200)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let s = noise_std(&x);
        assert!((s - 2.0 / 0.6745 / std::f64::consts::SQRT_2).abs() < 1e-12);
        // a single large step barely moves it
        for v in &mut x[100..] {
            *v += 50.0;
        }
        assert!((noise_std(&x) - s).abs() < 1e-12);
    }
}
