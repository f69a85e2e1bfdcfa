//! The verdicts by what keeps the loop moving and by record: a setpoint change excites the loop
//! (the fits can tell the process from the load), a load drift or ramp alone does not.

use super::tables::{pct, Groups};
use std::fmt::Write as _;
use stiction_core::diagnose::Verdict;
use stiction_core::sim::catalogue::{Excitation, Truth};

/// The excitations, as the table names them.
const EXCITATIONS: [(Excitation, &str); 5] = [
    (Excitation::SetpointSteps, "setpoint steps"),
    (Excitation::StepsAndDrift, "setpoint steps and a load drift"),
    (Excitation::LoadDrift, "a load drift alone"),
    (Excitation::LoadRamp, "a load ramp alone"),
    (Excitation::Regulation, "regulation (rare small steps)"),
];

/// Sticky loops called `stiction` and not-sticky loops not called `stiction`, by excitation and
/// by sampling (records under 5 s apart, and slower), backlash left out.
pub(super) fn excitation_table(md: &mut String, groups: &Groups) {
    // [excitation][fine, coarse] = ((sticky called, sticky), (not-sticky not called, not-sticky))
    let mut cells = [[((0usize, 0usize), (0usize, 0usize)); 2]; EXCITATIONS.len()];
    for (class, items) in groups {
        let truth = class.truth();
        for (l, d) in items {
            let Some(row) = EXCITATIONS.iter().position(|(e, _)| *e == l.excitation) else {
                continue;
            };
            let cell = &mut cells[row][usize::from(l.ts() >= 5.0)];
            let called = d.verdict == Verdict::Stiction;
            match truth {
                Truth::Sticky => {
                    cell.0 .0 += usize::from(called);
                    cell.0 .1 += 1;
                }
                Truth::NotSticky => {
                    cell.1 .0 += usize::from(!called);
                    cell.1 .1 += 1;
                }
                Truth::BacklashOnly => {}
            }
        }
    }
    let _ = writeln!(
        md,
        "By what keeps the loop moving (backlash left out): without a setpoint change the fits must tell the process from the load in closed loop, from noise the controller feeds back:\n\n\
         | excitation | sticky called stiction, records under 5 s | slower records | not-sticky not called stiction, records under 5 s | slower records |\n|---|---|---|---|---|"
    );
    for (row, (_, name)) in EXCITATIONS.iter().enumerate() {
        let [fine, coarse] = cells[row];
        if fine.0 .1 + fine.1 .1 + coarse.0 .1 + coarse.1 .1 == 0 {
            continue;
        }
        let cell = |(k, n): (usize, usize)| {
            if n == 0 {
                "-".to_string()
            } else {
                format!("{k} of {n} ({})", pct(k, n))
            }
        };
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {} | {} |",
            cell(fine.0),
            cell(coarse.0),
            cell(fine.1),
            cell(coarse.1)
        );
    }
    let _ = writeln!(md);
}
