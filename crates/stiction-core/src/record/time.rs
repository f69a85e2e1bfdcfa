//! The time axis of a record: the column names taken as time, the sampling time, missing times
//! filled in, and the rows put in time order.

/// Column names taken as the time, in this order (any case), when none is named: the common
/// names of historian and spreadsheet exports.
pub const TIME_NAMES: &[&str] = &[
    "t",
    "time",
    "timestamp",
    "time stamp",
    "datetime",
    "date time",
    "date/time",
    "date",
    "zeit",
    "zeitstempel",
    "datum",
];

/// The median step of a time column, if time increases (NaN entries are skipped), rounded to
/// the microsecond: timestamps since 1970 carry about 1e-7 s of float noise.
pub fn sampling_time(t: &[f64]) -> Option<f64> {
    let finite: Vec<f64> = t.iter().copied().filter(|v| v.is_finite()).collect();
    let mut steps: Vec<f64> = finite.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    let ts = steps[steps.len() / 2];
    let rounded = (ts * 1e6).round() / 1e6;
    let ts = if rounded > 0.0 { rounded } else { ts };
    (ts > 0.0 && ts.is_finite()).then_some(ts)
}

/// Fill NaN times by straight lines between their neighbours (by the median step past the
/// ends). False when no time is known.
pub fn fill_times(t: &mut [f64]) -> bool {
    let known: Vec<usize> = (0..t.len()).filter(|&k| t[k].is_finite()).collect();
    let (Some(&first), Some(&last)) = (known.first(), known.last()) else {
        return false;
    };
    // the median step per sample between known times (neighbours or not)
    let mut steps: Vec<f64> = known
        .windows(2)
        .map(|w| (t[w[1]] - t[w[0]]) / (w[1] - w[0]) as f64)
        .collect();
    steps.sort_by(f64::total_cmp);
    let step = steps.get(steps.len() / 2).copied().unwrap_or(1.0);
    for k in 0..first {
        t[k] = t[first] - (first - k) as f64 * step;
    }
    for k in last + 1..t.len() {
        t[k] = t[last] + (k - last) as f64 * step;
    }
    for w in known.windows(2) {
        let (a, b) = (w[0], w[1]);
        for k in a + 1..b {
            t[k] = t[a] + (t[b] - t[a]) * (k - a) as f64 / (b - a) as f64;
        }
    }
    true
}

pub(super) fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// The rows to keep, in time order, when the time is not in order or repeats (the first row of
/// each time kept), with a note; `None` when time only increases.
pub fn time_order(t: &[f64]) -> Option<(Vec<usize>, String)> {
    if t.windows(2).all(|w| w[1] > w[0]) {
        return None;
    }
    let backwards = t.windows(2).filter(|w| w[1] < w[0]).count();
    let mut keep: Vec<usize> = (0..t.len()).collect();
    keep.sort_by(|&a, &b| t[a].total_cmp(&t[b]).then(a.cmp(&b)));
    let before = keep.len();
    keep.dedup_by(|b, a| t[*a] == t[*b]);
    let repeats = before - keep.len();
    let mut said = Vec::new();
    if backwards > 0 {
        said.push(format!(
            "the rows are not in time order ({} back): sorted by time",
            count(backwards, "step goes", "steps go")
        ));
    }
    if repeats > 0 {
        said.push(format!(
            "{} an earlier row's time: the first row of each time is kept",
            count(repeats, "row repeats", "rows repeat")
        ));
    }
    Some((keep, said.join("; ")))
}
