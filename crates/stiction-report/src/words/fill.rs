//! Filling a diagnosis's words: every reason's `text` (the diagnosis's and each window's) and the
//! next step's, from the typed values the core returns with them empty.

use super::findings::{reason, words, Towards};
use super::next_step::next_step;
use stiction_core::diagnose::{Diagnosis, Finding, Reading, Reason, Statistic, VerdictModel};

/// Fill every `text` of `d`: its reasons', each window's reasons' and its next step's. Call it
/// right after `diagnose`, before printing, serialising or building fleet rows from `d`;
/// filling twice gives the same words.
pub fn fill(d: &mut Diagnosis) {
    let reading = d.statistics.as_ref();
    for r in &mut d.reasons {
        r.text = reason_in(r, reading);
    }
    for w in &mut d.windows {
        for r in &mut w.reasons {
            r.text = reason_in(r, None);
        }
    }
    d.next_step.text = next_step(&d.next_step);
}

/// A reason in words, naming what was measured where nothing points to a sticky valve.
fn reason_in(r: &Reason, reading: Option<&Reading>) -> String {
    match (&r.finding, reading) {
        (Finding::NothingOfAStickyValve, Some(reading)) => {
            let measured = measured(reading);
            let base = words(&r.finding, Towards::Unknown);
            if measured.is_empty() {
                base
            } else {
                format!(
                    "{base}: of what was measured ({}), none moves the odds towards one",
                    list(&measured)
                )
            }
        }
        _ => reason(r),
    }
}

/// What a statistic measures, as the list of what was measured names it.
fn measures(s: Statistic) -> &'static str {
    match s {
        Statistic::StickShare | Statistic::Sticks => "PV's steps",
        Statistic::Stuck => "PV's holds off the setpoint",
        Statistic::FitGain | Statistic::FitBand | Statistic::FitTest => "the closed-loop fit",
        Statistic::CycleShape => "the cycle's shape",
        Statistic::LoopLag => "the linear loop's lag",
    }
}

/// What the reading measured of what the model reads, each once, in the model's order.
fn measured(reading: &Reading) -> Vec<&'static str> {
    let model = VerdictModel::embedded();
    let read = |s: Statistic| model.inputs.iter().any(|i| i.statistic == s);
    let mut out: Vec<&'static str> = Vec::new();
    for c in reading
        .contributions
        .iter()
        .filter(|c| c.value.is_some() && read(c.statistic))
    {
        let m = measures(c.statistic);
        if !out.contains(&m) {
            out.push(m);
        }
    }
    out
}

/// "a, b and c".
fn list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use stiction_core::diagnose::Contribution;

    #[test]
    fn nothing_of_a_sticky_valve_names_what_was_measured() {
        let reading = Reading {
            probability: 0.1,
            contributions: vec![
                Contribution {
                    statistic: Statistic::StickShare,
                    value: Some(0.0),
                    contribution: 0.0,
                },
                Contribution {
                    statistic: Statistic::Sticks,
                    value: Some(0.0),
                    contribution: 0.0,
                },
                Contribution {
                    statistic: Statistic::FitGain,
                    value: Some(0.0),
                    contribution: -0.2,
                },
                Contribution {
                    statistic: Statistic::CycleShape,
                    value: None,
                    contribution: 0.0,
                },
            ],
        };
        let r = Reason::plain(Finding::NothingOfAStickyValve);
        let text = reason_in(&r, Some(&reading));
        assert!(
            text.starts_with("no statistic points to a sticky valve"),
            "{text}"
        );
        // only what was measured and the model reads is named; the cycle was not measured
        assert!(!text.contains("cycle"), "{text}");
        let read = |s: Statistic| {
            VerdictModel::embedded()
                .inputs
                .iter()
                .any(|i| i.statistic == s)
        };
        if read(Statistic::StickShare) {
            assert!(text.contains("PV's steps"), "{text}");
        }
        assert_eq!(list(&["a", "b", "c"]), "a, b and c");
    }
}
