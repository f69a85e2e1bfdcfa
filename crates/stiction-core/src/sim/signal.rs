//! Command, setpoint and disturbance signals over time.
//!
//! The first six kinds are defined per sample (a random walk takes one step per sample); the plant
//! kinds added for routine-data scenarios ([`Signal::Ramp`], [`Signal::RandomSteps`],
//! [`Signal::IntegratedRandomWalk`], [`Signal::NarrowBand`], [`Signal::Sum`]) are defined in
//! seconds, so they look the same whatever the simulation step.

use super::{require, SimError};
use crate::rng::{gaussian, seeded};
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// A command (or setpoint, or disturbance) signal over time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Signal {
    /// `offset + amplitude * sin(2 pi t / period)`.
    Sine {
        /// Amplitude, in the signal's units.
        amplitude: f64,
        /// Period, seconds.
        period: f64,
        /// Mean level.
        offset: f64,
    },
    /// A symmetric triangle wave between `offset - amplitude` and `offset + amplitude`, starting at
    /// `offset` and rising.
    Triangle {
        /// Amplitude, in the signal's units.
        amplitude: f64,
        /// Period, seconds.
        period: f64,
        /// Mean level.
        offset: f64,
    },
    /// `offset` plus a Gaussian random walk with step standard deviation `step_std` (one step per
    /// sample).
    RandomWalk {
        /// Standard deviation of each step.
        step_std: f64,
        /// The level at the first sample.
        offset: f64,
        /// Seed of the steps.
        seed: u64,
    },
    /// Random levels, uniform in `offset ± amplitude`, each held for `hold` seconds.
    Steps {
        /// Largest distance of a level from `offset`.
        amplitude: f64,
        /// Time each level is held, seconds.
        hold: f64,
        /// Middle of the levels.
        offset: f64,
        /// Seed of the levels.
        seed: u64,
    },
    /// `from` until time `at`, then `to`.
    Step {
        /// Level before the step.
        from: f64,
        /// Level after the step.
        to: f64,
        /// Time of the step, seconds.
        at: f64,
    },
    /// A constant.
    Constant {
        /// The level.
        value: f64,
    },
    /// `offset` until time `start`, then rising (or falling) by `slope` per second.
    Ramp {
        /// Rate, units per second.
        slope: f64,
        /// Time the ramp starts, seconds.
        start: f64,
        /// Level before the ramp.
        offset: f64,
    },
    /// A setpoint step sequence as operators make it: random levels, uniform in
    /// `offset ± amplitude`, each held for a random time uniform in `min_hold..=max_hold` seconds.
    /// The first level is `offset` itself (the loop starts at its operating point).
    RandomSteps {
        /// Largest distance of a level from `offset`.
        amplitude: f64,
        /// Shortest hold, seconds.
        min_hold: f64,
        /// Longest hold, seconds.
        max_hold: f64,
        /// The first level and the middle of the others.
        offset: f64,
        /// Seed of the levels and holds.
        seed: u64,
    },
    /// A slow load drift: `offset` plus an integrated random walk. The slope (units per second)
    /// starts at 0 and is itself a random walk whose increments over one second have standard
    /// deviation `slope_std`; the level integrates the slope.
    IntegratedRandomWalk {
        /// Standard deviation of the slope's increments over one second.
        slope_std: f64,
        /// The level at the first sample.
        offset: f64,
        /// Seed of the increments.
        seed: u64,
    },
    /// Random narrow-band noise around `period`: white noise through a second-order resonator
    /// `w0^2 / (s^2 + 2 damping w0 s + w0^2)`, `w0 = 2 pi / period`, discretised by matching its
    /// poles. Scaled so the generated stretch has the standard deviation of a sine of this
    /// `amplitude` (amplitude / √2); small `damping` (0.02..0.2) gives a waxing and waning
    /// oscillation that is not a pure sinusoid.
    NarrowBand {
        /// Amplitude of the sine of equal standard deviation.
        amplitude: f64,
        /// Centre period, seconds.
        period: f64,
        /// The resonator's damping ratio.
        damping: f64,
        /// Seed of the white noise.
        seed: u64,
    },
    /// The sum of several signals.
    Sum {
        /// The signals added.
        parts: Vec<Signal>,
    },
    /// A recorded series (another loop's PV, say), `values[j]` at `j * dt` seconds, drawn
    /// straight between its samples and held at its last value after them.
    Recorded {
        /// Seconds between the values.
        dt: f64,
        /// The values.
        values: Vec<f64>,
    },
}

impl Signal {
    /// An error naming the first setting out of range (a negative amplitude, a period or hold
    /// that is not positive, a value that is not finite).
    pub fn validate(&self) -> Result<(), SimError> {
        match self {
            Signal::Sine {
                amplitude,
                period,
                offset,
            }
            | Signal::Triangle {
                amplitude,
                period,
                offset,
            } => {
                require(*amplitude >= 0.0, "amplitude", ">= 0", *amplitude)?;
                require(*period > 0.0, "period", "> 0 seconds", *period)?;
                require(true, "offset", "finite", *offset)
            }
            Signal::RandomWalk {
                step_std, offset, ..
            } => {
                require(*step_std >= 0.0, "step_std", ">= 0", *step_std)?;
                require(true, "offset", "finite", *offset)
            }
            Signal::Steps {
                amplitude,
                hold,
                offset,
                ..
            } => {
                require(*amplitude >= 0.0, "amplitude", ">= 0", *amplitude)?;
                require(*hold > 0.0, "hold", "> 0 seconds", *hold)?;
                require(true, "offset", "finite", *offset)
            }
            Signal::Step { from, to, at } => {
                require(true, "from", "finite", *from)?;
                require(true, "to", "finite", *to)?;
                require(true, "at", "finite", *at)
            }
            Signal::Constant { value } => require(true, "value", "finite", *value),
            Signal::Ramp {
                slope,
                start,
                offset,
            } => {
                require(true, "slope", "finite", *slope)?;
                require(true, "start", "finite", *start)?;
                require(true, "offset", "finite", *offset)
            }
            Signal::RandomSteps {
                amplitude,
                min_hold,
                max_hold,
                offset,
                ..
            } => {
                require(*amplitude >= 0.0, "amplitude", ">= 0", *amplitude)?;
                require(*min_hold > 0.0, "min_hold", "> 0 seconds", *min_hold)?;
                require(*max_hold >= *min_hold, "max_hold", ">= min_hold", *max_hold)?;
                require(true, "offset", "finite", *offset)
            }
            Signal::IntegratedRandomWalk {
                slope_std, offset, ..
            } => {
                require(*slope_std >= 0.0, "slope_std", ">= 0", *slope_std)?;
                require(true, "offset", "finite", *offset)
            }
            Signal::NarrowBand {
                amplitude,
                period,
                damping,
                ..
            } => {
                require(*amplitude >= 0.0, "amplitude", ">= 0", *amplitude)?;
                require(*period > 0.0, "period", "> 0 seconds", *period)?;
                require(
                    *damping > 0.0 && *damping < 1.0,
                    "damping",
                    "in (0, 1)",
                    *damping,
                )
            }
            Signal::Sum { parts } => parts.iter().try_for_each(Signal::validate),
            Signal::Recorded { dt, values } => {
                require(*dt > 0.0, "dt", "> 0 seconds", *dt)?;
                require(!values.is_empty(), "values", "at least one", 0.0)?;
                values
                    .iter()
                    .try_for_each(|&v| require(true, "values", "finite", v))
            }
        }
    }

    /// Sample the signal at `t[k] = k * ts`, `k = 0..samples`.
    pub fn generate(&self, ts: f64, samples: usize) -> Vec<f64> {
        let time = |k: usize| k as f64 * ts;
        match *self {
            Signal::Sine {
                amplitude,
                period,
                offset,
            } => (0..samples)
                .map(|k| offset + amplitude * (std::f64::consts::TAU * time(k) / period).sin())
                .collect(),
            Signal::Triangle {
                amplitude,
                period,
                offset,
            } => (0..samples)
                .map(|k| {
                    // phase in [0, 1): rise 0..0.25 to +A, fall to -A at 0.75, rise back to 0
                    let p = (time(k) / period).rem_euclid(1.0);
                    let tri = if p < 0.25 {
                        4.0 * p
                    } else if p < 0.75 {
                        2.0 - 4.0 * p
                    } else {
                        4.0 * p - 4.0
                    };
                    offset + amplitude * tri
                })
                .collect(),
            Signal::RandomWalk {
                step_std,
                offset,
                seed,
            } => {
                let mut rng = seeded(seed);
                let mut level = offset;
                (0..samples)
                    .map(|k| {
                        if k > 0 {
                            level += step_std * gaussian(&mut rng);
                        }
                        level
                    })
                    .collect()
            }
            Signal::Steps {
                amplitude,
                hold,
                offset,
                seed,
            } => {
                let mut rng = seeded(seed);
                let mut level = offset;
                let mut next_change = 0.0;
                (0..samples)
                    .map(|k| {
                        if time(k) >= next_change - 1e-12 {
                            level = offset + amplitude * (2.0 * rng.random::<f64>() - 1.0);
                            next_change += hold;
                        }
                        level
                    })
                    .collect()
            }
            Signal::Step { from, to, at } => (0..samples)
                .map(|k| if time(k) < at { from } else { to })
                .collect(),
            Signal::Constant { value } => vec![value; samples],
            Signal::Ramp {
                slope,
                start,
                offset,
            } => (0..samples)
                .map(|k| offset + slope * (time(k) - start).max(0.0))
                .collect(),
            Signal::RandomSteps {
                amplitude,
                min_hold,
                max_hold,
                offset,
                seed,
            } => random_steps(amplitude, (min_hold, max_hold), offset, seed, ts, samples),
            Signal::IntegratedRandomWalk {
                slope_std,
                offset,
                seed,
            } => {
                let mut rng = seeded(seed);
                let (mut level, mut slope) = (offset, 0.0);
                let kick = slope_std * ts.sqrt();
                (0..samples)
                    .map(|k| {
                        if k > 0 {
                            level += slope * ts;
                            slope += kick * gaussian(&mut rng);
                        }
                        level
                    })
                    .collect()
            }
            Signal::NarrowBand {
                amplitude,
                period,
                damping,
                seed,
            } => narrow_band(amplitude, period, damping, seed, ts, samples),
            Signal::Sum { ref parts } => {
                let mut sum = vec![0.0; samples];
                for p in parts {
                    for (s, v) in sum.iter_mut().zip(p.generate(ts, samples)) {
                        *s += v;
                    }
                }
                sum
            }
            Signal::Recorded { dt, ref values } => recorded(values, dt, ts, samples),
        }
    }
}

/// `values` (one every `dt` seconds) at `k * ts`, straight between them, the last held after.
fn recorded(values: &[f64], dt: f64, ts: f64, samples: usize) -> Vec<f64> {
    (0..samples)
        .map(|k| {
            let x = k as f64 * ts / dt;
            let j = x.floor() as usize;
            match (values.get(j), values.get(j + 1)) {
                (Some(a), Some(b)) => a + (b - a) * (x - j as f64),
                _ => values[values.len() - 1],
            }
        })
        .collect()
}

fn random_steps(
    amplitude: f64,
    (min_hold, max_hold): (f64, f64),
    offset: f64,
    seed: u64,
    ts: f64,
    samples: usize,
) -> Vec<f64> {
    let mut rng = seeded(seed);
    let hold = |rng: &mut crate::rng::Rng| min_hold + (max_hold - min_hold) * rng.random::<f64>();
    let mut level = offset;
    let mut next_change = hold(&mut rng);
    (0..samples)
        .map(|k| {
            if k as f64 * ts >= next_change - 1e-12 {
                level = offset + amplitude * (2.0 * rng.random::<f64>() - 1.0);
                next_change += hold(&mut rng);
            }
            level
        })
        .collect()
}

/// White noise through a discretised resonator (poles `r e^{±i w0 ts}`, `r = e^{-damping w0 ts}`),
/// after a burn-in of a few decay times so the record starts in the steady state.
fn narrow_band(
    amplitude: f64,
    period: f64,
    damping: f64,
    seed: u64,
    ts: f64,
    samples: usize,
) -> Vec<f64> {
    let w0 = std::f64::consts::TAU / period;
    let r = (-damping * w0 * ts).exp();
    let (a1, a2) = (2.0 * r * (w0 * ts).cos(), -r * r);
    let burn_in = ((5.0 / (damping * w0)) / ts).ceil() as usize;
    let mut rng = seeded(seed);
    let (mut y1, mut y2) = (0.0, 0.0);
    let mut out = Vec::with_capacity(samples);
    for k in 0..burn_in + samples {
        let y = a1 * y1 + a2 * y2 + gaussian(&mut rng);
        y2 = y1;
        y1 = y;
        if k >= burn_in {
            out.push(y);
        }
    }
    let n = out.len().max(1) as f64;
    let mean = out.iter().sum::<f64>() / n;
    let std = (out.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
    let scale = if std > 0.0 {
        amplitude / std::f64::consts::SQRT_2 / std
    } else {
        0.0
    };
    out.iter().map(|v| (v - mean) * scale).collect()
}
