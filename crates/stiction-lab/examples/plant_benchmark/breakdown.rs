//! The verdicts by what keeps the loop moving and by loop kind, each by record: a setpoint change
//! excites the loop (the fits can tell the process from the load), a load drift or ramp alone
//! does not.

use super::tables::{pct, Groups};
use std::fmt::Write as _;
use stiction_core::diagnose::Verdict;
use stiction_lab::catalogue::{BenchmarkLoop, Excitation, LoopKind, Truth};

/// Sticky loops called stiction and not-sticky loops not called stiction, each (hits, loops),
/// for records under 5 s apart and slower.
type Cells = [((usize, usize), (usize, usize)); 2];

/// The loops of `groups` that `pick` keeps, counted into cells (backlash left out).
fn count(groups: &Groups, pick: &dyn Fn(&BenchmarkLoop) -> bool) -> Cells {
    let mut cells = [((0usize, 0usize), (0usize, 0usize)); 2];
    for (class, items) in groups {
        for (l, d) in items.iter().filter(|(l, _)| pick(l)) {
            let cell = &mut cells[usize::from(l.ts() >= 5.0)];
            let called = d.verdict == Verdict::Stiction;
            match class.truth() {
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
    cells
}

/// One row: `name` and its four cells; nothing when it holds no loop.
fn row(md: &mut String, name: &str, [fine, coarse]: Cells) {
    if fine.0 .1 + fine.1 .1 + coarse.0 .1 + coarse.1 .1 == 0 {
        return;
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

/// The columns of both tables.
const COLUMNS: &str = "sticky called stiction, records under 5 s | slower records | not-sticky not called stiction, records under 5 s | slower records |\n|---|---|---|---|---|";

/// The excitations, as the table names them.
const EXCITATIONS: [(Excitation, &str); 7] = [
    (Excitation::SetpointSteps, "setpoint steps"),
    (Excitation::StepsAndDrift, "setpoint steps and a load drift"),
    (Excitation::LoadDrift, "a load drift alone"),
    (Excitation::LoadRamp, "a load ramp alone"),
    (
        Excitation::StepsAndLoadSteps,
        "setpoint steps and load steps",
    ),
    (Excitation::LoadSteps, "load steps alone"),
    (Excitation::Regulation, "regulation (rare small steps)"),
];

/// The verdicts by excitation, and by loop kind (backlash left out).
pub(super) fn breakdown_tables(md: &mut String, groups: &Groups) {
    let _ = writeln!(
        md,
        "By what keeps the loop moving (backlash left out): without a setpoint change the fits must tell the process from the load in closed loop, from noise the controller feeds back:\n\n\
         | excitation | {COLUMNS}"
    );
    for (excitation, name) in EXCITATIONS {
        row(md, name, count(groups, &|l| l.excitation == excitation));
    }
    let _ = writeln!(md, "\nBy loop kind:\n\n| kind | {COLUMNS}");
    for kind in [
        LoopKind::Flow,
        LoopKind::Pressure,
        LoopKind::Level,
        LoopKind::Temperature,
        LoopKind::Analyser,
        LoopKind::CoolingWater,
    ] {
        row(md, kind.name(), count(groups, &|l| l.kind == kind));
    }
    let _ = writeln!(md);
}
