//! The observed cycle: its complex amplitude at a known frequency, and the amplitude of each cycle
//! (a limit cycle keeps its amplitude; a linear loop near its stability limit lets it grow, decay
//! or wander with the noise that drives it).

use super::controller::solve3;
use super::Complex64;
use crate::spectral::band_pass;
use serde::{Deserialize, Serialize};

/// The complex amplitude of `x` at `theta` radians per sample: the least-squares fit
/// `x[k] ≈ m + Re(X e^{jθk})`, returned as `X` (its modulus is the amplitude, its argument the
/// phase). Zero when the fit is singular (fewer than 3 samples, or θ a multiple of π).
pub fn fundamental(x: &[f64], theta: f64) -> Complex64 {
    fit_fundamental(
        x.iter()
            .enumerate()
            .map(|(k, &v)| ((theta * k as f64).sin_cos(), v)),
    )
}

/// As [`fundamental`], with `(sin θk, cos θk)` for `k = 0, 1, ...` taken from `trig` (at least as
/// long as `x`): many signals at one frequency share one table, bit for bit the same result.
pub fn fundamental_from_table(x: &[f64], trig: &[(f64, f64)]) -> Complex64 {
    fit_fundamental(trig.iter().copied().zip(x.iter().copied()))
}

/// The least-squares fit of `v ≈ m + A cos + B sin` over `((sin, cos), v)` pairs, as `A - jB`.
fn fit_fundamental(samples: impl Iterator<Item = ((f64, f64), f64)>) -> Complex64 {
    let mut g = [[0.0f64; 3]; 3];
    let mut h = [0.0f64; 3];
    for ((s, c), v) in samples {
        let r = [c, s, 1.0];
        for i in 0..3 {
            h[i] += r[i] * v;
            for j in 0..3 {
                g[i][j] += r[i] * r[j];
            }
        }
    }
    match solve3(g, h) {
        // x = A cos + B sin = Re((A - jB) e^{jθk})
        Some([a, b, _]) => Complex64::new(a, -b),
        None => Complex64::new(0.0, 0.0),
    }
}

/// The amplitude of each cycle of an oscillation, and how it changes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AmplitudeTrend {
    /// Cycles measured.
    pub cycles: usize,
    /// Mean amplitude (of the fundamental over each cycle).
    pub mean: f64,
    /// Relative change of the amplitude over the cycles measured, from a straight line fitted
    /// to its logarithm (0.5: grew by half; -0.5: fell by half).
    pub change: f64,
    /// Scatter of the amplitudes about that line: the standard deviation of the log amplitude's
    /// residuals (0.1: about 10 % from cycle to cycle).
    pub scatter: f64,
}

impl AmplitudeTrend {
    /// The trend of a sequence of cycle amplitudes; `None` for fewer than 4, or one not positive.
    pub fn of(amps: &[f64]) -> Option<Self> {
        if amps.len() < 4 || amps.iter().any(|a| !(*a > 0.0)) {
            return None;
        }
        let logs: Vec<f64> = amps.iter().map(|a| a.ln()).collect();
        let m = logs.len() as f64;
        let index: Vec<f64> = (0..logs.len()).map(|k| k as f64).collect();
        let (slope, residuals) = straight_line(&index, &logs);
        let var = residuals.iter().map(|r| r * r).sum::<f64>() / (m - 2.0);
        Some(Self {
            cycles: amps.len(),
            mean: amps.iter().sum::<f64>() / m,
            change: (slope * (m - 1.0)).exp() - 1.0,
            scatter: var.sqrt(),
        })
    }
}

/// The least-squares straight line through `(t, y)`: its slope, and what it leaves of `y`.
fn straight_line(t: &[f64], y: &[f64]) -> (f64, Vec<f64>) {
    let n = t.len() as f64;
    let (tbar, ybar) = (t.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in t.iter().zip(y) {
        sxy += (a - tbar) * (b - ybar);
        sxx += (a - tbar).powi(2);
    }
    let slope = sxy / sxx;
    let residuals = t
        .iter()
        .zip(y)
        .map(|(a, b)| b - ybar - slope * (a - tbar))
        .collect();
    (slope, residuals)
}

/// The cycles of an oscillation, each from one upward zero crossing of the band-passed signal to
/// the next. A limit cycle driven by noise drifts in phase, so a Fourier coefficient over the
/// whole record would cancel itself; the coefficients of each cycle at its own frequency do not.
#[derive(Debug, Clone, PartialEq)]
pub struct Cycles {
    /// `[start, end)` of each whole cycle (the first and last of the record left out: the
    /// filter's ends; crossings closer than half the period are no cycle).
    pub bounds: Vec<(usize, usize)>,
}

impl Cycles {
    /// Cut `x` (period about `period` samples) into cycles; `None` for fewer than 4.
    pub fn find(x: &[f64], period: f64) -> Option<Self> {
        let f0 = 1.0 / period;
        let y = band_pass(x, 0.6 * f0, 1.5 * f0);
        let ups: Vec<usize> = (1..y.len())
            .filter(|&k| y[k - 1] < 0.0 && y[k] >= 0.0)
            .collect();
        // a crossing pair closer than half the period (at least 3 samples) is the filtered
        // signal's wiggle about zero, not a cycle: its fundamental would be no amplitude (a cycle
        // of 2 samples has none), so it is left out
        let shortest = ((0.5 * period).ceil() as usize).max(3);
        let bounds: Vec<(usize, usize)> = ups
            .windows(2)
            .map(|w| (w[0], w[1]))
            .filter(|(a, b)| b - a >= shortest)
            .collect();
        if bounds.len() < 6 {
            return None;
        }
        Some(Self {
            bounds: bounds[1..bounds.len() - 1].to_vec(),
        })
    }

    /// Mean period, samples.
    pub fn period(&self) -> f64 {
        self.bounds.iter().map(|(a, b)| (b - a) as f64).sum::<f64>() / self.bounds.len() as f64
    }

    /// How freely the cycle's phase runs in `x`: each cycle's phase at the mean frequency
    /// (`fundamental` over the cycle, referred to the record's start) is held against a straight
    /// line (a fixed period), and the wander is the variance of what is left over half the variance
    /// of its steps from cycle to cycle.
    ///
    /// An oscillation forced by an input of fixed period keeps time with it: its phases scatter
    /// about the line independently, and the wander stays near 1 (for 6 to 60 cycles of white
    /// scatter, under 2 in 99 of 100 records and under 2.6 in 999 of 1,000). A self-sustained
    /// oscillation (a limit cycle, or a resonance driven by noise) has no clock: each cycle's
    /// noise shifts all later ones, the phase drifts as a random walk, and the wander grows with
    /// the cycles (median 3.5 over 30, 7 over 60). `None` for fewer than 6 cycles.
    pub fn phase_wander(&self, x: &[f64]) -> Option<f64> {
        let m = self.bounds.len();
        if m < 6 {
            return None;
        }
        let theta = 2.0 * std::f64::consts::PI / self.period();
        let mut phases: Vec<f64> = self
            .bounds
            .iter()
            .map(|&(a, b)| fundamental(&x[a..b], theta).arg() - theta * a as f64)
            .collect();
        // unwrap: neighbouring cycles differ by far less than a turn
        for k in 1..m {
            let d = phases[k] - phases[k - 1];
            phases[k] -= (d / std::f64::consts::TAU).round() * std::f64::consts::TAU;
        }
        // against the cycles' middles (a cycle left out leaves a gap in time, not in the count)
        let mids: Vec<f64> = self
            .bounds
            .iter()
            .map(|&(a, b)| 0.5 * (a + b) as f64)
            .collect();
        let (_, residuals) = straight_line(&mids, &phases);
        let var = residuals.iter().map(|r| r * r).sum::<f64>() / m as f64;
        let steps: Vec<f64> = residuals.windows(2).map(|w| w[1] - w[0]).collect();
        let mean_step = steps.iter().sum::<f64>() / steps.len() as f64;
        let step_var =
            steps.iter().map(|s| (s - mean_step).powi(2)).sum::<f64>() / steps.len() as f64;
        (step_var > 0.0).then(|| var / (0.5 * step_var))
    }

    /// The complex amplitude of `x` in each cycle, at the cycle's own frequency, with that
    /// frequency.
    pub fn coefficients(&self, x: &[f64]) -> Vec<(f64, Complex64)> {
        self.bounds
            .iter()
            .map(|&(a, b)| {
                let th = 2.0 * std::f64::consts::PI / (b - a) as f64;
                (th, fundamental(&x[a..b], th))
            })
            .collect()
    }
}

/// The complex ratio of two signals' cycles (least squares over the cycles: `Σ y x̄ / Σ |x|²`).
pub fn ratio(y: &[(f64, Complex64)], x: &[(f64, Complex64)]) -> Complex64 {
    let num: Complex64 = y.iter().zip(x).map(|(a, b)| a.1 * b.1.conj()).sum();
    let den: f64 = x.iter().map(|b| b.1.norm_sqr()).sum();
    num / den.max(f64::MIN_POSITIVE)
}

/// The RMS size of `y`'s cycles against `x`'s.
pub fn share(y: &[(f64, Complex64)], x: &[(f64, Complex64)]) -> f64 {
    let num: f64 = y.iter().map(|a| a.1.norm_sqr()).sum();
    let den: f64 = x.iter().map(|b| b.1.norm_sqr()).sum();
    (num / den.max(f64::MIN_POSITIVE)).sqrt()
}

/// [`share`] less what white measurement noise of standard deviation `sigma` puts into every
/// cycle's fundamental, in `y` and in `x`: the least-squares amplitude over a cycle of `N` samples
/// scatters by `4 σ² / N` in power, so a residual of noise alone is no share. When `x`'s cycles
/// hold no more power than that noise, [`share`] as it is.
pub fn share_above_noise(y: &[(f64, Complex64)], x: &[(f64, Complex64)], sigma: f64) -> f64 {
    let power = |c: &[(f64, Complex64)]| -> f64 {
        c.iter()
            .map(|(th, z)| z.norm_sqr() - 4.0 * sigma * sigma * th / (2.0 * std::f64::consts::PI))
            .sum()
    };
    let cycle = power(x);
    if !(cycle > 0.0) {
        return share(y, x);
    }
    (power(y).max(0.0) / cycle).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// `n` samples of a unit sine of `period` samples under white noise of standard deviation
    /// `noise`, drawn from `rng`.
    fn noisy_sine(n: usize, period: f64, noise: f64, rng: &mut crate::rng::Rng) -> Vec<f64> {
        (0..n)
            .map(|k| (2.0 * PI * k as f64 / period).sin() + noise * crate::rng::gaussian(rng))
            .collect()
    }

    #[test]
    fn the_fundamental_of_a_shifted_sinusoid() {
        let theta = 2.0 * PI / 37.3;
        let x: Vec<f64> = (0..500)
            .map(|k| {
                4.0 + 2.5 * (theta * k as f64 - 0.7).cos() + 0.3 * (3.0 * theta * k as f64).sin()
            })
            .collect();
        let f = fundamental(&x, theta);
        assert!(
            (f.norm() - 2.5).abs() < 0.01 && (f.arg() + 0.7).abs() < 0.01,
            "{f}"
        );
    }

    #[test]
    fn constant_growing_and_wandering_amplitudes() {
        let period = 40.0;
        let wave = |amp: &dyn Fn(f64) -> f64| -> Vec<f64> {
            (0..2000)
                .map(|k| amp(k as f64) * (2.0 * PI * k as f64 / period).sin())
                .collect()
        };
        let measure = |x: &[f64]| {
            let c = Cycles::find(x, period)?;
            let amps: Vec<f64> = c.coefficients(x).iter().map(|(_, z)| z.norm()).collect();
            AmplitudeTrend::of(&amps)
        };
        let steady = measure(&wave(&|_| 3.0)).unwrap();
        assert!(
            (steady.mean - 3.0).abs() < 0.05 && steady.change.abs() < 0.01 && steady.scatter < 0.02,
            "{steady:?}"
        );
        let growing = measure(&wave(&|k| (k / 1000.0).exp())).unwrap();
        assert!(
            growing.change > 3.0 && growing.scatter < 0.02,
            "{growing:?}"
        );
        let wandering = measure(&wave(&|k| 2.0 + (k / 97.0).sin() * (k / 411.0).cos())).unwrap();
        assert!(wandering.scatter > 0.15, "{wandering:?}");
        assert!(measure(&wave(&|_| 1.0)[..150]).is_none());
    }

    #[test]
    fn white_noise_is_no_share_of_a_cycle() {
        let period = 20.0;
        let mut rng = crate::rng::seeded(7);
        let pv: Vec<f64> = (0..2000)
            .map(|k| (2.0 * PI * k as f64 / period).sin())
            .collect();
        let noise: Vec<f64> = (0..2000)
            .map(|_| 0.5 * crate::rng::gaussian(&mut rng))
            .collect();
        let noisy: Vec<f64> = pv.iter().zip(&noise).map(|(a, b)| a + b).collect();
        let c = Cycles::find(&pv, period).unwrap();
        let (cp, cn) = (c.coefficients(&noisy), c.coefficients(&noise));
        // a residual of noise alone: about sqrt(4 σ² / N) = 0.22 of a unit cycle, and nothing
        // once the noise's own power is taken off
        let raw = share(&cn, &cp);
        let above = share_above_noise(&cn, &cp, 0.5);
        assert!((0.17..0.28).contains(&raw), "{raw}");
        assert!(above < 0.08, "{above}");
        // a residual that is a tenth of the cycle stays one
        let tenth: Vec<f64> = pv.iter().zip(&noise).map(|(a, b)| 0.1 * a + b).collect();
        let part = share_above_noise(&c.coefficients(&tenth), &cp, 0.5);
        assert!((0.05..0.15).contains(&part), "{part}");
    }

    #[test]
    fn a_forced_cycle_keeps_time_and_a_free_one_drifts() {
        let period = 40.0;
        let wander = |x: &[f64]| Cycles::find(x, period).unwrap().phase_wander(x).unwrap();
        for seed in 0..10 {
            let mut rng = crate::rng::seeded(seed);
            // a sine of fixed period under measurement noise: its crossings scatter, never drift
            let forced = noisy_sine(2400, period, 0.3, &mut rng);
            let w = wander(&forced);
            assert!(w < 2.6, "seed {seed}: forced {w}");
            // the same cycle with a phase that random-walks (a self-sustained oscillation under noise)
            // (over 120 cycles: the wander of a random walk grows with the cycles counted)
            let mut phase = 0.0;
            let free: Vec<f64> = (0..4800)
                .map(|k| {
                    phase += 0.03 * crate::rng::gaussian(&mut rng);
                    (2.0 * PI * k as f64 / period + phase).sin()
                })
                .collect();
            let w = wander(&free);
            assert!(w > 3.0, "seed {seed}: free {w}");
        }
    }

    #[test]
    fn a_forced_cycles_wander_stays_under_2_in_99_of_100_records() {
        // sines of fixed period under white noise, 8 to 60 cycles, at three noise levels
        let mut over = 0;
        let mut runs = 0;
        for seed in 0..300u64 {
            let mut rng = crate::rng::seeded(1000 + seed);
            let period = 20.0 + (seed % 7) as f64 * 3.3;
            let cycles = 8 + (seed % 53) as usize;
            let noise = [0.1, 0.3, 0.6][(seed % 3) as usize];
            let x = noisy_sine((cycles as f64 * period) as usize, period, noise, &mut rng);
            let Some(w) = Cycles::find(&x, period).and_then(|c| c.phase_wander(&x)) else {
                continue;
            };
            runs += 1;
            over += (w >= 2.0) as usize;
        }
        assert!(runs > 250, "{runs}");
        assert!(over * 100 <= 2 * runs, "{over} of {runs} over 2");
    }

    #[test]
    fn a_wiggle_about_zero_is_no_cycle() {
        // a cycle of 8.8 samples under heavy noise: the band-passed signal sometimes crosses zero
        // twice within a sample or two; such a "cycle" has no fundamental and would void the
        // amplitude trend
        let period = 8.8;
        for seed in 0..20 {
            let mut rng = crate::rng::seeded(seed);
            let x = noisy_sine(2000, period, 1.5, &mut rng);
            let c = Cycles::find(&x, period).unwrap();
            assert!(c.bounds.iter().all(|(a, b)| b - a >= 5), "{:?}", c.bounds);
            let amps: Vec<f64> = c.coefficients(&x).iter().map(|(_, z)| z.norm()).collect();
            let trend = AmplitudeTrend::of(&amps).expect("every cycle has an amplitude");
            assert!(trend.cycles > 100, "seed {seed}: {trend:?}");
        }
    }
}
