//! The hidden-valve oracle's rows: a Stenman loop of 10 s and its twin, each judged by the
//! particle filter (`particles.rs`) under the loop's valve and a healthy one, with the load's path
//! known, with a drift's model only, and with the process as the closed-loop fit identifies it.

use super::particles::log_likelihood;
use super::profile::rescaled;
use super::{balanced, pct, share, Row};
use std::fmt::Write as _;
use stiction_core::models::{Model, Stenman};
use stiction_core::quantify::{compare_fits, CompareRequest};
use stiction_core::sim::{ClosedLoop, Process};
use stiction_lab::catalogue::BenchmarkLoop;

/// The oracle's log-likelihood ratios on a sticky loop and its twin, and whether the filter under
/// the valve each record has kept track of both.
#[derive(Clone, Copy)]
pub struct Pair {
    sticky: f64,
    twin: f64,
    tracked: bool,
}

/// With the load's path known, with a drift's model only, with the process identified too; and
/// with a drift's model only under processes a little off the truth (how much of the identified
/// process's loss a better identification could win back).
pub type Hidden = [Option<Pair>; 6];

/// The share of records at which a filter may have lost track before its estimate is set aside.
const TRACKED: f64 = 0.01;

/// The hidden-valve oracle's log-likelihood ratios on a Stenman loop `l` and its twin, and
/// whether the filter under the valve each record has kept track: with the load's path known,
/// with a drift's model only, and with the process as the closed-loop fit identifies it.
pub fn hidden(l: &BenchmarkLoop, twin_setup: &ClosedLoop, particles: usize) -> Option<Hidden> {
    let twin_data = twin_setup.run().ok()?;
    let healthy = Model::Stenman(Stenman { d: 0.0 });
    // the ratio, and whether the filter under the valve the loop has kept track
    let llr = |setup: &ClosedLoop, op: &[f64], pv: &[f64], sticky: bool, known: bool| {
        let seed = setup.seed ^ 0x5eed;
        let a = log_likelihood(setup, &l.setup.model, op, pv, particles, seed, known)?;
        let b = log_likelihood(setup, &healthy, op, pv, particles, seed, known)?;
        let lost = if sticky { a.lost } else { b.lost };
        Some((a.log_likelihood - b.log_likelihood, lost <= TRACKED))
    };
    let pair = |known: bool| -> Option<Pair> {
        let (sticky, kept) = llr(&l.setup, &l.data.op, &l.data.pv, true, known)?;
        let (twin, twin_kept) = llr(twin_setup, &twin_data.op, &twin_data.pv, false, known)?;
        Some(Pair {
            sticky,
            twin,
            tracked: kept && twin_kept,
        })
    };
    // the sticky loop and its twin under loops `s1`, `s0` other than their own, a drift's model
    // only
    let under = |s1: &ClosedLoop, s0: &ClosedLoop| -> Option<Pair> {
        let (sticky, kept) = llr(s1, &l.data.op, &l.data.pv, true, false)?;
        let (twin, twin_kept) = llr(s0, &twin_data.op, &twin_data.pv, false, false)?;
        Some(Pair {
            sticky,
            twin,
            tracked: kept && twin_kept,
        })
    };
    let fitted = || -> Option<Pair> {
        let s1 = identified(l, &l.setup, &l.data.op, &l.data.pv)?;
        let s0 = identified(l, twin_setup, &twin_data.op, &twin_data.pv)?;
        under(&s1, &s0)
    };
    // the true process a little off, as an identification could leave it
    let off = |change: Change| -> Option<Pair> {
        let (mut s1, mut s0) = (l.setup.clone(), twin_setup.clone());
        change(&mut s1);
        change(&mut s0);
        under(&s1, &s0)
    };
    Some([
        pair(true),
        pair(false),
        fitted(),
        off(OFF[0].1),
        off(OFF[1].1),
        off(OFF[2].1),
    ])
}

/// The loop `setup` (of the catalogue's loop `l`) with its process as the closed-loop fit
/// identifies it from the record `op`, `pv` (first order with dead time, or integrating), the
/// actuator lag left to it, and the noise raised to the fit's misfit.
pub fn identified(
    l: &BenchmarkLoop,
    setup: &ClosedLoop,
    op: &[f64],
    pv: &[f64],
) -> Option<ClosedLoop> {
    let f = compare_fits(
        op,
        pv,
        &CompareRequest {
            ts: setup.ts,
            integrating: Some(l.integrating),
            ..CompareRequest::default()
        },
    )?;
    let k = f.gain?;
    let mut s = setup.clone();
    s.process = if l.integrating {
        Process::Integrating {
            k,
            delay: f.dead_time,
        }
    } else {
        Process::Foptd {
            k,
            tau: f.time_constant.unwrap_or(0.0).max(0.1),
            delay: f.dead_time,
        }
    };
    s.valve_lag = 0.0;
    // the model's error counted as noise: the fit's simulation error on the changes over its
    // lag holds two samples' noise
    let misfit = (f.linear.sse.min(f.stenman.sse) / (2.0 * f.samples_used.max(1) as f64)).sqrt();
    s.noise = s.noise.max(misfit);
    Some(s)
}

/// A change made to a loop's setup.
pub type Change = fn(&mut ClosedLoop);

/// The ways of knowing the process a little wrong, as an identification could leave it.
pub const OFF: [(&str, Change); 3] = [
    ("the actuator lag left out", |s| s.valve_lag = 0.0),
    (
        "the process's gain 10 % high, time constant and dead time 20 % long",
        |s| s.process = rescaled(&s.process, 1.1, 1.2, 1.2),
    ),
    (
        "the process's gain 10 % low, time constant and dead time 20 % short",
        |s| s.process = rescaled(&s.process, 0.9, 0.8, 0.8),
    ),
];

/// The oracle's table: each way of knowing the load, over all loops and over those whose filter
/// kept track.
pub fn hidden_table(md: &mut String, rows: &[Row], particles: usize) {
    let all: Vec<&Hidden> = rows.iter().filter_map(|r| r.hidden.as_ref()).collect();
    let _ = writeln!(
        md,
        "\n## OP and PV at the recorded samples, what happens between them hidden (Stenman loops of 750 samples every 10 s, {particles} particles)\n\n\
         A particle filter over the whole loop (see `particles.rs`): the process, controller, noise, setpoint, the valve model and the load's path (or, for a drift, only its model) known; \
         the measurement noise the controller saw between the records hidden. With the load's path known this is more than any method has; with a drift's model only, no more than the first oracles. \
         The filter's estimate is biased low where it loses track of PV (every particle 10 noise standard deviations away from the record): \
         under the wrong valve that is the evidence itself, under the valve the loop has it makes the ratio uncertain. The rows \"kept track\" keep the loops \
         whose filter under their own valve lost track at no more than 1 % of the records. The last column takes the threshold \
         that does best on the loops themselves: how well the ratio ranks sticky loops above twins, not a test.\n"
    );
    let _ = writeln!(
        md,
        "| load | loops | sticky called stiction | twins called healthy | balanced accuracy | at the best threshold (in-sample) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    for (i, load) in [
        "its path known",
        "its model known (a drift's level and slope in each particle)",
        "its model known, the process as the closed-loop fit identifies it (the noise raised to the fit's misfit)",
    ]
    .into_iter()
    .map(String::from)
    .chain(OFF.iter().map(|(w, _)| format!("its model known, {w}")))
    .enumerate()
    {
        let every: Vec<Pair> = all.iter().filter_map(|h| h[i]).collect();
        let tracked: Vec<Pair> = every.iter().copied().filter(|h| h.tracked).collect();
        for (words, part) in [
            ("all", &every),
            ("the filter under the loop's own valve kept track", &tracked),
        ] {
            let hit = share(part.iter().map(|h| h.sticky > 0.0));
            let twin = share(part.iter().map(|h| h.twin <= 0.0));
            let ba = balanced(hit, twin);
            let _ = writeln!(
                md,
                "| {load} | {words} ({}) | {} | {} | {ba:.3} | {:.3} |",
                part.len(),
                pct(hit),
                pct(twin),
                best_threshold(part)
            );
        }
    }
}

/// The balanced accuracy of "stiction above a threshold" at the threshold that does best on these
/// loops themselves: how well the ratio ranks sticky loops above twins, not a test's accuracy.
fn best_threshold(part: &[Pair]) -> f64 {
    let mut cuts: Vec<f64> = part.iter().flat_map(|p| [p.sticky, p.twin]).collect();
    cuts.push(f64::NEG_INFINITY);
    cuts.iter()
        .map(|&c| {
            balanced(
                share(part.iter().map(|p| p.sticky > c)),
                share(part.iter().map(|p| p.twin <= c)),
            )
        })
        .fold(0.0, f64::max)
}
