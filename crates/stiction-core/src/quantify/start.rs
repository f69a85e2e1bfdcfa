//! Where the valve stood at the first sample.

use super::search::quantify_inner;
use super::{problem::range, QuantifyRequest, QuantifyStatus};
use crate::checked::Checked;

/// A record rarely starts just as the valve moved, and a Stenman valve started elsewhere can stay
/// out of step with the real one for good. Each candidate position at the first sample (the first
/// OP and a spread across the span OP covers) gets a search of `op`, `pv` (the exact search
/// around its best grid points); the one that fits best is returned, with the evaluations spent.
pub(super) fn best_start(
    op: &[f64],
    pv: &[f64],
    req: &Checked<QuantifyRequest>,
) -> (Option<f64>, u64) {
    let local = req.adjust(|r| {
        r.staged = false;
        r.full_partition = false;
    });
    let mut evaluations = 0;
    let mut best: Option<(f64, f64)> = None;
    for x0 in start_candidates(op) {
        // a candidate is a finite OP value: the request stays valid
        let at = local.adjust(|r| r.valve_start = Some(x0));
        let Ok((q, _)) = quantify_inner(op, pv, &at, None) else {
            continue;
        };
        evaluations += q.evaluations;
        if let Some(sse) = q.fit.as_ref().map(|f| f.sse_simulation) {
            if q.status == QuantifyStatus::Ok && best.is_none_or(|b| sse < b.0) {
                best = Some((sse, x0));
            }
        }
    }
    (best.map(|b| b.1), evaluations)
}

/// Candidate valve positions at the first sample: the first OP, and a spread across the span
/// OP covers in `op` (a valve that sticks stands anywhere within its band of the command).
fn start_candidates(op: &[f64]) -> Vec<f64> {
    let Some(&u0) = op.first() else {
        return Vec::new();
    };
    let (lo, hi) = range(op);
    let span = hi - lo;
    let mut out = vec![u0];
    for f in [-0.5, -0.25, 0.25, 0.5] {
        let x = (u0 + f * span).clamp(lo, hi);
        if out.iter().all(|&y| (y - x).abs() > 0.05 * span) {
            out.push(x);
        }
    }
    out
}
