//! Preparing a loop record from its columns, as every front end needs it: the CLI from a file's
//! table, the Python package from a pandas DataFrame or numpy arrays. Gaps are NaN; a row whose
//! time is missing is a gap and its time is filled in between its neighbours; rows are put in
//! time order (a row repeating a time dropped); the sampling time is the median step; a merge of
//! signals stored at their own times goes on a regular grid (`own_times`); short gaps can be
//! bridged (`gaps`).
//!
//! Pure functions over slices: the signals are borrowed ([`Cow`]) and copied only when a gap in
//! time or the time order calls for it, so a front end reads its arrays without copies.

use crate::diagnose::LoopRecord;
use std::borrow::Cow;

mod cells;
mod gaps;
mod numbers;
mod own_times;
mod time;
pub use cells::{is_missing, mode_word};
pub use gaps::{bridged, bridged_note, longest_clean, short_gaps};
pub use numbers::{parse_number, parse_number_grouped, Grouping};
pub use own_times::OWN_TIMES_SHARE;
use time::count;
pub use time::{fill_times, sampling_time, time_order, TIME_NAMES};

/// The signals of one loop, as columns (gaps NaN; `auto` `true` where the controller is in
/// automatic; `time` in seconds).
#[derive(Debug, Clone)]
pub struct Signals<'a> {
    /// The controller output (op), normally % of valve span.
    pub op: Cow<'a, [f64]>,
    /// The process variable (pv).
    pub pv: Cow<'a, [f64]>,
    /// The setpoint (sp), when recorded.
    pub sp: Option<Cow<'a, [f64]>>,
    /// The recorded valve position (mv), when recorded.
    pub mv: Option<Cow<'a, [f64]>>,
    /// The controller mode, `true` in automatic, when recorded.
    pub auto: Option<Cow<'a, [bool]>>,
    /// Time of each sample, seconds, when recorded.
    pub time: Option<Cow<'a, [f64]>>,
}

impl<'a> Signals<'a> {
    /// Borrowed signals without sp, mv, mode or time.
    pub fn new(op: &'a [f64], pv: &'a [f64]) -> Signals<'a> {
        Signals {
            op: Cow::Borrowed(op),
            pv: Cow::Borrowed(pv),
            sp: None,
            mv: None,
            auto: None,
            time: None,
        }
    }

    /// The record `diagnose` judges.
    pub fn record(&self) -> LoopRecord<'_> {
        LoopRecord {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            mv: self.mv.as_deref(),
            time: self.time.as_deref(),
            auto: self.auto.as_deref(),
        }
    }
}

/// A record ready for `diagnose`: its signals in time order, the sampling time, and what was
/// decided on the way.
#[derive(Debug, Clone)]
pub struct Prepared<'a> {
    /// The signals, in time order.
    pub signals: Signals<'a>,
    /// Sampling time, seconds.
    pub ts: f64,
    /// What a person should know (rows sorted, repeated times dropped, no time values).
    pub notes: Vec<String>,
    /// The input row of each sample, when the rows were sorted by time or put on a grid (else
    /// sample k is row k).
    pub rows: Option<Vec<usize>>,
    /// Whether the signals were stored at their own times and put on a regular grid (their
    /// blank cells then stand for "nothing stored here", not for missing data).
    pub on_grid: bool,
    /// Whether the setpoint was stored only when it changed, and each value was held until the
    /// next (its blank cells are not missing data).
    pub setpoint_held: bool,
}

/// Why a record cannot be prepared.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PrepareError {
    /// The sampling time (seconds) given is not a positive number.
    #[error("the sampling time must be a positive number of seconds, got {0}")]
    Ts(f64),
    /// The time column does not increase, so no sampling time follows from it.
    #[error("the time column does not increase; give the sampling time")]
    TimeNotIncreasing,
    /// A signal's length differs from OP's.
    #[error("{signal} has {len} samples but op has {op}: the signals must have the same length")]
    Length {
        /// Which signal (`pv`, `sp`, `mv`, `mode` or `time`).
        signal: &'static str,
        /// Its samples.
        len: usize,
        /// Samples of OP.
        op: usize,
    },
}

fn check_lengths(s: &Signals) -> Result<(), PrepareError> {
    let op = s.op.len();
    let lens = [
        ("pv", Some(s.pv.len())),
        ("sp", s.sp.as_ref().map(|v| v.len())),
        ("mv", s.mv.as_ref().map(|v| v.len())),
        ("mode", s.auto.as_ref().map(|v| v.len())),
        ("time", s.time.as_ref().map(|v| v.len())),
    ];
    for (signal, len) in lens {
        if let Some(len) = len.filter(|&l| l != op) {
            return Err(PrepareError::Length { signal, len, op });
        }
    }
    Ok(())
}

/// Prepare a record: a sample without its time becomes a gap (its time filled in), rows are put
/// in time order, and the sampling time is `ts` if given, else the median step of the time,
/// else 1 s. A record whose signals were stored at their own times (most rows partly blank: a
/// merge of a historian's recorded values) is put on a regular grid every `ts` seconds.
pub fn prepare<'a>(mut s: Signals<'a>, ts: Option<f64>) -> Result<Prepared<'a>, PrepareError> {
    if let Some(ts) = ts {
        if !(ts > 0.0 && ts.is_finite()) {
            return Err(PrepareError::Ts(ts));
        }
    }
    check_lengths(&s)?;
    let mut notes = Vec::new();
    if let Some(t) = s.time.as_deref() {
        let missing: Vec<usize> = (0..t.len()).filter(|&k| t[k].is_nan()).collect();
        if !missing.is_empty() {
            gaps_where_time_is_missing(&mut s, &missing);
        }
    }
    if let Some(t) = &mut s.time {
        if t.iter().any(|v| v.is_nan()) && !fill_times(t.to_mut()) {
            notes.push("the time column has no values; it is left out".into());
            s.time = None;
        }
    }
    let mut rows = None;
    if let Some((keep, note)) = s.time.as_deref().and_then(time_order) {
        notes.push(note);
        reorder(&mut s, &keep);
        rows = Some(keep);
    }
    let ts = match (ts, s.time.as_deref()) {
        (Some(ts), _) => ts,
        (None, Some(t)) => sampling_time(t).ok_or(PrepareError::TimeNotIncreasing)?,
        (None, None) => {
            notes.push(
                "no time column and no sampling time given: the samples are taken as 1 s apart (give the sampling time, or name the time column)"
                    .into(),
            );
            1.0
        }
    };
    let mut on_grid = false;
    if let Some(blank) = own_times::stored_at_own_times(&s) {
        if let Some((grid, grid_rows)) = own_times::on_grid(&s, ts) {
            notes.push(own_times::note(&blank, s.op.len(), grid.op.len(), ts));
            rows = Some(match &rows {
                Some(keep) => grid_rows.iter().map(|&r| keep[r]).collect(),
                None => grid_rows,
            });
            s = grid;
            on_grid = true;
        }
    }
    let mut setpoint_held = false;
    if let (false, Some(blank)) = (on_grid, own_times::setpoint_on_change(&s)) {
        if let Some(sp) = s.sp.as_mut() {
            let stored = sp.len() - blank;
            *sp = Cow::Owned(own_times::held(sp));
            notes.push(format!(
                "the setpoint is stored only when it changes ({} blank between {}): each value is held until the next",
                count(blank, "cell", "cells"),
                count(stored, "stored value", "stored values")
            ));
            setpoint_held = true;
        }
    }
    Ok(Prepared {
        signals: s,
        ts,
        notes,
        rows,
        on_grid,
        setpoint_held,
    })
}

/// A row without its time is a gap in op, pv, sp and mv.
fn gaps_where_time_is_missing(s: &mut Signals, missing: &[usize]) {
    for v in [
        Some(&mut s.op),
        Some(&mut s.pv),
        s.sp.as_mut(),
        s.mv.as_mut(),
    ]
    .into_iter()
    .flatten()
    {
        let v = v.to_mut();
        for &k in missing {
            v[k] = f64::NAN;
        }
    }
}

fn pick<T: Copy>(v: &[T], keep: &[usize]) -> Vec<T> {
    keep.iter().map(|&k| v[k]).collect()
}

/// Keep the rows `keep`, in that order, in every signal.
fn reorder(s: &mut Signals, keep: &[usize]) {
    s.op = Cow::Owned(pick(&s.op, keep));
    s.pv = Cow::Owned(pick(&s.pv, keep));
    for v in [s.sp.as_mut(), s.mv.as_mut(), s.time.as_mut()]
        .into_iter()
        .flatten()
    {
        *v = Cow::Owned(pick(v, keep));
    }
    if let Some(a) = s.auto.as_mut() {
        *a = Cow::Owned(pick(a, keep));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_times_are_filled_between_neighbours() {
        let nan = f64::NAN;
        let mut t = [nan, 1.0, nan, nan, 4.0, nan];
        assert!(fill_times(&mut t));
        assert_eq!(t, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        assert!(!fill_times(&mut [nan, nan]));
    }

    #[test]
    fn rows_are_sorted_and_repeats_dropped() {
        assert!(time_order(&[0.0, 1.0, 2.0]).is_none());
        let (keep, note) = time_order(&[0.0, 2.0, 1.0, 2.0, 3.0]).unwrap();
        assert_eq!(keep, vec![0, 2, 1, 4]);
        assert!(
            note.contains("1 step goes back") && note.contains("1 row repeats"),
            "{note}"
        );
    }

    #[test]
    fn signals_in_order_are_not_copied() {
        let op = [1.0, 2.0, 3.0];
        let pv = [0.0, 0.5, 1.0];
        let t = [0.0, 2.0, 4.0];
        let mut s = Signals::new(&op, &pv);
        s.time = Some(Cow::Borrowed(&t));
        let p = prepare(s, None).unwrap();
        assert_eq!(p.ts, 2.0);
        assert!(matches!(p.signals.op, Cow::Borrowed(_)));
        assert!(p.rows.is_none() && p.notes.is_empty());
    }

    #[test]
    fn a_row_without_time_is_a_gap_and_rows_are_sorted() {
        let nan = f64::NAN;
        let op = [1.0, 2.0, 3.0, 4.0];
        let pv = [0.0, 0.5, 1.0, 1.5];
        let sp = [5.0; 4];
        let t = [0.0, nan, 3.0, 2.0];
        let mut s = Signals::new(&op, &pv);
        s.sp = Some(Cow::Borrowed(&sp));
        s.time = Some(Cow::Borrowed(&t));
        let p = prepare(s, None).unwrap();
        // t filled to [0, 1.5, 3, 2], then sorted: rows 0, 1, 3, 2
        assert_eq!(p.rows, Some(vec![0, 1, 3, 2]));
        assert!(p.signals.op[1].is_nan() && p.signals.sp.as_ref().unwrap()[1].is_nan());
        assert_eq!(p.signals.op[2], 4.0);
        assert_eq!(
            prepare(Signals::new(&op, &pv[..2]), None).unwrap_err(),
            PrepareError::Length {
                signal: "pv",
                len: 2,
                op: 4
            }
        );
        assert_eq!(
            prepare(Signals::new(&op, &pv), Some(0.0)).unwrap_err(),
            PrepareError::Ts(0.0)
        );
    }
}
