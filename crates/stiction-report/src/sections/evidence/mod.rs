//! How the verdict was decided: the model's reading (each statistic's value and its share of the
//! log-odds), every family's detail (folded in the page), and the shape family's indices.

use super::*;
use stiction_core::diagnose::{Family, FamilyEvidence, VerdictModel};

mod details;

/// One statistic of the verdict's model as the page shows it.
#[derive(Serialize)]
pub struct StatisticRow {
    pub name: &'static str,
    pub value: String,
    pub contribution: String,
    /// `towards`, `away` or `none`, for the cell's colour.
    pub way: &'static str,
}

/// One family, folded: its summary line, then its detail.
#[derive(Serialize)]
pub struct FamilyBlock {
    pub family: &'static str,
    pub vote: Chip,
    /// Its statistics' share of the log-odds, in words ("+1.2 to the log-odds"), when the
    /// model reads it here.
    pub contribution: Option<String>,
    pub note: String,
    pub rows: Vec<KvRow>,
}

#[derive(Serialize)]
pub struct IndexRow {
    pub name: String,
    pub value: String,
    pub vote: Chip,
    pub threshold: String,
    pub weight: String,
    pub reference: String,
    pub note: String,
}

#[derive(Serialize)]
pub struct Evidence {
    /// How the probability is formed, in words.
    pub model: String,
    /// A family votes stiction from this share of the log-odds.
    pub vote_from: String,
    pub statistics: Vec<StatisticRow>,
    pub families: Vec<FamilyBlock>,
    pub indices: Vec<IndexRow>,
    /// Why no index was computed, when none was.
    pub no_index: Option<&'static str>,
}

/// A share of the log-odds as the page prints it: `+1.24`, `−0.42`, `0`.
pub(super) fn log_odds(c: f64) -> String {
    if c.abs() < 0.005 {
        "0".into()
    } else {
        format!("{c:+.2}").replace('-', "−")
    }
}

fn way(c: f64) -> &'static str {
    match c {
        x if x >= 0.005 => "towards",
        x if x <= -0.005 => "away",
        _ => "none",
    }
}

/// The statistics the model reads, each with its value and share of the log-odds, then the
/// model's base and the total.
fn statistic_rows(d: &Diagnosis) -> Vec<StatisticRow> {
    let Some(reading) = &d.statistics else {
        return Vec::new();
    };
    let model = VerdictModel::embedded();
    let read = |s| model.inputs.iter().any(|i| i.statistic == s);
    let mut rows: Vec<StatisticRow> = reading
        .contributions
        .iter()
        .filter(|c| read(c.statistic))
        .map(|c| StatisticRow {
            name: words::statistic(c.statistic),
            value: c.value.map_or("not measured".into(), |v| {
                words::statistic_value(c.statistic, v)
            }),
            contribution: log_odds(c.contribution),
            way: way(c.contribution),
        })
        .collect();
    let total = model.intercept
        + reading
            .contributions
            .iter()
            .map(|c| c.contribution)
            .sum::<f64>();
    rows.push(StatisticRow {
        name: "base (every statistic at a healthy record's value)",
        value: String::new(),
        contribution: log_odds(model.intercept),
        way: way(model.intercept),
    });
    rows.push(StatisticRow {
        name: "in all: the log-odds of a sticky valve",
        value: format!("P = {:.2}", reading.probability),
        contribution: log_odds(total),
        way: way(total),
    });
    rows
}

fn model_words(d: &Diagnosis) -> String {
    let m = VerdictModel::embedded();
    let read = m.inputs.len();
    match d.probability {
        Some(p) => format!(
            "One logistic model reads {read} statistics the families measure; each moves the log-odds of a sticky valve \
             from a healthy record's value (a larger value never points away from a sticky valve). Here they add up to \
             P = {p:.2}: stiction from {:.2}, no stiction under {:.2}, undetermined between{}.",
            m.stiction_from,
            m.no_stiction_below,
            if d.families.iter().any(|f| f.family == Family::Valve
                && f.vote != Vote::Undetermined)
            {
                "; with the valve position recorded, the valve family decides"
            } else {
                ""
            }
        ),
        None => "The record could not be judged, so the model read nothing.".into(),
    }
}

fn family_block(f: &FamilyEvidence, d: &Diagnosis) -> FamilyBlock {
    let mut rows = details::rows(f);
    if let Some(reading) = &d.statistics {
        let model = VerdictModel::embedded();
        let parts: Vec<String> = reading
            .contributions
            .iter()
            .filter(|c| words::measured_by(c.statistic) == f.family)
            .filter(|c| model.inputs.iter().any(|i| i.statistic == c.statistic))
            .map(|c| {
                format!(
                    "{} {}: {}",
                    words::statistic(c.statistic),
                    c.value.map_or("not measured".into(), |v| {
                        words::statistic_value(c.statistic, v)
                    }),
                    log_odds(c.contribution)
                )
            })
            .collect();
        if !parts.is_empty() {
            rows.insert(0, kv("In the verdict's model", parts.join("; ")));
        }
    }
    FamilyBlock {
        family: f.family.words(),
        vote: vote_chip(f.vote),
        contribution: f
            .contribution
            .map(|c| format!("{} to the log-odds", log_odds(c))),
        note: f.note.clone(),
        rows,
    }
}

pub fn evidence(d: &Diagnosis) -> Evidence {
    let indices = d
        .indices
        .iter()
        .map(|i| IndexRow {
            name: i.name.clone(),
            value: opt(i.value),
            vote: vote_chip(i.vote),
            threshold: i.threshold.clone(),
            weight: num(i.weight),
            reference: i.reference.clone(),
            note: i.note.clone(),
        })
        .collect();
    let no_index = d.indices.is_empty().then_some(match d.verdict {
        Verdict::InsufficientData => "the record cannot carry a verdict (see why above)",
        _ => "the loop does not oscillate regularly with a constant setpoint, so there is no shape for them to read",
    });
    Evidence {
        model: model_words(d),
        vote_from: num(stiction_core::diagnose::VOTE),
        statistics: statistic_rows(d),
        families: d.families.iter().map(|f| family_block(f, d)).collect(),
        indices,
        no_index,
    }
}
