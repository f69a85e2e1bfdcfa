//! Short gaps bridged: a missing cell or two in a long record (a historian's "Bad Input", a
//! blank) would otherwise cut it into stretches, and only the longest is judged. A run of at
//! most [`MAX_RUN`] samples with a missing value, inside automatic mode and without a break of
//! the time axis, is filled by a straight line between its neighbours, when such runs hold at
//! most [`MAX_SHARE`] of the record. Longer gaps, or more of them, still split the record.

use crate::quality::Record;

/// The longest run of samples bridged.
pub(super) const MAX_RUN: usize = 3;
/// Bridged samples may be at most this share of the record.
pub(super) const MAX_SHARE: f64 = 0.01;

/// A record's signals with its short gaps filled.
pub(super) struct Bridged {
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
    pub sp: Option<Vec<f64>>,
    pub mv: Option<Vec<f64>>,
    /// Runs bridged and the samples in them.
    pub runs: usize,
    pub samples: usize,
}

impl Bridged {
    /// The bridged record (time and mode as recorded).
    pub fn record<'a>(&'a self, r: &Record<'a>) -> Record<'a> {
        Record {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            mv: self.mv.as_deref(),
            time: r.time,
            auto: r.auto,
        }
    }
}

/// The record with its short gaps bridged, or `None` when there is none to bridge (or too many).
pub(super) fn short_gaps(r: &Record, breaks: &[bool]) -> Option<Bridged> {
    let n = r.op.len();
    let missing = |k: usize| {
        !(r.op[k].is_finite()
            && r.pv[k].is_finite()
            && r.sp.is_none_or(|s| s[k].is_finite())
            && r.mv.is_none_or(|m| m[k].is_finite()))
    };
    let manual = |k: usize| r.auto.is_some_and(|a| !a[k]);
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
        // [start, k) missing; bridge it between start - 1 and k when both are usable
        let inside = k < n && !missing(start - 1);
        let short = k - start <= MAX_RUN;
        let joined = (start..=k.min(n - 1)).all(|j| !breaks[j] && !manual(j)) && !manual(start - 1);
        if inside && short && joined {
            runs.push((start, k));
        }
    }
    let samples: usize = runs.iter().map(|(a, b)| b - a).sum();
    if runs.is_empty() || samples as f64 > MAX_SHARE * n as f64 {
        return None;
    }
    let fill = |v: &[f64]| {
        let mut out = v.to_vec();
        for &(a, b) in &runs {
            let (left, right) = (v[a - 1], v[b]);
            for (j, o) in out[a..b].iter_mut().enumerate() {
                if !o.is_finite() {
                    let f = (j + 1) as f64 / (b - a + 1) as f64;
                    *o = left + f * (right - left);
                }
            }
        }
        out
    };
    Some(Bridged {
        op: fill(r.op),
        pv: fill(r.pv),
        sp: r.sp.map(fill),
        mv: r.mv.map(fill),
        runs: runs.len(),
        samples,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_cell_is_bridged_by_a_straight_line() {
        let op: Vec<f64> = (0..400).map(|k| k as f64).collect();
        let mut pv = op.clone();
        pv[100] = f64::NAN;
        pv[200] = f64::NAN;
        pv[201] = f64::NAN;
        let b = short_gaps(&Record::new(&op, &pv), &vec![false; 400]).expect("two short gaps");
        assert_eq!((b.runs, b.samples), (2, 3));
        assert!((b.pv[100] - 100.0).abs() < 1e-12);
        assert!((b.pv[200] - 200.0).abs() < 1e-12 && (b.pv[201] - 201.0).abs() < 1e-12);
        assert_eq!(b.op, op);
    }

    #[test]
    fn long_gaps_edges_breaks_and_many_gaps_are_left_to_split_the_record() {
        let op = vec![1.0; 400];
        let mut pv = vec![2.0; 400];
        pv[50..54].fill(f64::NAN); // four samples: too long
        pv[0] = f64::NAN; // at the edge: nothing to bridge from
        pv[399] = f64::NAN;
        assert!(short_gaps(&Record::new(&op, &pv), &vec![false; 400]).is_none());
        let mut pv = vec![2.0; 400];
        pv[100] = f64::NAN;
        let mut breaks = vec![false; 400];
        breaks[101] = true; // the time axis breaks right after the gap
        assert!(short_gaps(&Record::new(&op, &pv), &breaks).is_none());
        let mut pv = vec![2.0; 400];
        for k in (10..400).step_by(50) {
            pv[k] = f64::NAN; // 8 gaps: 2 % of the record
        }
        assert!(short_gaps(&Record::new(&op, &pv), &vec![false; 400]).is_none());
    }
}
