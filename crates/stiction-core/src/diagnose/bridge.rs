//! Short gaps bridged before the stretches are cut (see [`crate::record::short_gaps`]): a run of
//! at most three samples with a missing value, inside automatic mode and an unbroken time axis.

use crate::quality::Record;
use crate::record::{bridged, short_gaps};

/// A record's signals with its short gaps filled.
pub(super) struct Bridged {
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
    pub sp: Option<Vec<f64>>,
    pub mv: Option<Vec<f64>>,
    /// The runs bridged, `[start, end)`.
    pub runs: Vec<(usize, usize)>,
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
/// `breaks`: `true` at a sample that starts after a break of the time axis.
pub(super) fn short_gaps_bridged(r: &Record, breaks: &[bool]) -> Option<Bridged> {
    let mut columns = vec![r.op, r.pv];
    columns.extend(r.sp);
    columns.extend(r.mv);
    let joinable = |k: usize| !breaks[k] && r.auto.is_none_or(|a| a[k]);
    let runs = short_gaps(&columns, &joinable);
    if runs.is_empty() {
        return None;
    }
    Some(Bridged {
        op: bridged(r.op, &runs),
        pv: bridged(r.pv, &runs),
        sp: r.sp.map(|v| bridged(v, &runs)),
        mv: r.mv.map(|v| bridged(v, &runs)),
        runs,
    })
}
