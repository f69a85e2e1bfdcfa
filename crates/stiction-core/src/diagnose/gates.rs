//! The data-quality findings of a record: what was left out and why, and the look-alikes the
//! families must not read as stiction (historian compression, a frozen or quantised PV). Only a
//! record too short to judge stops a verdict; the rest is reported and taken into account.

use super::request::DiagnoseRequest;
use super::stretch::Excluded;
use crate::quality::{self, Finding, Gate, Record};

/// `n` and the noun's singular or plural form: "1 gap", "3 gaps".
pub(crate) fn plural(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

fn finding(gate: Gate, passed: bool, value: f64, limit: f64, message: String) -> Finding {
    Finding {
        gate,
        passed,
        value,
        limit,
        message,
    }
}

/// The findings for the analysed stretch `[s, e)` of `r`.
pub(super) fn findings(
    r: &Record,
    (s, e): (usize, usize),
    stretches: usize,
    excluded: &Excluded,
    req: &DiagnoseRequest,
) -> Vec<Finding> {
    let n = r.op.len();
    let used = e - s;
    let mut out = vec![finding(
        Gate::RecordLength,
        used >= req.min_samples,
        used as f64,
        req.min_samples as f64,
        if used == n {
            plural(n, "sample", "samples")
        } else {
            format!(
                "samples {s} to {e} analysed ({used} of {n}, the longest of {}); left out: {}",
                plural(stretches, "usable stretch", "usable stretches"),
                left_out(excluded)
            )
        },
    )];
    out.extend(left_out_findings(excluded, n, req));
    if excluded.time_breaks > 0 {
        out.push(finding(
            Gate::TimeGaps,
            false,
            excluded.time_breaks as f64,
            0.0,
            format!(
                "{} in the time axis (steps longer than {} sampling times, or time not increasing): the record is split there",
                plural(excluded.time_breaks, "break", "breaks"),
                req.limits.gap_steps
            ),
        ));
    }
    let pv = &r.pv[s..e];
    let unrecorded = quality::unrecorded(pv);
    let share = unrecorded.iter().filter(|&&u| u).count() as f64 / used.max(1) as f64;
    out.push(finding(
        Gate::PvCompressed,
        share <= req.limits.repeated_share,
        share,
        req.limits.repeated_share,
        format!(
            "PV repeats itself or runs in exactly straight lines in {:.0} % of the samples (historian compression or a frozen transmitter: PV not recorded there, never read as the valve sticking)",
            100.0 * share
        ),
    ));
    let mut levels: Vec<u64> = pv.iter().map(|v| v.to_bits()).collect();
    levels.sort_unstable();
    levels.dedup();
    let per_100 = 100.0 * levels.len() as f64 / used.max(1) as f64;
    out.push(finding(
        Gate::PvQuantised,
        per_100 >= req.limits.levels_per_100 || levels.len() >= 50,
        levels.len() as f64,
        req.limits.levels_per_100,
        format!(
            "PV takes {}",
            plural(levels.len(), "distinct value", "distinct values")
        ),
    ));
    if let Some(sp) = r.sp {
        let changes = sp[s..e].windows(2).filter(|w| w[1] != w[0]).count();
        out.push(finding(
            Gate::SetpointChanges,
            true,
            changes as f64,
            0.0,
            format!(
                "the setpoint changes {} in the analysed stretch (kept: they excite the loop)",
                plural(changes, "time", "times")
            ),
        ));
    }
    out
}

/// A finding for each reason samples were left out (manual mode, missing values, spikes, OP or
/// PV at a limit), of `n` samples in all.
fn left_out_findings(excluded: &Excluded, n: usize, req: &DiagnoseRequest) -> Vec<Finding> {
    let mut out = Vec::new();
    for (gate, count, what, limit) in [
        (
            Gate::ManualMode,
            excluded.manual,
            "in manual",
            req.limits.manual_share,
        ),
        (
            Gate::MissingValues,
            excluded.missing,
            "with a missing value",
            1.0,
        ),
        (
            Gate::Spikes,
            excluded.spikes,
            "in a spike (one to three samples of a signal far beyond its own range and back: a glitch, not the process)",
            1.0,
        ),
        (
            Gate::OpSaturated,
            excluded.saturated,
            "with OP at a limit (0 %, 100 % or pinned at its extreme)",
            req.limits.saturated_share,
        ),
        (
            Gate::PvAtLimit,
            excluded.pv_at_limit,
            "with PV held at its extreme (a transmitter at the end of its range or a clamp: PV does not follow the process there)",
            req.limits.saturated_share,
        ),
    ] {
        if count > 0 {
            let share = count as f64 / n.max(1) as f64;
            out.push(finding(
                gate,
                share <= limit,
                share,
                limit,
                format!(
                    "{} {what} ({:.0} % of the record), left out",
                    plural(count, "sample", "samples"),
                    100.0 * share
                ),
            ));
        }
    }
    out
}

fn left_out(x: &Excluded) -> String {
    let mut parts = Vec::new();
    if x.manual > 0 {
        parts.push(format!("{} in manual", x.manual));
    }
    if x.missing > 0 {
        parts.push(format!("{} missing", x.missing));
    }
    if x.saturated > 0 {
        parts.push(format!("{} with OP at a limit", x.saturated));
    }
    if x.pv_at_limit > 0 {
        parts.push(format!("{} with PV at a limit", x.pv_at_limit));
    }
    if x.spikes > 0 {
        parts.push(format!("{} in a spike", x.spikes));
    }
    if x.time_breaks > 0 {
        parts.push(plural(x.time_breaks, "time gap", "time gaps"));
    }
    if parts.is_empty() {
        "nothing".into()
    } else {
        parts.join(", ")
    }
}

/// OP beyond the valve's span by more than this share of it: the span is likely not OP's.
const OUTSIDE_SPAN: f64 = 0.05;

/// A warning when OP leaves the valve's span (`op_range`, by default 0 to 100 %) by more than
/// [`OUTSIDE_SPAN`] of it: bands in % of span then mean nothing until `--op-range` says what OP
/// a closed and a fully open valve have.
pub(super) fn op_outside_span(op: &[f64], req: &DiagnoseRequest) -> Option<String> {
    let (lo, hi) = op
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let [closed, open] = req.op_range;
    let margin = OUTSIDE_SPAN * (open - closed);
    (lo < closed - margin || hi > open + margin).then(|| {
        let (lo, hi) = (quality::readable(lo), quality::readable(hi));
        format!(
            "OP runs from {lo} to {hi}, outside the valve's span {closed} to {open}: bands in % of span assume OP is on that span; \
             give --op-range LO:HI (the OP of a closed and of a fully open valve)"
        )
    })
}

/// Why a stretch in which OP or PV never moves cannot be judged, and what to do: with OP still
/// the controller did not act on the valve; with PV still nothing shows the loop's response (a
/// frozen transmitter, or PV not recorded).
pub(super) fn still(op: &[f64], pv: &[f64]) -> Option<(String, super::Action)> {
    let constant = |x: &[f64]| x.first().filter(|&&v| x.iter().all(|&u| u == v)).copied();
    if let Some(v) = constant(op) {
        return Some((
            format!(
                "OP stays at {v} over the whole analysed stretch: the controller did not move the valve (manual mode, or OP not recorded), so the record says nothing about the valve"
            ),
            super::Action::UsableRecord,
        ));
    }
    constant(pv).map(|v| {
        (
            format!(
                "PV stays at {v} over the whole analysed stretch while OP moves: a frozen transmitter or a PV not recorded, so nothing shows how the loop responds to the valve"
            ),
            super::Action::CheckTransmitter,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn op_off_its_span_is_named_and_op_on_it_is_not() {
        let req = DiagnoseRequest::default();
        assert!(op_outside_span(&[0.0, 50.0, 100.0], &req).is_none());
        // a little beyond the ends (a controller's output limits of -2 and 102 %) is no warning
        assert!(op_outside_span(&[-2.0, 102.0], &req).is_none());
        let w = op_outside_span(&[1200.0, 3400.0], &req).unwrap();
        assert!(
            w.contains("1200.0000 to 3400.0000") && w.contains("--op-range"),
            "{w}"
        );
        let w = op_outside_span(&[4.9e301, 5.1e301], &req).unwrap();
        assert!(w.contains("4.900e301"), "{w}");
        let on_its_span = DiagnoseRequest {
            op_range: [1000.0, 4000.0],
            ..DiagnoseRequest::default()
        };
        assert!(op_outside_span(&[1200.0, 3400.0], &on_its_span).is_none());
    }

    #[test]
    fn an_op_or_pv_that_never_moves_is_still() {
        let moving = [50.0, 50.0, 50.1];
        let why = |op: &[f64], pv: &[f64]| still(op, pv).map(|(reason, _)| reason);
        assert!(why(&[50.0; 3], &moving).unwrap().contains("OP stays at 50"));
        assert!(why(&moving, &[7.0; 3]).unwrap().contains("PV stays at 7"));
        assert!(why(&moving, &moving).is_none());
        assert!(why(&[], &[]).is_none());
    }
}
