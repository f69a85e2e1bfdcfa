//! How often a verdict given with a confidence was right, by confidence band: what the number
//! means on the benchmark's mix of loops (not a probability on a plant's own mix, where sticky
//! valves may be rarer or commoner).

use super::tables::{pct, Groups};
use std::fmt::Write as _;
use stiction_core::diagnose::Verdict;
use stiction_lab::catalogue::Truth;

/// The confidence bands' lower edges.
const BANDS: [f64; 4] = [0.0, 0.4, 0.6, 0.8];

/// The band of a confidence: the index of the highest lower edge at or below it.
fn band(c: f64) -> usize {
    BANDS.iter().rposition(|&lo| c >= lo).unwrap_or(0)
}

/// The table: for `stiction` and `no_stiction`, per confidence band, the verdicts given and the
/// share right (backlash-only valves left out: they are outside the goals).
pub(super) fn confidence_table(md: &mut String, groups: &Groups) {
    // [verdict][band] = (given, right)
    let mut cells = [[(0usize, 0usize); BANDS.len()]; 2];
    for (class, items) in groups {
        let truth = class.truth();
        if truth == Truth::BacklashOnly {
            continue;
        }
        for (_, d) in items {
            let (row, right) = match d.verdict {
                Verdict::Stiction => (0, truth == Truth::Sticky),
                Verdict::NoStiction => (1, truth == Truth::NotSticky),
                _ => continue,
            };
            let Some(c) = d.confidence else { continue };
            let cell = &mut cells[row][band(c)];
            cell.0 += 1;
            cell.1 += usize::from(right);
        }
    }
    let _ = writeln!(
        md,
        "What the confidence means here: verdicts by confidence, and how many were right (on this mix of loops; backlash left out):\n"
    );
    let header: Vec<String> = BANDS
        .iter()
        .enumerate()
        .map(|(i, lo)| match BANDS.get(i + 1) {
            Some(hi) => format!("{lo:.1} to {hi:.1}"),
            None => format!("{lo:.1} to 1"),
        })
        .collect();
    let _ = writeln!(md, "| verdict | {} |", header.join(" | "));
    let _ = writeln!(md, "|---|{}", "---|".repeat(BANDS.len()));
    for (row, name) in ["stiction", "no_stiction"].iter().enumerate() {
        let cols: Vec<String> = cells[row]
            .iter()
            .map(|&(given, right)| {
                if given == 0 {
                    "-".into()
                } else {
                    format!("{right} of {given} ({})", pct(right, given))
                }
            })
            .collect();
        let _ = writeln!(md, "| {name} | {} |", cols.join(" | "));
    }
    let _ = writeln!(md);
}
