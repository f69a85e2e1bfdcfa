//! How near the truth the process must be: the band-unknown oracle (the load's model known, PV at
//! the recorded samples) under processes off the truth by a sweep of amounts, each as an
//! identification could leave it (the gain and the times too high together, or too low).

use super::kalman::{llrs, FullRun};
use super::profile::rescaled;
use super::unknown::band_unknown;
use super::unknown_tables::{area_under_roc, best_balanced, shares};
use super::{balanced, Row};
use std::fmt::Write as _;
use stiction_core::models::Model;
use stiction_core::sim::ClosedLoop;

/// The amounts: the gain times 1 + e and the time constants and dead time times (1 + e)², or
/// both divided by as much.
const ERRORS: [f64; 4] = [0.05, 0.1, 0.2, 0.4];

/// The process factors (gain, times) of each step of the sweep: every amount too high, then too low.
fn factors() -> impl Iterator<Item = (f64, f64)> {
    ERRORS
        .iter()
        .map(|e| (1.0 + e, (1.0 + e) * (1.0 + e)))
        .chain(
            ERRORS
                .iter()
                .map(|e| (1.0 / (1.0 + e), 1.0 / ((1.0 + e) * (1.0 + e)))),
        )
}

/// One step of the sweep on a Stenman loop and its twin: the ratios (sticky loop, twin) with the
/// band known and with the band unknown.
pub type Step = [(f64, f64); 2];

/// The sweep on a Stenman loop (`setup`, its valve `model`, run as `run`) and its twin.
pub fn sweep(
    setup: &ClosedLoop,
    model: &Model,
    twin_setup: &ClosedLoop,
    (run, twin_run): (&FullRun, &FullRun),
    bands: usize,
) -> Vec<Step> {
    factors()
        .map(|(k, t)| {
            let (mut s1, mut s0) = (setup.clone(), twin_setup.clone());
            s1.process = rescaled(&s1.process, k, t, t);
            s0.process = rescaled(&s0.process, k, t, t);
            [
                (
                    llrs(&s1, model, run).recorded,
                    llrs(&s0, model, twin_run).recorded,
                ),
                (
                    band_unknown(&s1, run, bands).recorded,
                    band_unknown(&s0, twin_run, bands).recorded,
                ),
            ]
        })
        .collect()
}

/// The sweep's table over every Stenman loop and its twin.
pub fn sweep_table(md: &mut String, rows: &[Row], bands: usize) {
    let _ = writeln!(
        md,
        "\n## How near the truth the process must be (Stenman loops and their twins; load's model known, PV at the recorded samples)\n\n\
         The same oracle under a process off the truth, as an identification could leave it: the gain times 1 + e and the time constant and \
         dead time times (1 + e)² (too high), or both divided by as much (too low); the actuator lag, controller, noise and load's model as \
         they are. Band known, and band unknown (averaged over {bands} bands as above), at ratio 1 and at every threshold (the best one \
         chosen on these pairs, an upper bound for any threshold set elsewhere).\n\n\
         | process | pairs | balanced accuracy, band known | band unknown, at ratio 1 | band unknown, best threshold (in-sample) | band unknown, area under the ROC curve |\n|---|---|---|---|---|---|"
    );
    let swept: Vec<&Vec<Step>> = rows.iter().filter_map(|r| r.sweep.as_ref()).collect();
    for (i, (k, t)) in factors().enumerate() {
        let known: Vec<(f64, f64)> = swept.iter().map(|s| s[i][0]).collect();
        let unknown: Vec<(f64, f64)> = swept.iter().map(|s| s[i][1]).collect();
        let ba = |p: &[(f64, f64)]| {
            let (hit, twin) = shares(p);
            balanced(hit, twin)
        };
        let words = format!(
            "gain {:+.0} %, time constant and dead time {:+.0} %",
            100.0 * (k - 1.0),
            100.0 * (t - 1.0)
        );
        let _ = writeln!(
            md,
            "| {words} | {} | {:.3} | {:.3} | {:.3} | {:.3} |",
            swept.len(),
            ba(&known),
            ba(&unknown),
            best_balanced(&unknown),
            area_under_roc(&unknown)
        );
    }
}
