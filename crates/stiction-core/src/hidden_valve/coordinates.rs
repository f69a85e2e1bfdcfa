//! The coordinates of the loop model the search moves, their values, and the scales they are
//! relative to (read off the record).

use super::model::LoopModel;

/// A coordinate of the loop model and the values it is searched over.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Coordinate {
    Gain,
    Tau,
    Delay,
    ValveLag,
    Noise,
    Drift,
    Cycle,
    CycleRadius,
    CycleAngle,
}

pub(super) const PROCESS: [Coordinate; 4] = [
    Coordinate::Gain,
    Coordinate::Tau,
    Coordinate::Delay,
    Coordinate::ValveLag,
];
pub(super) const LOADS: [Coordinate; 5] = [
    Coordinate::Noise,
    Coordinate::Drift,
    Coordinate::Cycle,
    Coordinate::CycleRadius,
    Coordinate::CycleAngle,
];

/// The scales a search is relative to: sampling time, PV's sample-to-sample noise, the sign of
/// the process gain, and the cycling load's angles (radians per sample) to choose from.
pub(super) struct Scales {
    pub ts: f64,
    pub noise: f64,
    pub sign: f64,
    pub angles: Vec<f64>,
}

pub(super) fn values(c: Coordinate, s: &Scales) -> Vec<f64> {
    let times = |xs: &[f64], by: f64| xs.iter().map(|x| x * by).collect();
    match c {
        Coordinate::Gain => times(&[0.3, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0], s.sign),
        Coordinate::Tau => times(&[0.3, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0], s.ts),
        Coordinate::Delay => (0..=12).map(|i| i as f64 * s.ts).collect(),
        Coordinate::ValveLag => vec![0.0, 1.0, 2.5, 5.0],
        Coordinate::Noise => times(&[0.05, 0.1, 0.2, 0.4, 0.7, 1.0, 1.5, 2.5, 4.0], s.noise),
        Coordinate::Drift => times(&[1e-4, 1e-3, 0.01, 0.03, 0.1, 0.3, 1.0], s.noise),
        Coordinate::Cycle => times(&[0.0, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0], s.noise),
        Coordinate::CycleRadius => vec![0.8, 0.9, 0.97, 0.995],
        Coordinate::CycleAngle => s.angles.clone(),
    }
}

pub(super) fn set(m: &mut LoopModel, c: Coordinate, v: f64) {
    match c {
        Coordinate::Gain => m.gain = v,
        Coordinate::Tau => m.tau = v,
        Coordinate::Delay => m.delay = v,
        Coordinate::ValveLag => m.valve_lag = v,
        Coordinate::Noise => m.noise = v,
        Coordinate::Drift => m.drift = v,
        Coordinate::Cycle => m.cycle = v,
        Coordinate::CycleRadius => m.cycle_radius = v,
        Coordinate::CycleAngle => m.cycle_angle = v,
    }
}

/// Robust standard deviation of a series' sample-to-sample changes, over √2 (white noise's own).
/// Unlike `diagnose::oscillation::noise_std` it measures the changes' spread about their median,
/// so a steady ramp of PV does not count as noise.
pub(super) fn step_noise(x: &[f64]) -> f64 {
    let mut d: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return 0.0;
    }
    d.sort_by(f64::total_cmp);
    let med = d[d.len() / 2];
    let mut dev: Vec<f64> = d.iter().map(|v| (v - med).abs()).collect();
    dev.sort_by(f64::total_cmp);
    1.4826 * dev[dev.len() / 2] / std::f64::consts::SQRT_2
}

/// The angle (radians per sample) of PV's strongest cycle: the peak of its periodogram, the
/// slowest few frequencies left out.
fn cycle_angle(pv: &[f64]) -> f64 {
    let n = pv.len();
    let mean = pv.iter().sum::<f64>() / n as f64;
    let (mut best, mut angle) = (0.0, std::f64::consts::PI / 8.0);
    // a few hundred frequencies are enough to place a load's resonance
    let steps = (n / 2).min(400);
    for j in 3..steps {
        let w = std::f64::consts::PI * j as f64 / steps as f64;
        let (mut c, mut s) = (0.0, 0.0);
        for (t, v) in pv.iter().enumerate() {
            let (sin, cos) = (w * t as f64).sin_cos();
            c += (v - mean) * cos;
            s += (v - mean) * sin;
        }
        if c * c + s * s > best {
            (best, angle) = (c * c + s * s, w);
        }
    }
    angle
}

/// The cycling load's angles to choose from: PV's strongest cycle first, then the cycle the loop
/// shows (its period in samples, when the caller knows it), where they differ. Setpoint steps can
/// outweigh an oscillation in PV's periodogram; each hypothesis takes the likelier.
pub(super) fn cycle_angles(pv: &[f64], shown_period: Option<f64>) -> Vec<f64> {
    let strongest = cycle_angle(pv);
    let mut angles = vec![strongest];
    if let Some(p) = shown_period.filter(|p| *p > 2.0) {
        let shown = std::f64::consts::TAU / p;
        if shown != strongest {
            angles.push(shown);
        }
    }
    angles
}

/// The sign of the process gain: of the correlation of PV's changes with OP's a few samples
/// before.
pub(super) fn gain_sign(op: &[f64], pv: &[f64]) -> f64 {
    let n = op.len();
    let mut c = 0.0;
    for lag in 1..=10.min(n.saturating_sub(2)) {
        for t in lag + 1..n {
            c += (pv[t] - pv[t - 1]) * (op[t - lag] - op[t - lag - 1]);
        }
    }
    if c < 0.0 {
        -1.0
    } else {
        1.0
    }
}
