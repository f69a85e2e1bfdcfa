//! Gain, time constant and dead time of a fitted model.

#![allow(clippy::needless_range_loop)]

use super::*;

/// Gain, time constant and dead time where they follow from the fitted coefficients.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Physical {
    /// Steady-state gain (self-regulating) or integration rate per second (integrating).
    pub gain: Option<f64>,
    /// Time constant in seconds of the (dominant) real pole.
    pub time_constant: Option<f64>,
    /// Dead time in seconds: (nk - 1) sample times (zero-order hold).
    pub dead_time: f64,
}

/// Gain, time constant and dead time of `f`, for sampling time `ts` seconds.
pub fn physical(f: &Fit, ts: f64) -> Physical {
    let s = f.structure;
    let sum_a: f64 = f.a.iter().sum();
    let sum_b: f64 = f.b.iter().sum();
    let dead_time = (s.nk as f64 - 1.0) * ts;
    let pole = match f.a.len() {
        0 => None,
        1 => Some(f.a[0]),
        _ => {
            // z^2 - a1 z - a2: the dominant real root, if the roots are real
            let (a1, a2) = (f.a[0], f.a[1]);
            let disc = a1 * a1 + 4.0 * a2;
            (disc >= 0.0).then(|| {
                let r1 = 0.5 * (a1 + disc.sqrt());
                let r2 = 0.5 * (a1 - disc.sqrt());
                if r1.abs() >= r2.abs() {
                    r1
                } else {
                    r2
                }
            })
        }
    };
    let time_constant = pole.filter(|&p| p > 0.0 && p < 1.0).map(|p| -ts / p.ln());
    let gain = if (1.0 - sum_a).abs() > 1e-9 {
        let g = sum_b / (1.0 - sum_a);
        Some(if s.integrating { g / ts } else { g })
    } else {
        None
    };
    Physical {
        gain,
        time_constant,
        dead_time,
    }
}
