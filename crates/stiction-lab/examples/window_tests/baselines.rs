//! The two model-free tests engineers reach for on routine windows, as simple baselines (issue 10
//! names them: "PV steady while OP changes" in short windows, after Damarla et al. 2022/2023, and
//! a Kano-style "stick, then jump" check). Neither is `diagnose`: they have no look-alike guard and
//! no model of the loop, which is the point of comparing them with it. Each gives a count per
//! record; a record is flagged sticky from a count, either any at all (the naive reading) or a
//! count calibrated on the catalogue's calibration draws (`main.rs`).

/// Samples in each window of the window test (non-overlapping), the lengths tried, each with
/// the two-sided Student t at p = 0.01 (OP's slope significant from it) and at p = 0.05 (PV's
/// slope under it is no change) for its `window - 2` degrees of freedom.
pub const WINDOWS: [(usize, f64, f64); 4] = [
    (10, 3.355, 2.306),
    (20, 2.878, 2.101),
    (40, 2.712, 2.024),
    (80, 2.640, 1.991),
];
/// The window length of the naive reading (any window fires), an index into [`WINDOWS`].
pub const NAIVE: usize = 1;
/// OP's fitted travel over a window must reach this many of its noise standard deviations.
pub const OP_TRAVEL_SIGMAS: f64 = 3.0;
/// PV stays within this many of its noise standard deviations of its window's mean, and its
/// fitted travel under [`PV_TRAVEL_SIGMAS`].
pub const PV_BAND_SIGMAS: f64 = 3.0;
/// PV's fitted travel over a steady window stays under this many noise standard deviations.
pub const PV_TRAVEL_SIGMAS: f64 = 2.0;
/// The stick-then-jump check: PV inside this many noise standard deviations of where the stick
/// began ...
pub const STICK_BAND_SIGMAS: f64 = 2.5;
/// ... while OP travels at least this many of its own, mostly one way ...
pub const STICK_OP_SIGMAS: f64 = 4.0;
/// ... (OP's range over the stick at most this multiple of its net travel) ...
pub const MONOTONE: f64 = 1.25;

/// Noise standard deviation from first differences, robust to steps and cycles (the median
/// absolute deviation of the differences, over √2).
pub fn noise_sd(x: &[f64]) -> f64 {
    let mut d: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return 0.0;
    }
    let med = median(&mut d);
    let mut dev: Vec<f64> = d.iter().map(|v| (v - med).abs()).collect();
    1.4826 * median(&mut dev) / std::f64::consts::SQRT_2
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Least-squares slope of `x` over its index, its t statistic, and the largest deviation from
/// the window's mean.
fn slope(x: &[f64]) -> (f64, f64, f64) {
    let n = x.len() as f64;
    let tc = |i: usize| i as f64 - 0.5 * (n - 1.0);
    let mean = x.iter().sum::<f64>() / n;
    let stt: f64 = (0..x.len()).map(|i| tc(i) * tc(i)).sum();
    let b = x.iter().enumerate().map(|(i, v)| tc(i) * v).sum::<f64>() / stt;
    let sse: f64 = x
        .iter()
        .enumerate()
        .map(|(i, v)| (v - mean - b * tc(i)).powi(2))
        .sum();
    let se = (sse / (n - 2.0)).sqrt() / stt.sqrt();
    let t = if se > 0.0 { b / se } else { f64::INFINITY };
    let dev = x.iter().map(|v| (v - mean).abs()).fold(0.0, f64::max);
    (b, t, dev)
}

/// The window test with the `k`th of [`WINDOWS`]: (windows where OP changes while PV stays
/// steady, windows).
pub fn window_count(op: &[f64], pv: &[f64], k: usize) -> (usize, usize) {
    let (s_op, s_pv) = (noise_sd(op), noise_sd(pv));
    let (window, t_changes, t_steady) = WINDOWS[k];
    let travel = (window - 1) as f64;
    let mut fired = 0;
    let mut windows = 0;
    for (o, p) in op.chunks_exact(window).zip(pv.chunks_exact(window)) {
        windows += 1;
        let (b_op, t_op, _) = slope(o);
        let (b_pv, t_pv, dev_pv) = slope(p);
        let op_changes =
            t_op.abs() >= t_changes && (b_op * travel).abs() >= OP_TRAVEL_SIGMAS * s_op;
        let pv_steady = t_pv.abs() < t_steady
            && (b_pv * travel).abs() < PV_TRAVEL_SIGMAS * s_pv
            && dev_pv <= PV_BAND_SIGMAS * s_pv;
        if op_changes && pv_steady {
            fired += 1;
        }
    }
    (fired, windows)
}

/// The stick-then-jump check: stretches where PV stays within [`STICK_BAND_SIGMAS`] of where
/// it began (the median of its first three samples) while OP travels at least
/// [`STICK_OP_SIGMAS`] of its noise, mostly one way, ended by PV leaving the band (two samples in
/// a row) in OP's direction (a process of positive gain, as the catalogue's).
pub fn stick_jump_count(op: &[f64], pv: &[f64]) -> usize {
    let (s_op, s_pv) = (noise_sd(op), noise_sd(pv));
    let n = op.len().min(pv.len());
    let (mut i, mut count) = (0, 0);
    while i + 3 < n {
        // where the stick began: the median of its first three samples, so one noisy sample
        // does not set the band
        let mut first = [pv[i], pv[i + 1], pv[i + 2]];
        first.sort_by(f64::total_cmp);
        let anchor = first[1];
        let outside = |k: usize| (pv[k] - anchor).abs() > STICK_BAND_SIGMAS * s_pv;
        // PV leaves the band for good (two samples in a row), not on one noisy sample
        let mut j = i + 1;
        while j + 1 < n && !(outside(j) && outside(j + 1)) {
            j += 1;
        }
        if j + 1 >= n {
            break;
        }
        let stick = &op[i..j];
        let net = stick[stick.len() - 1] - stick[0];
        let (lo, hi) = stick
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(*v), h.max(*v))
            });
        let jump = pv[j] - anchor;
        if net.abs() >= STICK_OP_SIGMAS * s_op
            && hi - lo <= MONOTONE * net.abs()
            && jump.signum() == net.signum()
        {
            count += 1;
        }
        i = j;
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, sd: f64, seed: u64) -> Vec<f64> {
        let mut rng = stiction_core::rng::seeded(seed);
        (0..n)
            .map(|_| sd * stiction_core::rng::gaussian(&mut rng))
            .collect()
    }

    #[test]
    fn a_ramp_in_op_under_a_flat_pv_fires_and_noise_alone_does_not() {
        let n = 400;
        let pv = noise(n, 0.1, 1);
        let flat_op: Vec<f64> = noise(n, 0.1, 2).iter().map(|v| 50.0 + v).collect();
        let ramp_op: Vec<f64> = noise(n, 0.1, 3)
            .iter()
            .enumerate()
            .map(|(i, v)| 50.0 + 0.05 * i as f64 + v)
            .collect();
        for (k, w) in WINDOWS.iter().enumerate() {
            let (quiet, windows) = window_count(&flat_op, &pv, k);
            assert_eq!(windows, n / w.0);
            assert!(quiet <= 1, "{quiet}");
            assert!(window_count(&ramp_op, &pv, k).0 >= windows / 2);
        }
    }

    #[test]
    fn stick_then_jump_is_counted_once_per_stick() {
        // OP ramps 2 units over 40 samples while PV holds, then PV jumps up; three times
        let mut op = Vec::new();
        let mut pv = Vec::new();
        for k in 0..3 {
            for i in 0..40 {
                op.push(50.0 + 2.0 * k as f64 + 0.05 * i as f64);
                pv.push(10.0 + 2.0 * k as f64);
            }
        }
        op.push(56.0);
        pv.push(16.0);
        let e = noise(op.len(), 0.01, 4);
        let op: Vec<f64> = op.iter().zip(&e).map(|(a, b)| a + b).collect();
        let e = noise(pv.len(), 0.01, 5);
        let pv: Vec<f64> = pv.iter().zip(&e).map(|(a, b)| a + b).collect();
        assert_eq!(stick_jump_count(&op, &pv), 3);
    }
}
