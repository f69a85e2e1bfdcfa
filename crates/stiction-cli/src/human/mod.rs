//! The human output of `diagnose`: what the engineer reads first (the verdict and the probability
//! of a sticky valve, the one or two reasons that decided it, the band, the next step), then every
//! family's detail folded below (`details:`), the record, its oscillation and its quality. The
//! words are `stiction-report`'s ([`crate::words`]), filled into the diagnosis before printing.

mod details;
mod record;
pub mod settings;

use stiction_core::diagnose::{BandSource, Diagnosis, Verdict};

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

/// Print the diagnosis of `file` for a person (its words filled by [`crate::words::fill`]).
pub fn print_diagnosis(file: &str, d: &Diagnosis) {
    headline(file, d);
    band(d);
    println!("  next step: {}", d.next_step.text);
    if let Some(r) = d.reach.as_ref().filter(|_| d.verdict != Verdict::Stiction) {
        println!("  what this record can show: {}", crate::words::reach(r));
    }
    details::print(d);
    record::print(d);
    for w in &d.warnings {
        println!("  note: {w}");
    }
}

/// The verdict, the probability of a sticky valve and the reasons.
fn headline(file: &str, d: &Diagnosis) {
    let verdict = match d.verdict {
        Verdict::Stiction => "STICTION",
        v => crate::words::verdict(v),
    };
    match d.probability {
        Some(p) => println!("{file}: {verdict} (P {p:.2})"),
        None => println!("{file}: {verdict}"),
    }
    match d.reasons.as_slice() {
        [] => {}
        [one] => println!("  why: {}", one.text),
        many => {
            println!("  why:");
            for r in many {
                println!("    - {}", r.text);
            }
        }
    }
}

/// The stiction band of a `stiction` verdict, with the other estimates beside it.
fn band(d: &Diagnosis) {
    let Some(b) = &d.band else {
        return;
    };
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
