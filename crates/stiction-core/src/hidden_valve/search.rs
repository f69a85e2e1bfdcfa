//! The likelihood ratio with each hypothesis's loop model found by coordinate ascent.

use super::coordinates::{
    cycle_angle, gain_sign, set, step_noise, values, Coordinate, Scales, LOADS, PROCESS,
};
use super::likelihood::{healthy_log_likelihood, sticky_log_likelihood, Particles, Record};
use super::model::LoopModel;

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
    /// The healthy hypothesis's loop model.
    pub healthy: LoopModel,
    /// The sticky hypothesis's loop model.
    pub sticky: LoopModel,
    /// Likelihood evaluations: Kalman filters, particle filters.
    pub evaluations: (usize, usize),
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

/// The best of `best` (likelihood, band) and every band of `bands` under model `m`.
fn scan(
    sticky: &mut dyn FnMut(&LoopModel, f64) -> f64,
    bands: &[f64],
    m: &LoopModel,
    best: (f64, f64),
) -> (f64, f64) {
    bands.iter().fold(best, |b, &d| {
        let l = sticky(m, d);
        if l > b.0 {
            (l, d)
        } else {
            b
        }
    })
}

/// Coordinate ascent of the sticky likelihood (two sweeps), each move judged at the band and
/// its neighbours on the grid: another gain or dead time slips the valve at other samples, and
/// the band that fits moves with them.
fn ascend_with_band(
    sticky: &mut dyn FnMut(&LoopModel, f64) -> f64,
    bands: &[f64],
    (mut best, mut m, mut band): (f64, LoopModel, f64),
    coords: &[Coordinate],
    s: &Scales,
) -> (f64, LoopModel, f64) {
    for _ in 0..2 {
        for &c in coords {
            for v in values(c, s) {
                let mut trial = m;
                set(&mut trial, c, v);
                let i = bands.iter().position(|&b| b == band).unwrap_or(0);
                let near = &bands[i.saturating_sub(1)..(i + 2).min(bands.len())];
                let (l, d) = scan(sticky, near, &trial, (f64::NEG_INFINITY, band));
                if l > best {
                    (best, m, band) = (l, trial, d);
                }
            }
        }
    }
    (best, m, band)
}

/// The sticky hypothesis from a healthy optimum `m`: the bands scanned, the model ascended at the
/// best (two sweeps), the bands scanned again. Returns the likelihood, model and band.
fn sticky_optimum(
    sticky: &mut dyn FnMut(&LoopModel, f64) -> f64,
    m: &LoopModel,
    bands: &[f64],
    scales: &Scales,
) -> (f64, LoopModel, f64) {
    let (l1, band) = scan(sticky, bands, m, (f64::NEG_INFINITY, bands[0]));
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
    let (l1, m1, band) = ascend_with_band(sticky, bands, (l1, *m, band), &order, scales);
    let (l1, band) = scan(sticky, bands, &m1, (l1, band));
    (l1, m1, band)
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
    let (mut kalman, mut particles) = (0, 0);
    let mut healthy = |m: &LoopModel| {
        kalman += 1;
        healthy_log_likelihood(rec, m)
    };
    // the healthy likelihood has several optima: ascend from a few processes, keep the two best
    let mut optima: Vec<(f64, LoopModel)> = STARTS
        .iter()
        .map(|&(tau, delay)| {
            let m = LoopModel {
                tau: tau * rec.ts,
                delay: delay * rec.ts,
                ..start
            };
            let first = healthy(&m);
            ascend(&mut healthy, (first, m), &all, 3, &scales)
        })
        .collect();
    optima.sort_by(|a, b| b.0.total_cmp(&a.0));
    let bands: Vec<f64> = (0..set.bands)
        .map(|i| {
            let (a, b) = set.band_range;
            let x = i as f64 / (set.bands.max(2) - 1) as f64;
            set.op_span * a * (b / a).powf(x)
        })
        .collect();
    let mut sticky = |m: &LoopModel, band: f64| {
        particles += 1;
        sticky_log_likelihood(rec, m, band, &set.particles)
    };
    let (l1, m1, band) = optima
        .iter()
        .take(set.sticky_starts.max(1))
        .map(|(_, m)| sticky_optimum(&mut sticky, m, &bands, &scales))
        .fold((f64::NEG_INFINITY, start, bands[0]), |a, b| {
            if b.0 > a.0 {
                b
            } else {
                a
            }
        });
    // the healthy hypothesis searched again from the sticky one's model
    let again = healthy(&m1);
    let h0b = ascend(&mut healthy, (again, m1), &all, 2, &scales);
    let (l0, m0) = if h0b.0 > optima[0].0 { h0b } else { optima[0] };
    Some(HiddenValveTest {
        ratio: l1 - l0,
        band,
        healthy: m0,
        sticky: m1,
        evaluations: (kalman, particles),
    })
}
