//! Gaps in a record's columns: the longest run without one (what a fit needs), and short gaps
//! bridged. A missing cell or two in a long record (a historian's "Bad Input", a blank) would
//! otherwise cut it, and only the longest stretch would be used: a run of at most
//! [`BRIDGE_MAX_RUN`] rows with a missing value, between rows where every column is present, is
//! filled by a straight line between its neighbours, when such runs hold at most
//! [`BRIDGE_MAX_SHARE`] of the record. Longer gaps, or more of them, are left to split it.

/// The longest run of rows bridged.
const BRIDGE_MAX_RUN: usize = 3;
/// Bridged rows may be at most this share of the record.
const BRIDGE_MAX_SHARE: f64 = 0.01;

/// The longest run of rows `[start, end)` where every column holds a finite value (the first such
/// run when several are equally long); `None` when no row does. Fits (`quantify`, `estimate`)
/// use it: they need a record without gaps.
pub fn longest_clean(columns: &[&[f64]]) -> Option<(usize, usize)> {
    let n = columns.iter().map(|c| c.len()).min()?;
    let clean = |k: usize| columns.iter().all(|c| c[k].is_finite());
    let mut best: Option<(usize, usize)> = None;
    let mut start = None;
    for k in 0..=n {
        match (start, k < n && clean(k)) {
            (None, true) => start = Some(k),
            (Some(s), false) => {
                if best.is_none_or(|(a, b)| k - s > b - a) {
                    best = Some((s, k));
                }
                start = None;
            }
            _ => {}
        }
    }
    best
}

/// The runs of rows `[start, end)` with a missing value in some column that can be bridged: at
/// most `BRIDGE_MAX_RUN` rows, a present row on either side, and `joinable` true from the row
/// before to the row after (no break of the time axis, no manual mode, as the caller judges).
/// Empty when there is none, or when they would hold more than `BRIDGE_MAX_SHARE` of the rows.
pub fn short_gaps(columns: &[&[f64]], joinable: &dyn Fn(usize) -> bool) -> Vec<(usize, usize)> {
    let n = columns.iter().map(|c| c.len()).min().unwrap_or(0);
    let missing = |k: usize| columns.iter().any(|c| !c[k].is_finite());
    let mut runs = Vec::new();
    let mut k = 1;
    while k < n {
        if !missing(k) {
            k += 1;
            continue;
        }
        let start = k;
        while k < n && missing(k) {
            k += 1;
        }
        let inside = k < n && !missing(start - 1);
        if inside && k - start <= BRIDGE_MAX_RUN && (start - 1..=k).all(joinable) {
            runs.push((start, k));
        }
    }
    let rows: usize = runs.iter().map(|(a, b)| b - a).sum();
    if rows as f64 > BRIDGE_MAX_SHARE * n as f64 {
        runs.clear();
    }
    runs
}

/// `v` with its missing values in `runs` filled by straight lines between the runs' neighbours
/// (present values kept).
pub fn bridged(v: &[f64], runs: &[(usize, usize)]) -> Vec<f64> {
    let mut out = v.to_vec();
    for &(a, b) in runs {
        let (left, right) = (v[a - 1], v[b]);
        for (j, o) in out[a..b].iter_mut().enumerate() {
            if !o.is_finite() {
                *o = left + (j + 1) as f64 / (b - a + 1) as f64 * (right - left);
            }
        }
    }
    out
}

/// The note for bridged `runs`: "3 short gaps (4 rows with a missing value) bridged ...".
pub fn bridged_note(runs: &[(usize, usize)], rows: (&str, &str)) -> String {
    let count =
        |k: usize, one: &str, many: &str| format!("{k} {}", if k == 1 { one } else { many });
    let filled: usize = runs.iter().map(|(a, b)| b - a).sum();
    format!(
        "{} ({} with a missing value) bridged by straight lines between their neighbours, so they do not split the record (at most {BRIDGE_MAX_RUN} in a row and {} % of the record are bridged)",
        count(runs.len(), "short gap", "short gaps"),
        count(filled, rows.0, rows.1),
        BRIDGE_MAX_SHARE * 100.0
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_clean_run() {
        let nan = f64::NAN;
        let a = [1.0, nan, 1.0, 1.0, 1.0, 1.0, nan];
        let b = [1.0, 1.0, 1.0, nan, 1.0, 1.0, 1.0];
        assert_eq!(longest_clean(&[&a, &b]), Some((4, 6)));
        assert_eq!(longest_clean(&[&a]), Some((2, 6)));
        assert_eq!(longest_clean(&[&[nan, nan]]), None);
        assert_eq!(longest_clean(&[&[]]), None);
    }

    #[test]
    fn a_missing_cell_is_bridged_by_a_straight_line() {
        let op: Vec<f64> = (0..400).map(|k| k as f64).collect();
        let mut pv = op.clone();
        pv[100] = f64::NAN;
        pv[200] = f64::NAN;
        pv[201] = f64::NAN;
        let runs = short_gaps(&[&op, &pv], &|_| true);
        assert_eq!(runs, vec![(100, 101), (200, 202)]);
        let b = bridged(&pv, &runs);
        assert_eq!(b, op);
        assert_eq!(bridged(&op, &runs), op);
        assert!(bridged_note(&runs, ("sample", "samples"))
            .starts_with("2 short gaps (3 samples with a missing value) bridged"));
    }

    #[test]
    fn long_gaps_edges_breaks_and_many_gaps_are_left_to_split_the_record() {
        let op = vec![1.0; 400];
        let mut pv = vec![2.0; 400];
        pv[50..54].fill(f64::NAN); // four rows: too long
        pv[0] = f64::NAN; // at the edges: nothing to bridge from
        pv[399] = f64::NAN;
        assert!(short_gaps(&[&op, &pv], &|_| true).is_empty());
        let mut pv = vec![2.0; 400];
        pv[100] = f64::NAN;
        // the time axis breaks right after the gap
        assert!(short_gaps(&[&op, &pv], &|k| k != 101).is_empty());
        let mut pv = vec![2.0; 400];
        for k in (10..400).step_by(50) {
            pv[k] = f64::NAN; // 8 gaps: 2 % of the record
        }
        assert!(short_gaps(&[&op, &pv], &|_| true).is_empty());
    }
}
