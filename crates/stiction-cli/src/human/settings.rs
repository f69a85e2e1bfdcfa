//! `stiction diagnose --settings`: how `diagnose` measures (the typed settings table, at its
//! defaults) and how it decides (the verdict's model: its statistics with their knots, weights and
//! references, the intercept and the thresholds), as plain text or JSON.

use anyhow::Result;
use serde::Serialize;
use stiction_core::diagnose::{Settings, Statistic, VerdictModel, VOTE};

/// The settings and the model, as `--settings --json` writes them.
#[derive(Serialize)]
struct SettingsJson<'a> {
    settings: Settings,
    /// A family votes stiction from this share of the log-odds.
    family_vote_from: f64,
    model: &'a VerdictModel,
}

/// A statistic's name in files (`stick_share`), as serde writes it.
fn code(s: Statistic) -> String {
    serde_json::to_value(s)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .unwrap_or_default()
}

/// How the model reads a statistic's value `x` (its knots and range are on that scale).
fn read_as(s: Statistic) -> &'static str {
    match s {
        Statistic::Sticks | Statistic::Stuck | Statistic::FitBand | Statistic::FitTest => {
            "ln(1 + x)"
        }
        _ => "x",
    }
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Print the settings and the model.
pub fn print(json: bool) -> Result<()> {
    let model = VerdictModel::embedded();
    if json {
        let out = SettingsJson {
            settings: Settings::default(),
            family_vote_from: VOTE,
            model,
        };
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("How diagnose measures (diagnose::Settings, at its defaults):");
    for line in toml::to_string(&Settings::default())?.lines() {
        if !line.is_empty() {
            println!("  {line}");
        }
    }
    println!();
    println!("How it decides (the verdict's model, one logistic model with monotone effects):");
    println!(
        "  P(sticky valve) = 1 / (1 + exp(-z)), z = {} + the sum of each statistic's contribution",
        model.intercept
    );
    println!(
        "  a statistic's contribution: the sum over its knots of weight * max(0, x - knot), x clipped to its range, less the same at its reference"
    );
    println!(
        "  verdict: stiction from P {}, no stiction under P {}, undetermined between; a family votes stiction from {VOTE:+} to the log-odds; the valve family decides where MV is recorded",
        model.stiction_from, model.no_stiction_below
    );
    println!(
        "  {:<12} {:<10} {:<12} {:<16} {:<16} {:<9}  what it is",
        "statistic", "read as", "range", "knots", "weights", "reference"
    );
    for i in &model.inputs {
        println!(
            "  {:<12} {:<10} {:<12} {:<16} {:<16} {:<9}  {}",
            code(i.statistic),
            read_as(i.statistic),
            format!("{} to {}", i.range[0], i.range[1]),
            list(&i.knots),
            list(&i.weights),
            i.reference,
            crate::words::statistic(i.statistic)
        );
    }
    let t = &model.training;
    println!(
        "  trained by: {}; records: {}; a real record weighs {} simulated ones; ridge {}; checked: {}",
        t.command, t.records, t.real_weight, t.ridge, t.checked
    );
    Ok(())
}
