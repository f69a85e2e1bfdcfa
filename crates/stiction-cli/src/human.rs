//! The human output of `diagnose`: the verdict, the band, the fits and each family's vote, the
//! record, its oscillation and its quality, one line each.

use crate::words::{count, seconds};
use stiction_core::diagnose::{BandSource, Diagnosis, Verdict, Vote};

/// Why a weak cycle (`Oscillation::weak_cycle`) counts, for the oscillation line.
const WEAK_CYCLE: &str = "its half periods clear 1.5 noise standard deviations, not 3, and its period wanders as a limit cycle's does beside noise";

fn band_source(s: BandSource) -> &'static str {
    match s {
        BandSource::Valve => "from the recorded valve position",
        BandSource::ClosedLoop => "closed-loop estimate, Stenman exact",
        BandSource::FitScan => "closed-loop fit's scan",
        BandSource::SlipJumpFit => "closed-loop fit's slip-jump valve, Kano's S",
        BandSource::StickSlip => "median OP travel per stick",
        BandSource::DescribingFunction => "describing function of the limit cycle",
        BandSource::Levels => "levels test's best valve",
        BandSource::Ellipse => "width of the oscillation's PV-OP ellipse",
        BandSource::HiddenValve => "hidden-valve test, a grid of bands",
    }
}

/// Print the diagnosis of `file` for a person.
pub fn print_diagnosis(file: &str, d: &Diagnosis) {
    headline(file, d);
    fits(d);
    println!("  next step: {}", d.next_step);
    if let Some(r) = d.reach.as_ref().filter(|_| d.verdict != Verdict::Stiction) {
        println!("  what this record can show: {}", r.words());
    }
    evidence(d);
    record(d);
    for w in &d.warnings {
        println!("  note: {w}");
    }
}

/// The verdict, its reason and the band.
fn headline(file: &str, d: &Diagnosis) {
    let verdict = match d.verdict {
        Verdict::Stiction => "STICTION",
        v => crate::words::verdict(v),
    };
    match d.confidence {
        Some(c) => println!("{file}: {verdict} (confidence {c:.2})"),
        None => println!("{file}: {verdict}"),
    }
    if let Some(r) = &d.reason {
        println!("  reason: {r}");
    }
    if let Some(b) = &d.band {
        let interval = b
            .interval_percent_of_span
            .map(|[lo, hi]| format!(", optimal set {lo:.2} to {hi:.2} %"))
            .unwrap_or_default();
        let mut others: Vec<String> = b
            .others
            .iter()
            .map(|(s, v)| format!("{} {v:.2} %", band_source(*s)))
            .collect();
        if let Some(e) = b
            .ellipse_percent_of_span
            .filter(|_| b.source != BandSource::Ellipse)
        {
            others.push(format!("ellipse {e:.2} %"));
        }
        println!(
            "  stiction band: {:.2} % of valve span ({}{interval}){}",
            b.band_percent_of_span,
            band_source(b.source),
            if others.is_empty() {
                String::new()
            } else {
                format!("; beside it: {}", others.join(", "))
            }
        );
    }
}

/// The closed-loop fits and the linear loop's balance.
fn fits(d: &Diagnosis) {
    if let Some(m) = d.families.iter().find_map(|f| f.model.as_ref()) {
        if m.band_fits_better() {
            println!(
                "  closed-loop fit: R² {:.3} without stiction, {:.3} with (Stenman), {:.3} with a slip jump (Kano)",
                m.r2_without_stiction, m.r2_stenman, m.r2_slip_jump
            );
        } else {
            println!(
                "  closed-loop fit: R² {:.3} without stiction; no band found fits better (the search's best: {:.3} with Stenman's band, {:.3} with a slip jump)",
                m.r2_without_stiction, m.r2_stenman, m.r2_slip_jump
            );
        }
    }
    if let Some(l) = d.families.iter().find_map(|f| f.limit_cycle.as_ref()) {
        println!(
            "  linear loop: gain margin {}; to sustain the {:.0} s cycle the valve must lag OP by {:.0}° (gain {:.2}){}",
            l.margins
                .gain_margin
                .map_or("none".into(), |g| format!("{g:.2}")),
            l.period,
            l.needed_lag_degrees,
            l.needed_gain,
            l.describing.as_ref().map_or(String::new(), |b| format!(
                "; describing function: a band of {:.2} % of span{}",
                b.band_percent_of_span,
                b.predicted_period
                    .map_or(String::new(), |p| format!(", predicted period {p:.0} s"))
            ))
        );
    }
}

/// Each family's vote, then the shape indices.
fn evidence(d: &Diagnosis) {
    println!("  evidence:");
    for f in &d.families {
        println!(
            "    {:<24} {:<13} {}",
            f.family.words(),
            crate::words::vote(f.vote),
            f.note
        );
    }
    if let Some(c) = &d.combined {
        println!(
            "    {:<24} {:<13} probability of a sticky valve {:.2} from the families' statistics read together (trained trees; \
             stiction from {:.2}; {}); towards a sticky valve most: {}",
            "statistics combined",
            crate::words::vote(c.vote()),
            c.probability,
            c.threshold,
            c.role(),
            c.leading()
        );
    }
    if !d.indices.is_empty() {
        println!("  shape indices (oscillating stretch):");
        for i in &d.indices {
            println!(
                "    {:<18} {:>8}  {:<13} {}{}",
                i.name,
                i.value.map_or("-".into(), |v| format!("{v:.3}")),
                crate::words::vote(i.vote),
                i.threshold,
                if i.weight == 0.0 {
                    " [shown, not counted]"
                } else if i.only_votes.is_some() && i.vote == Vote::Undetermined {
                    " [one-sided: silent]"
                } else {
                    ""
                }
            );
        }
    }
}

/// The setpoint read off a record without SP, its levels and where it stepped (the first few).
fn read_off(r: &stiction_core::diagnose::SetpointReadOff) -> String {
    const SHOWN: usize = 8;
    let mut parts = vec![format!("{:.4}", r.levels[0])];
    for (step, level) in r.steps.iter().zip(&r.levels[1..]).take(SHOWN) {
        parts.push(format!("{level:.4} from sample {step}"));
    }
    if r.steps.len() > SHOWN {
        parts.push(format!("{} more steps", r.steps.len() - SHOWN));
    }
    format!(
        "setpoint read off OP and PV (no setpoint column): {}",
        parts.join(", then ")
    )
}

/// The record: samples, oscillation, data quality and the windows.
fn record(d: &Diagnosis) {
    println!(
        "  {} at {} s; analysed samples {} to {} ({})",
        count(d.samples, "sample", "samples"),
        seconds(d.ts),
        d.analysed[0],
        d.analysed[1],
        count(d.stretches.len(), "usable stretch", "usable stretches")
    );
    if let Some(o) = &d.oscillation {
        println!(
            "  oscillation: {}{}; period {}; regularity {} (threshold {}); {} half periods with a large IAE",
            match (o.oscillating, o.across_setpoint_steps, o.weak_cycle) {
                (true, true, false) =>
                    "yes, across the setpoint's steps (its holds are too short)".to_string(),
                (true, true, true) => format!(
                    "yes, a weak cycle across the setpoint's steps (its holds are too short; {WEAK_CYCLE})"
                ),
                (true, false, true) => format!("yes, a weak cycle ({WEAK_CYCLE})"),
                (true, false, false) => "yes".to_string(),
                _ => "no".to_string(),
            },
            o.reading_words().map_or(String::new(), |w| format!(" ({w})")),
            o.period.map_or("-".into(), |p| format!("{p:.1} s")),
            o.regularity.shown(),
            o.regularity.threshold,
            o.iae.exceedances
        );
    }
    if let Some(r) = &d.setpoint_read_off {
        println!("  {}", read_off(r));
    }
    let failed: Vec<_> = d.quality.iter().filter(|f| !f.passed).collect();
    if failed.is_empty() {
        println!(
            "  data quality: every check passed ({} made)",
            d.quality.len()
        );
    } else {
        for f in failed {
            println!("  data quality, {}: {}", f.gate, f.message);
        }
    }
    if d.windows.is_empty() {
        return;
    }
    println!("  windows:");
    for w in &d.windows {
        println!(
            "    samples {:>7} to {:>7} (t {:.0} to {:.0} s): {}{}{}",
            w.start,
            w.end,
            w.t_start,
            w.t_end,
            w.verdict,
            w.confidence
                .map(|c| format!(" ({c:.2})"))
                .unwrap_or_default(),
            w.reason
                .as_deref()
                .map(|r| format!(": {r}"))
                .unwrap_or_default()
        );
    }
}
