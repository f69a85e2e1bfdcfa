//! The same judgement per window of the record: each window's longest usable stretch is judged by
//! the same families as the whole record.

use super::reasons::{Finding, Reason};
use super::request::DiagnoseRequest;
use super::result::{Verdict, WindowVerdict};
use super::{stretch, Judged, LoopRecord};

/// A verdict per window of `w` samples (a short tail joins the last window).
pub(super) fn judge_windows(
    r: &LoopRecord,
    req: &DiagnoseRequest,
    w: usize,
    judge: fn(&LoopRecord, &DiagnoseRequest) -> Judged,
) -> Vec<WindowVerdict> {
    let n = r.op.len();
    let mut out = Vec::new();
    let mut start = 0;
    while start < n {
        let mut end = (start + w).min(n);
        if n - end < w / 2 {
            end = n;
        }
        let sub = r.slice(start, end);
        let (stretches, _) = stretch::usable(&sub, req);
        let (s, e) = stretches
            .iter()
            .copied()
            .max_by_key(|&(a, b)| (b - a, std::cmp::Reverse(a)))
            .unwrap_or((0, 0));
        let t = |k: usize| r.time.map_or(k as f64 * req.ts, |t| t[k]);
        let mut v = WindowVerdict {
            start,
            end,
            t_start: t(start),
            t_end: t(end - 1),
            verdict: Verdict::InsufficientData,
            probability: None,
            reasons: vec![record(format!(
                "the longest usable stretch has {} samples; a verdict needs at least {}",
                e - s,
                req.min_samples
            ))],
            period: None,
            votes: Vec::new(),
        };
        if e - s >= req.min_samples {
            let judged = sub.slice(s, e);
            match super::gates::still(judged.op, judged.pv) {
                Some((reason, _)) => v.reasons = vec![record(reason)],
                None => {
                    let j = judge(&judged, req);
                    v.verdict = j.decision.verdict;
                    v.probability = j.decision.probability;
                    v.reasons = j.decision.reasons;
                    v.period = j
                        .oscillation
                        .oscillating
                        .then_some(j.oscillation.period)
                        .flatten();
                    v.votes = j.families.iter().map(|f| (f.family, f.vote)).collect();
                }
            }
        }
        out.push(v);
        start = end;
    }
    out
}

fn record(message: String) -> Reason {
    Reason::plain(Finding::Record { message })
}
