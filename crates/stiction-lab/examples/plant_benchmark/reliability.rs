//! P's reliability: the loops by the model's probability of a sticky valve, how many of them are
//! sticky, and the verdicts given in each band and how many were right. On this mix of loops
//! (a plant's own mix may hold sticky valves more or less often), backlash left out.

use super::tables::{pct, Groups};
use std::fmt::Write as _;
use stiction_core::diagnose::Verdict;
use stiction_lab::catalogue::Truth;

/// The bands' lower edges (each up to the next; the last up to 1), as the verdict study's
/// reliability table on the real records (`examples/verdict`).
const BANDS: [f64; 5] = [0.0, 0.2, 0.4, 0.6, 0.8];

/// The band of a probability: the index of the highest lower edge at or below it.
fn band(p: f64) -> usize {
    BANDS.iter().rposition(|&lo| p >= lo).unwrap_or(0)
}

/// What one band holds.
#[derive(Default, Clone, Copy)]
struct Cell {
    loops: usize,
    sticky: usize,
    p_sum: f64,
    /// `stiction` verdicts given, and right.
    stiction: (usize, usize),
    /// `no_stiction` verdicts given, and right.
    no_stiction: (usize, usize),
    /// `undetermined` and `insufficient_data`.
    undecided: usize,
}

/// The table: per P band, the loops, their mean P, the share sticky, and the verdicts given and
/// right (loops without a probability, the record not judged, are counted under it).
pub(super) fn reliability_table(md: &mut String, groups: &Groups) {
    let mut cells = [Cell::default(); BANDS.len()];
    let mut without = 0;
    for (class, items) in groups {
        let truth = class.truth();
        if truth == Truth::BacklashOnly {
            continue;
        }
        let sticky = truth == Truth::Sticky;
        for (_, d) in items {
            let Some(p) = d.probability else {
                without += 1;
                continue;
            };
            let c = &mut cells[band(p)];
            c.loops += 1;
            c.sticky += usize::from(sticky);
            c.p_sum += p;
            match d.verdict {
                Verdict::Stiction => {
                    c.stiction.0 += 1;
                    c.stiction.1 += usize::from(sticky);
                }
                Verdict::NoStiction => {
                    c.no_stiction.0 += 1;
                    c.no_stiction.1 += usize::from(!sticky);
                }
                Verdict::Undetermined | Verdict::InsufficientData => c.undecided += 1,
            }
        }
    }
    let _ = writeln!(
        md,
        "P's reliability: the loops by the model's probability of a sticky valve (P), the share of them sticky (a \
         calibrated P has it near the mean P), and the verdicts given and right (on this mix of loops; backlash left out):\n"
    );
    let _ = writeln!(
        md,
        "| P | loops | mean P | sticky | stiction: right of given | no_stiction: right of given | undetermined or insufficient_data |\n|---|---|---|---|---|---|---|"
    );
    let given = |(n, right): (usize, usize)| {
        if n == 0 {
            "-".to_string()
        } else {
            format!("{right} of {n} ({})", pct(right, n))
        }
    };
    for (i, (lo, c)) in BANDS.iter().zip(cells).enumerate() {
        let hi = BANDS.get(i + 1).copied().unwrap_or(1.0);
        if c.loops == 0 {
            let _ = writeln!(md, "| {lo:.1}-{hi:.1} | 0 | - | - | - | - | - |");
            continue;
        }
        let _ = writeln!(
            md,
            "| {lo:.1}-{hi:.1} | {} | {:.2} | {} of {} ({}) | {} | {} | {} |",
            c.loops,
            c.p_sum / c.loops as f64,
            c.sticky,
            c.loops,
            pct(c.sticky, c.loops),
            given(c.stiction),
            given(c.no_stiction),
            c.undecided
        );
    }
    if without > 0 {
        let _ = writeln!(md, "\n{without} loops without P (the record not judged).");
    }
    let _ = writeln!(md);
}
