//! A valve that does not move at all: OP winds, through the integral action, against an offset
//! that PV holds without moving towards the setpoint. A healthy valve moves PV towards the
//! setpoint as OP travels; a stuck one (or a closed block valve) leaves PV where it is.

/// How a hold is told.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StuckSettings {
    /// Samples of the moving mean the control error's sign is read through.
    pub smoothing: usize,
    /// Fewest samples of a hold.
    pub min_samples: usize,
    /// The offset is at least this many PV noise standard deviations.
    pub offset: f64,
    /// PV's spread over the hold (5th to 95th percentile) at most this share of the offset.
    pub spread: f64,
}

impl Default for StuckSettings {
    fn default() -> Self {
        Self {
            smoothing: 5,
            min_samples: 10,
            offset: 4.0,
            spread: 0.5,
        }
    }
}

/// The longest OP travel (OP units, unsigned) over a hold, and the hold's samples `[start, end)`.
pub fn longest_hold(
    op: &[f64],
    pv: &[f64],
    error: &[f64],
    sign: f64,
    pv_noise: f64,
    set: &StuckSettings,
) -> Option<(f64, [usize; 2])> {
    let smooth = crate::diagnose::oscillation::smooth(error, set.smoothing);
    let n = error.len();
    let mut best: Option<(f64, [usize; 2])> = None;
    let mut i = 0;
    while i < n {
        let side = smooth[i].signum();
        let mut j = i + 1;
        while j < n && smooth[j].signum() == side {
            j += 1;
        }
        if side != 0.0 && j - i >= set.min_samples {
            if let Some(travel) = hold(op, pv, error, sign, pv_noise, set, (i, j)) {
                if best.is_none_or(|b| travel > b.0) {
                    best = Some((travel, [i, j]));
                }
            }
        }
        i = j;
    }
    best
}

/// OP's travel over `[a, b)` when it is a hold.
fn hold(
    op: &[f64],
    pv: &[f64],
    error: &[f64],
    sign: f64,
    pv_noise: f64,
    set: &StuckSettings,
    (a, b): (usize, usize),
) -> Option<f64> {
    let offset = error[a..b].iter().sum::<f64>() / (b - a) as f64;
    if offset.abs() < set.offset * pv_noise {
        return None;
    }
    let mut part = pv[a..b].to_vec();
    part.sort_by(f64::total_cmp);
    let q = |p: f64| part[((part.len() - 1) as f64 * p).round() as usize];
    if q(0.95) - q(0.05) > set.spread * offset.abs() {
        return None;
    }
    let travel = op[b - 1] - op[a];
    (travel.signum() == sign * offset.signum()).then_some(travel.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn op_winding_against_a_held_offset_is_a_hold() {
        // PV sits 2 below the setpoint while OP winds up 30 % of span
        let n = 200;
        let op: Vec<f64> = (0..n).map(|i| 10.0 + 0.15 * i as f64).collect();
        let pv: Vec<f64> = (0..n).map(|i| 0.01 * ((i * 7) % 5) as f64).collect();
        let error: Vec<f64> = pv.iter().map(|p| 2.0 - p).collect();
        let (travel, range) =
            longest_hold(&op, &pv, &error, 1.0, 0.02, &StuckSettings::default()).unwrap();
        assert!((travel - 29.85).abs() < 0.01, "{travel}");
        assert_eq!(range, [0, n]);
        // PV moving towards the setpoint as OP winds: a healthy valve
        let pv: Vec<f64> = (0..n).map(|i| 1.9 * i as f64 / n as f64).collect();
        let error: Vec<f64> = pv.iter().map(|p| 2.0 - p).collect();
        assert!(longest_hold(&op, &pv, &error, 1.0, 0.02, &StuckSettings::default()).is_none());
    }
}
