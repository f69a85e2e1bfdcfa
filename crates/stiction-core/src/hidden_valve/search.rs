//! The likelihood ratio with each hypothesis's loop model found by coordinate ascent.

use super::ascent::{ascend, band_starts, remembered, sticky_optimum, Grid};
use super::coordinates::{cycle_angles, gain_sign, step_noise, Coordinate, Scales, LOADS, PROCESS};
use super::likelihood::{healthy_log_likelihood, sticky_log_likelihood, Particles, Record, Slip};
use super::model::LoopModel;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// How the test searches.
#[derive(Debug, Clone, Copy)]
pub struct TestSettings {
    /// Bands tried, as shares of the OP span (log-spaced between these) ...
    pub band_range: (f64, f64),
    /// ... this many.
    pub bands: usize,
    /// The OP span the bands are shares of (100 for OP in %).
    pub op_span: f64,
    /// The process integrates (a level).
    pub integrating: bool,
    /// OP's unrecorded moves between the samples, in OP noise standard deviations (the OP
    /// noise read from its sample-to-sample changes).
    pub input_noise: f64,
    /// The particle filter's settings.
    pub particles: Particles,
    /// The sticky hypothesis is searched from this many of the best healthy optima.
    pub sticky_starts: usize,
    /// How far short of OP a slip may land, as shares of the band, each tried with every band
    /// (`[0.0]`: Stenman's valve alone; He's valve lands `fd` short of OP).
    pub short_shares: &'static [f64],
    /// Valves each sticky search starts from at its healthy optimum: 1, the scan's best; 2, also
    /// the best whose band lies more than a grid step from it (another basin).
    pub band_starts: usize,
    /// The period, samples, of the cycle the record shows, when the caller knows it: the
    /// cycling load may sit there as well as at PV's strongest cycle (its periodogram's peak,
    /// which setpoint steps can outweigh). `None`: at PV's strongest cycle only.
    pub cycle_period: Option<f64>,
}

impl Default for TestSettings {
    fn default() -> Self {
        Self {
            band_range: (0.003, 0.08),
            bands: 10,
            op_span: 100.0,
            integrating: false,
            input_noise: 0.5,
            particles: Particles::default(),
            sticky_starts: 2,
            short_shares: &[0.0],
            band_starts: 1,
            cycle_period: None,
        }
    }
}

/// The test's outcome.
#[derive(Debug, Clone, PartialEq)]
pub struct HiddenValveTest {
    /// Log-likelihood ratio, sticky against healthy (natural log).
    pub ratio: f64,
    /// The sticky hypothesis's best band, OP units.
    pub band: f64,
    /// How far short of OP its slips land, OP units.
    pub short: f64,
    /// The healthy hypothesis's loop model.
    pub healthy: LoopModel,
    /// The sticky hypothesis's loop model.
    pub sticky: LoopModel,
    /// Likelihood evaluations: Kalman filters, particle filters.
    pub evaluations: (usize, usize),
}

/// Starting processes of the healthy search: time constant and dead time, in samples.
const STARTS: [(f64, f64); 4] = [(2.0, 1.0), (10.0, 1.0), (10.0, 4.0), (40.0, 4.0)];

/// The hidden-valve likelihood ratio of a record; `None` on fewer than 50 samples or a flat PV.
pub fn test(rec: &Record, set: &TestSettings) -> Option<HiddenValveTest> {
    let n = rec.pv.len();
    if n < 50 || rec.op.len() != n {
        return None;
    }
    // a level's valve offset would be a ramp of PV: the integrator sees OP's deviations
    let shifted: Vec<f64>;
    let rec = &if set.integrating {
        let mean = rec.op.iter().sum::<f64>() / n as f64;
        shifted = rec.op.iter().map(|v| v - mean).collect();
        Record {
            op: &shifted,
            limits: rec.limits.map(|(lo, hi)| (lo - mean, hi - mean)),
            ..*rec
        }
    } else {
        *rec
    };
    let angles = cycle_angles(rec.pv, set.cycle_period);
    let strongest = angles[0];
    let scales = Scales {
        ts: rec.ts,
        noise: step_noise(rec.pv),
        sign: gain_sign(rec.op, rec.pv),
        angles,
    };
    if scales.noise.is_nan() || scales.noise <= 0.0 {
        return None;
    }
    let start = LoopModel {
        gain: scales.sign,
        tau: 10.0 * rec.ts,
        delay: rec.ts,
        valve_lag: 0.0,
        integrating: set.integrating,
        noise: scales.noise,
        drift: 0.01 * scales.noise,
        cycle: 0.0,
        cycle_radius: 0.95,
        cycle_angle: strongest,
        input_noise: set.input_noise * step_noise(rec.op),
    };
    let all: Vec<Coordinate> = PROCESS.iter().chain(&LOADS).copied().collect();
    // the starts are searched in parallel: every evaluation is a deterministic function of its
    // model (the particle filter's seed is fixed), so the result does not depend on the threads
    let (kalman, particles) = (AtomicUsize::new(0), AtomicUsize::new(0));
    let healthy = |m: &LoopModel| {
        kalman.fetch_add(1, Ordering::Relaxed);
        healthy_log_likelihood(rec, m)
    };
    // the healthy likelihood has several optima: ascend from a few processes, keep the two best
    let mut optima: Vec<(f64, LoopModel)> = STARTS
        .par_iter()
        .map(|&(tau, delay)| {
            let m = LoopModel {
                tau: tau * rec.ts,
                delay: delay * rec.ts,
                ..start
            };
            let mut f = remembered(|m, ()| healthy(m), |()| ());
            let first = f(&m, ());
            ascend(&mut |m| f(m, ()), (first, m), &all, 3, &scales)
        })
        .collect();
    optima.sort_by(|a, b| b.0.total_cmp(&a.0));
    if set.bands == 0 || set.short_shares.is_empty() {
        return None;
    }
    let grid = Grid::new(set);
    let sticky = |m: &LoopModel, slip: Slip| {
        particles.fetch_add(1, Ordering::Relaxed);
        sticky_log_likelihood(rec, m, slip, &set.particles)
    };
    // from each healthy optimum, an ascent from each of its valves to start from (one memory of
    // likelihoods for them all)
    let searched: Vec<(f64, LoopModel, Slip)> = optima[..set.sticky_starts.clamp(1, optima.len())]
        .par_iter()
        .flat_map_iter(|(_, m)| {
            let mut f = remembered(&sticky, |s: Slip| (s.band.to_bits(), s.short.to_bits()));
            band_starts(&mut f, m, &grid, set.band_starts)
                .into_iter()
                .map(|start| sticky_optimum(&mut f, m, start, &grid, &scales))
                .collect::<Vec<_>>()
        })
        .collect();
    let (l1, m1, slip) =
        searched
            .into_iter()
            .fold((f64::NEG_INFINITY, start, grid.slips[0]), |a, b| {
                if b.0 > a.0 {
                    b
                } else {
                    a
                }
            });
    // the healthy hypothesis searched again from the sticky one's model
    let mut f = remembered(|m, ()| healthy(m), |()| ());
    let again = f(&m1, ());
    let h0b = ascend(&mut |m| f(m, ()), (again, m1), &all, 2, &scales);
    let (l0, m0) = if h0b.0 > optima[0].0 { h0b } else { optima[0] };
    drop(f);
    let evaluations = (kalman.into_inner(), particles.into_inner());
    Some(HiddenValveTest {
        ratio: l1 - l0,
        band: slip.band,
        short: slip.short,
        healthy: m0,
        sticky: m1,
        evaluations,
    })
}
