//! What a record lets the families see of a sticky valve: the sticky loops called stiction by
//! their band over the OP's noise as the diagnosis measured it (`Diagnosis::reach`).
//! Proportional action passes the PV's measurement noise on to OP; a band of a few such standard
//! deviations is crossed by the noise alone, and the valve then moves in small jumps a healthy
//! valve's noise looks like. The table on the calibration draws set `diagnose::reach`'s figures.

use super::tables::{pct, Groups};
use std::fmt::Write as _;
use stiction_core::diagnose::Verdict;
use stiction_lab::catalogue::Truth;

/// Upper edges of the rows (band over the OP's noise standard deviation).
const EDGES: [(f64, &str); 7] = [
    (2.0, "under 2"),
    (4.0, "2 to 4"),
    (8.0, "4 to 8"),
    (12.0, "8 to 12"),
    (25.0, "12 to 25"),
    (50.0, "25 to 50"),
    (f64::INFINITY, "50 and more"),
];

/// Sticky loops called stiction, by band (Stenman d, Kano S, He fs) over the OP's noise standard
/// deviation (as the diagnosis measured it), for records under 5 s apart and slower.
pub(super) fn detectability_table(md: &mut String, groups: &Groups) {
    // (called, loops) per row, for fine and coarse records
    let mut cells = [[(0usize, 0usize); 2]; EDGES.len()];
    for (class, items) in groups {
        if class.truth() != Truth::Sticky {
            continue;
        }
        for (l, d) in items {
            // OP's noise as the diagnosis measured it (its reach), OP units = % of span here
            let Some(op_noise) = d.reach.as_ref().map(|r| r.op_noise) else {
                continue;
            };
            let ratio = l.setup.model.values()[0] / op_noise;
            let Some(row) = EDGES.iter().position(|&(hi, _)| ratio < hi) else {
                continue;
            };
            let cell = &mut cells[row][usize::from(l.ts() >= 5.0)];
            cell.0 += usize::from(d.verdict == Verdict::Stiction);
            cell.1 += 1;
        }
    }
    let _ = writeln!(
        md,
        "Sticky loops called stiction, by band (Stenman d, Kano S, He fs) over the OP's noise standard deviation as the diagnosis measured it (its `reach`; mostly what proportional action passes on to OP of the PV's noise). `diagnose` reports the shares found under 4 and over 12 on the calibration draws (`diagnose::reach`):\n"
    );
    let _ = writeln!(
        md,
        "| band over the OP's noise | records under 5 s | slower records |\n|---|---|---|"
    );
    let cell = |(k, n): (usize, usize)| {
        if n == 0 {
            "-".to_string()
        } else {
            format!("{k} of {n} ({})", pct(k, n))
        }
    };
    for ((_, label), [fine, coarse]) in EDGES.iter().zip(cells) {
        if fine.1 + coarse.1 > 0 {
            let _ = writeln!(md, "| {label} | {} | {} |", cell(fine), cell(coarse));
        }
    }
    let _ = writeln!(md);
}
