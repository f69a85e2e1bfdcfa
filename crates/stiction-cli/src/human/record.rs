//! The record under the details: samples, oscillation, the setpoint read off, data quality and
//! the verdict per window.

use crate::words::{count, seconds};
use stiction_core::diagnose::{Diagnosis, SetpointReadOff};

/// Why a weak cycle (`Oscillation::weak_cycle`) counts, for the oscillation line.
const WEAK_CYCLE: &str = "its half periods clear 1.5 noise standard deviations, not 3, and its period wanders as a limit cycle's does beside noise";

/// The setpoint read off a record without SP, its levels and where it stepped (the first few).
fn read_off(r: &SetpointReadOff) -> String {
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

/// The oscillation line.
fn oscillation(d: &Diagnosis) {
    let Some(o) = &d.oscillation else {
        return;
    };
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

/// The record: samples, oscillation, data quality and the windows.
pub fn print(d: &Diagnosis) {
    println!(
        "  {} at {} s; analysed samples {} to {} ({})",
        count(d.samples, "sample", "samples"),
        seconds(d.ts),
        d.analysed[0],
        d.analysed[1],
        count(d.stretches.len(), "usable stretch", "usable stretches")
    );
    if let Some(j) = &d.judged_on {
        println!("  {}", crate::words::judged_on(j, d.analysed));
    }
    oscillation(d);
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
    windows(d);
}

/// The verdict per window: its samples, times, verdict, probability and reasons.
fn windows(d: &Diagnosis) {
    if d.windows.is_empty() {
        return;
    }
    println!("  windows:");
    for w in &d.windows {
        let reasons: Vec<&str> = w.reasons.iter().map(|r| r.text.as_str()).collect();
        println!(
            "    samples {:>7} to {:>7} (t {:.0} to {:.0} s): {}{}{}",
            w.start,
            w.end,
            w.t_start,
            w.t_end,
            w.verdict,
            w.probability
                .map(|p| format!(" (P {p:.2})"))
                .unwrap_or_default(),
            if reasons.is_empty() {
                String::new()
            } else {
                format!(": {}", reasons.join("; "))
            }
        );
    }
}
