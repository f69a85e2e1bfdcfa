//! The likelihood ratio with each hypothesis's loop model found by coordinate ascent.

use super::coordinates::{
    cycle_angle, gain_sign, set, step_noise, values, Coordinate, Scales, LOADS, PROCESS,
};
use super::likelihood::{healthy_log_likelihood, sticky_log_likelihood, Particles, Record, Slip};
use super::model::LoopModel;
use rayon::prelude::*;
use std::collections::HashMap;
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

/// A model's parameters, bit for bit: the key under which a likelihood is remembered.
fn key(m: &LoopModel) -> [u64; 10] {
    [
        m.gain,
        m.tau,
        m.delay,
        m.valve_lag,
        m.noise,
        m.drift,
        m.cycle,
        m.cycle_radius,
        m.cycle_angle,
        m.input_noise,
    ]
    .map(f64::to_bits)
}

/// `f` remembered: the ascents come back to models (and valves) they have judged, each
/// coordinate's grid holding the current value; a remembered likelihood is the same number.
fn remembered<K: std::hash::Hash + Eq, A: Copy>(
    f: impl Fn(&LoopModel, A) -> f64,
    with: impl Fn(A) -> K,
) -> impl FnMut(&LoopModel, A) -> f64 {
    let mut seen: HashMap<([u64; 10], K), f64> = HashMap::new();
    move |m, a| *seen.entry((key(m), with(a))).or_insert_with(|| f(m, a))
}

/// Coordinate ascent of `f` from `(best, m)` over `coords`, `sweeps` times.
fn ascend(
    f: &mut dyn FnMut(&LoopModel) -> f64,
    (mut best, mut m): (f64, LoopModel),
    coords: &[Coordinate],
    sweeps: usize,
    s: &Scales,
) -> (f64, LoopModel) {
    for _ in 0..sweeps {
        for &c in coords {
            for v in values(c, s) {
                let mut trial = m;
                set(&mut trial, c, v);
                let l = f(&trial);
                if l > best {
                    (best, m) = (l, trial);
                }
            }
        }
    }
    (best, m)
}

/// Starting processes of the healthy search: time constant and dead time, in samples.
const STARTS: [(f64, f64); 4] = [(2.0, 1.0), (10.0, 1.0), (10.0, 4.0), (40.0, 4.0)];

/// The valves tried: every band at every share of it a slip may land short of OP, share by
/// share (a share's bands in order, so a band's neighbours on the grid sit beside it).
struct Grid {
    slips: Vec<Slip>,
    bands: usize,
}

impl Grid {
    fn new(set: &TestSettings) -> Self {
        let (a, b) = set.band_range;
        let bands: Vec<f64> = (0..set.bands)
            .map(|i| set.op_span * a * (b / a).powf(i as f64 / (set.bands.max(2) - 1) as f64))
            .collect();
        let slips = set
            .short_shares
            .iter()
            .flat_map(|&share| {
                bands.iter().map(move |&band| Slip {
                    band,
                    short: share * band,
                })
            })
            .collect();
        Self {
            slips,
            bands: set.bands,
        }
    }

    /// `slip` and its neighbours in band at the same share.
    fn near(&self, slip: Slip) -> &[Slip] {
        let i = self.slips.iter().position(|&s| s == slip).unwrap_or(0);
        let row = i / self.bands * self.bands;
        let lo = i.saturating_sub(1).max(row);
        let hi = (i + 2).min(row + self.bands);
        &self.slips[lo..hi]
    }
}

/// The best of `best` (likelihood, valve) and every valve of `slips` under model `m`.
fn scan(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    slips: &[Slip],
    m: &LoopModel,
    best: (f64, Slip),
) -> (f64, Slip) {
    slips.iter().fold(best, |b, &v| {
        let l = sticky(m, v);
        if l > b.0 {
            (l, v)
        } else {
            b
        }
    })
}

/// Coordinate ascent of the sticky likelihood (two sweeps), each move judged at the valve and
/// its neighbours in band: another gain or dead time slips the valve at other samples, and the
/// band that fits moves with them.
fn ascend_with_band(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    grid: &Grid,
    (mut best, mut m, mut slip): (f64, LoopModel, Slip),
    coords: &[Coordinate],
    s: &Scales,
) -> (f64, LoopModel, Slip) {
    for _ in 0..2 {
        for &c in coords {
            for v in values(c, s) {
                let mut trial = m;
                set(&mut trial, c, v);
                let (l, d) = scan(sticky, grid.near(slip), &trial, (f64::NEG_INFINITY, slip));
                if l > best {
                    (best, m, slip) = (l, trial, d);
                }
            }
        }
    }
    (best, m, slip)
}

/// The sticky hypothesis from a healthy optimum `m`: the valves scanned, the model ascended at
/// the best (two sweeps), the valves scanned again. Returns the likelihood, model and valve.
fn sticky_optimum(
    sticky: &mut dyn FnMut(&LoopModel, Slip) -> f64,
    m: &LoopModel,
    grid: &Grid,
    scales: &Scales,
) -> (f64, LoopModel, Slip) {
    let (l1, slip) = scan(sticky, &grid.slips, m, (f64::NEG_INFINITY, grid.slips[0]));
    let order = [
        Coordinate::Noise,
        Coordinate::Cycle,
        Coordinate::Drift,
        Coordinate::CycleRadius,
        Coordinate::Gain,
        Coordinate::Tau,
        Coordinate::Delay,
        Coordinate::ValveLag,
    ];
    let (l1, m1, slip) = ascend_with_band(sticky, grid, (l1, *m, slip), &order, scales);
    let (l1, slip) = scan(sticky, &grid.slips, &m1, (l1, slip));
    (l1, m1, slip)
}

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
    let scales = Scales {
        ts: rec.ts,
        noise: step_noise(rec.pv),
        sign: gain_sign(rec.op, rec.pv),
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
        cycle_angle: cycle_angle(rec.pv),
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
    let searched: Vec<(f64, LoopModel, Slip)> = optima[..set.sticky_starts.clamp(1, optima.len())]
        .par_iter()
        .map(|(_, m)| {
            let mut f = remembered(&sticky, |s: Slip| (s.band.to_bits(), s.short.to_bits()));
            sticky_optimum(&mut f, m, &grid, &scales)
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
