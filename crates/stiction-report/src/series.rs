//! The data the report's charts show, prepared before any drawing: the time axis and its unit,
//! min/max decimation for long traces, thinning for the phase plot, and the zoom window of a long
//! record (the stretch where OP and PV vary most).

use crate::LoopData;

/// A record longer than this many samples gets an overview (decimated) and a zoomed window.
pub const LONG_RECORD: usize = 5000;

/// Seconds from the first sample for every sample of the record.
pub fn time_axis(data: &LoopData) -> Vec<f64> {
    match &data.time {
        Some(t) if !t.is_empty() => t.iter().map(|v| v - t[0]).collect(),
        _ => (0..data.op.len()).map(|k| k as f64 * data.ts).collect(),
    }
}

/// The unit a time axis of `span` seconds reads best in: its name and seconds per unit.
pub fn time_unit(span: f64) -> (&'static str, f64) {
    if span > 2.0 * 86400.0 {
        ("d", 86400.0)
    } else if span > 5.0 * 3600.0 {
        ("h", 3600.0)
    } else if span > 3000.0 {
        ("min", 60.0)
    } else {
        ("s", 1.0)
    }
}

/// The first, lowest and highest sample of each of `buckets` buckets, in time order: the
/// envelope and every spike survive. Short series come back whole.
pub fn decimate(x: &[f64], y: &[f64], buckets: usize) -> (Vec<f64>, Vec<f64>) {
    let n = x.len().min(y.len());
    if n <= 3 * buckets {
        return (x[..n].to_vec(), y[..n].to_vec());
    }
    let size = n.div_ceil(buckets);
    let (mut xs, mut ys) = (
        Vec::with_capacity(3 * buckets),
        Vec::with_capacity(3 * buckets),
    );
    let mut start = 0;
    while start < n {
        let end = (start + size).min(n);
        let (mut lo, mut hi) = (start, start);
        for k in start..end {
            // NaN (a gap) never wins a comparison: the bucket keeps its finite extremes
            if y[k] < y[lo] || y[lo].is_nan() {
                lo = k;
            }
            if y[k] > y[hi] || y[hi].is_nan() {
                hi = k;
            }
        }
        let mut keep = [start, lo.min(hi), lo.max(hi)];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for k in keep {
            if k != last {
                xs.push(x[k]);
                ys.push(y[k]);
                last = k;
            }
        }
        start = end;
    }
    (xs, ys)
}

/// Every k-th sample, at most about `points`.
pub fn thin(v: &[f64], points: usize) -> Vec<f64> {
    let step = v.len().div_ceil(points.max(1)).max(1);
    v.iter().step_by(step).copied().collect()
}

/// The zoom window's length in samples: five periods of the oscillation when there is one,
/// else 1000 samples; between 300 and 2000 samples, and never longer than the stretch.
pub fn zoom_length(period_samples: Option<f64>, stretch: usize) -> usize {
    let want = period_samples
        .filter(|p| p.is_finite() && *p > 0.0)
        .map_or(1000.0, |p| 5.0 * p);
    (want.round() as usize).clamp(300, 2000).min(stretch)
}

/// Prefix sums of `v - mean` and of its square (NaN counted as the mean), for window variances.
fn prefix(v: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
    let finite = v.iter().filter(|x| x.is_finite());
    let count = finite.clone().count().max(1) as f64;
    let mean = finite.sum::<f64>() / count;
    let (mut s, mut q) = (vec![0.0; v.len() + 1], vec![0.0; v.len() + 1]);
    for (k, x) in v.iter().enumerate() {
        let d = if x.is_finite() { x - mean } else { 0.0 };
        s[k + 1] = s[k] + d;
        q[k + 1] = q[k] + d * d;
    }
    let total = (q[v.len()] - s[v.len()] * s[v.len()] / v.len().max(1) as f64) / count;
    (s, q, total)
}

/// The start of the window of `len` samples of `op` and `pv` (over the same samples) where they
/// vary most: the largest sum of each signal's variance in the window over its variance in the
/// whole slice. Noise weighs alike everywhere, so the window with the largest oscillation (or
/// the stick-slip episodes with the largest jumps) wins; ties go to the earliest window.
pub fn busiest_window(op: &[f64], pv: &[f64], len: usize) -> usize {
    let n = op.len().min(pv.len());
    if len == 0 || len >= n {
        return 0;
    }
    let (so, qo, vo) = prefix(&op[..n]);
    let (sp, qp, vp) = prefix(&pv[..n]);
    let var = |s: &[f64], q: &[f64], a: usize| {
        let (sum, sq) = (s[a + len] - s[a], q[a + len] - q[a]);
        (sq - sum * sum / len as f64) / len as f64
    };
    let score = |a: usize| {
        var(&so, &qo, a) / vo.max(f64::MIN_POSITIVE) + var(&sp, &qp, a) / vp.max(f64::MIN_POSITIVE)
    };
    let (mut best, mut best_score) = (0, f64::NEG_INFINITY);
    for a in 0..=(n - len) {
        let s = score(a);
        if s > best_score {
            (best, best_score) = (a, s);
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimation_keeps_spikes() {
        let x: Vec<f64> = (0..100_000).map(|k| k as f64).collect();
        let mut y = vec![0.0; 100_000];
        y[54_321] = 9.0;
        y[77_777] = -4.0;
        let (xs, ys) = decimate(&x, &y, 500);
        assert!(xs.len() <= 1500, "{}", xs.len());
        assert!(ys.contains(&9.0) && ys.contains(&-4.0));
        assert!(xs.windows(2).all(|w| w[0] < w[1]), "in time order");
    }

    #[test]
    fn the_busiest_window_holds_the_oscillation() {
        // quiet noise-like wiggle everywhere, a large oscillation in samples 6000..7000
        let n = 20_000;
        let wiggle = |k: usize| 0.01 * ((k * 7919 % 13) as f64 - 6.0);
        let op: Vec<f64> = (0..n)
            .map(|k| {
                let osc = if (6000..7000).contains(&k) {
                    (k as f64 * 0.1).sin()
                } else {
                    0.0
                };
                50.0 + osc + wiggle(k)
            })
            .collect();
        let pv: Vec<f64> = op.iter().map(|v| 2.0 * v).collect();
        let len = zoom_length(Some(62.8), n);
        assert_eq!(len, 314);
        let a = busiest_window(&op, &pv, len);
        assert!((6000..=7000 - len).contains(&a), "{a}");
        assert_eq!(zoom_length(None, 700), 700);
        assert_eq!(zoom_length(Some(1e6), 50_000), 2000);
    }
}
