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
            Gate::OpSaturated,
            excluded.saturated,
            "with OP at a limit (0 %, 100 % or pinned at its extreme)",
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
    if x.time_breaks > 0 {
        parts.push(plural(x.time_breaks, "time gap", "time gaps"));
    }
    if parts.is_empty() {
        "nothing".into()
    } else {
        parts.join(", ")
    }
}
