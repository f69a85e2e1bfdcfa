//! Exports of recorded values: a historian stores each tag at its own times (on change, past its
//! exception and compression deviations), and an export of several tags, or an outer join of
//! per-tag exports, puts them on the union of those times. Most rows then hold one signal and
//! leave the others blank: the blanks are not missing data but "nothing stored here". Read as
//! gaps they cut the record to pieces. So such a record is put on a regular time grid, each
//! signal interpolated between its own stored values as the historian interpolates them
//! (straight lines for OP, PV and MV; the setpoint held, as a step signal; the mode as read at
//! or before each grid time).

use super::{count, Signals};
use std::borrow::Cow;

/// A record is taken as stored at its signals' own times when at least this share of its rows
/// hold some signals and leave others blank.
pub const OWN_TIMES_SHARE: f64 = 0.2;
/// ... and the blank runs of a signal (rows in a row) are at most this long at the median: the
/// signals interleave (one long blank run is an outage, not a merge).
const INTERLEAVED_RUN: usize = 3;
/// Stored values further apart than this share of the record's time span are not joined: the
/// grid has a gap there.
const LONGEST_JOIN: f64 = 0.1;
/// The regular grid may have at most this many times the rows (and this many more).
const GRID_PER_ROW: usize = 20;
const GRID_EXTRA: usize = 10_000;

/// The blank cells of each signal (name, count), when the rows look like a merge of signals
/// stored at their own times: a time column, at least [`OWN_TIMES_SHARE`] of the rows partly
/// blank, every signal stored at least twice, and the blanks interleaved with stored values
/// (median blank run at most [`INTERLEAVED_RUN`] rows).
pub(super) fn stored_at_own_times(s: &Signals) -> Option<Vec<(&'static str, usize)>> {
    s.time.as_ref()?;
    let columns = numeric(s);
    let n = s.op.len();
    let partly = (0..n)
        .filter(|&k| {
            let present = columns.iter().filter(|(_, v)| v[k].is_finite()).count();
            present > 0 && present < columns.len()
        })
        .count();
    let stored_twice = columns
        .iter()
        .all(|(_, v)| v.iter().filter(|x| x.is_finite()).count() >= 2);
    let interleaved = columns.iter().all(|(_, v)| {
        let mut runs = blank_runs(v);
        runs.sort_unstable();
        runs.get(runs.len() / 2)
            .is_none_or(|&r| r <= INTERLEAVED_RUN)
    });
    let merged = partly as f64 >= OWN_TIMES_SHARE * n as f64 && stored_twice && interleaved;
    (n > 0 && merged).then(|| {
        columns
            .iter()
            .map(|(name, v)| (*name, v.iter().filter(|x| !x.is_finite()).count()))
            .filter(|(_, k)| *k > 0)
            .collect()
    })
}

/// The lengths of `v`'s runs of blank (non-finite) cells.
fn blank_runs(v: &[f64]) -> Vec<usize> {
    let mut runs = Vec::new();
    let mut run = 0;
    for x in v {
        if x.is_finite() {
            if run > 0 {
                runs.push(run);
            }
            run = 0;
        } else {
            run += 1;
        }
    }
    if run > 0 {
        runs.push(run);
    }
    runs
}

fn numeric<'b>(s: &'b Signals) -> Vec<(&'static str, &'b [f64])> {
    let mut columns = vec![("op", &*s.op), ("pv", &*s.pv)];
    columns.extend(s.sp.as_deref().map(|v| ("sp", v)));
    columns.extend(s.mv.as_deref().map(|v| ("mv", v)));
    columns
}

/// The signals on a regular grid every `ts` seconds from the first time to the last, each
/// interpolated between its own stored values (NaN before its first and after its last), and
/// the row at or before each grid time; `None` when the grid would be too long.
pub(super) fn on_grid(s: &Signals, ts: f64) -> Option<(Signals<'static>, Vec<usize>)> {
    let t = s.time.as_deref()?;
    let (first, last) = (*t.first()?, *t.last()?);
    let samples = ((last - first) / ts + 1e-9).floor() as usize + 1;
    if samples > GRID_PER_ROW * t.len() + GRID_EXTRA {
        return None;
    }
    let grid: Vec<f64> = (0..samples).map(|k| first + k as f64 * ts).collect();
    let mut rows = Vec::with_capacity(samples);
    let mut r = 0;
    for &g in &grid {
        while r + 1 < t.len() && t[r + 1] <= g + 1e-9 * ts {
            r += 1;
        }
        rows.push(r);
    }
    let line = |v: &[f64]| interpolated(t, v, &grid);
    // the setpoint held: each row's last stored value, once, then picked at each grid time
    let held_sp = |v: &[f64]| {
        let by_row = held(v);
        rows.iter().map(|&r| by_row[r]).collect::<Vec<f64>>()
    };
    let signals = Signals {
        op: Cow::Owned(line(&s.op)),
        pv: Cow::Owned(line(&s.pv)),
        sp: s.sp.as_deref().map(|v| Cow::Owned(held_sp(v))),
        mv: s.mv.as_deref().map(|v| Cow::Owned(line(v))),
        auto: s
            .auto
            .as_deref()
            .map(|a| Cow::Owned(rows.iter().map(|&r| a[r]).collect())),
        time: Some(Cow::Owned(grid)),
    };
    Some((signals, rows))
}

/// `v` (stored where finite, at times `t`) by straight lines at the times `grid`; not across
/// stored values further apart than [`LONGEST_JOIN`] of the time span.
fn interpolated(t: &[f64], v: &[f64], grid: &[f64]) -> Vec<f64> {
    let longest = LONGEST_JOIN * (t[t.len() - 1] - t[0]);
    let stored: Vec<(f64, f64)> = t
        .iter()
        .zip(v)
        .filter(|(_, x)| x.is_finite())
        .map(|(&a, &b)| (a, b))
        .collect();
    let mut out = Vec::with_capacity(grid.len());
    let mut j = 0;
    for &g in grid {
        while j + 1 < stored.len() && stored[j + 1].0 <= g {
            j += 1;
        }
        let value = match (stored.get(j), stored.get(j + 1)) {
            (Some(&(ta, a)), _) if ta == g => a,
            (Some(&(ta, a)), Some(&(tb, b))) if ta < g && tb - ta <= longest => {
                a + (b - a) * (g - ta) / (tb - ta)
            }
            _ => f64::NAN,
        };
        out.push(value);
    }
    out
}

/// The blank cells of a setpoint stored only when it changes (a step tag, as historians and
/// hand-made sheets keep it): blank in at least [`OWN_TIMES_SHARE`] of the rows where OP and PV
/// are present, and stored at least once.
pub(super) fn setpoint_on_change(s: &Signals) -> Option<usize> {
    let sp = s.sp.as_deref()?;
    let n = sp.len();
    let blank = (0..n)
        .filter(|&k| !sp[k].is_finite() && s.op[k].is_finite() && s.pv[k].is_finite())
        .count();
    let stored = sp.iter().filter(|x| x.is_finite()).count();
    (stored > 0 && n > 0 && blank as f64 >= OWN_TIMES_SHARE * n as f64).then(|| n - stored)
}

/// `v` with each stored value held until the next (blank before the first).
pub(super) fn held(v: &[f64]) -> Vec<f64> {
    let mut last = f64::NAN;
    v.iter()
        .map(|&x| {
            if x.is_finite() {
                last = x;
            }
            last
        })
        .collect()
}

/// The note for a record put on the grid.
pub(super) fn note(blank: &[(&str, usize)], rows: usize, samples: usize, ts: f64) -> String {
    let which: Vec<String> = blank.iter().map(|(n, k)| format!("{n} {k}")).collect();
    format!(
        "the signals are stored at their own times (a merge of a historian's recorded values: {} blank between stored values, {which}): each is interpolated between its stored values onto a grid every {ts} s ({} from {}), OP, PV and MV by straight lines, the setpoint held, the mode as read at or before each grid time; give --ts to choose the grid",
        count(blank.iter().map(|(_, k)| k).sum(), "cell", "cells"),
        count(samples, "sample", "samples"),
        count(rows, "row", "rows"),
        which = which.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_between_stored_values_and_nothing_past_them() {
        let t = [0.0, 1.0, 2.0, 4.0, 40.0];
        let v = [f64::NAN, 10.0, f64::NAN, 14.0, 14.0];
        let out = interpolated(&t, &v, &[0.0, 1.0, 2.5, 4.0]);
        assert!(out[0].is_nan());
        assert_eq!(&out[1..], &[10.0, 12.0, 14.0]);
        // stored values further apart than a tenth of the span are not joined
        let t: Vec<f64> = (0..100).map(f64::from).collect();
        let mut v = t.clone();
        v[40..60].fill(f64::NAN);
        let out = interpolated(&t, &v, &t);
        assert!(out[45].is_nan() && out[39] == 39.0 && out[60] == 60.0);
        v[45..60].copy_from_slice(&t[45..60]);
        assert_eq!(interpolated(&t, &v, &t)[42], 42.0);
        assert_eq!(held(&[1.0, f64::NAN, 3.0, f64::NAN])[3], 3.0);
        assert!(held(&[f64::NAN, 2.0])[0].is_nan());
        let h = held(&[f64::NAN, 1.0, f64::NAN, f64::NAN, 3.0, f64::NAN]);
        assert!(h[0].is_nan());
        assert_eq!(&h[1..], &[1.0, 1.0, 1.0, 3.0, 3.0]);
    }

    #[test]
    fn a_merge_of_recorded_values_goes_on_a_regular_grid() {
        // op stored at even seconds, pv at odd ones and at 0
        let n = 50;
        let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let op: Vec<f64> = (0..n)
            .map(|k| if k % 2 == 0 { k as f64 } else { f64::NAN })
            .collect();
        let pv: Vec<f64> = (0..n)
            .map(|k| {
                if k % 2 == 1 || k == 0 {
                    2.0 * k as f64
                } else {
                    f64::NAN
                }
            })
            .collect();
        let mut s = Signals::new(&op, &pv);
        s.time = Some(Cow::Borrowed(&t));
        let blank = stored_at_own_times(&s).expect("a merge");
        assert_eq!(blank, vec![("op", 25), ("pv", 24)]);
        let (g, rows) = on_grid(&s, 1.0).unwrap();
        assert_eq!(g.op.len(), n);
        assert_eq!(
            g.op[..n - 1],
            (0..n - 1).map(|k| k as f64).collect::<Vec<_>>()[..]
        );
        assert!(g.op[n - 1].is_nan(), "past op's last stored value");
        assert_eq!(g.pv[2], 4.0);
        assert_eq!(rows[7], 7);
        // a setpoint stored only when it changes, beside dense OP and PV
        let sp: Vec<f64> = (0..n)
            .map(|k| match k {
                0 => 50.0,
                20 => 51.0,
                _ => f64::NAN,
            })
            .collect();
        let mut s4 = Signals::new(&t, &t);
        s4.sp = Some(Cow::Borrowed(&sp));
        assert_eq!(setpoint_on_change(&s4), Some(n - 2));
        s4.sp = Some(Cow::Borrowed(&t));
        assert_eq!(setpoint_on_change(&s4), None);
        // an outage (one long blank run on a regular time axis) is not a merge
        let mut pv3 = t.clone();
        pv3[10..30].fill(f64::NAN);
        let mut s3 = Signals::new(&t, &pv3);
        s3.time = Some(Cow::Borrowed(&t));
        assert!(stored_at_own_times(&s3).is_none());
        // nor a record with a few gaps
        let mut op2 = t.clone();
        op2[3] = f64::NAN;
        let mut s2 = Signals::new(&op2, &t);
        s2.time = Some(Cow::Borrowed(&t));
        assert!(stored_at_own_times(&s2).is_none());
    }
}
