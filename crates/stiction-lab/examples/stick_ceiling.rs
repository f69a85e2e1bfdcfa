//! How many sticks the data show: on the catalogue's routine sticky loops (issue 10), the
//! simulator's recorded valve position (MV) says exactly when the valve was stuck. Each stuck
//! interval is held to what the stick-slip family (`diagnose::evidence::stick_slip`) needs to see
//! a stick at all, with the process's true gain:
//!
//! - **visible**: OP (smoothed over 5 samples, as the family does) travels at least
//!   `Thresholds::op_travel_sigmas` OP noise standard deviations while MV holds, and that travel through the
//!   process gain would move PV by at least two PV bands (`2 * Thresholds::pv_band_sigmas` noise standard
//!   deviations; for a level, PV's smoothed rate of change);
//! - **quiet**: a visible stick in which PV also stays inside one band (the family's rule);
//! - **drifting**: a visible stick in which PV never moves OP's way by more than a band (PV may
//!   drift with the load against OP's push; the rule a load-tolerant family would use).
//!
//! The family votes stiction from 5 episodes, so the share of loops with 5 or more visible sticks
//! is a ceiling for it on these records, whatever rule it uses to find them.
//!
//!     cargo run --release -p stiction-lab --example stick_ceiling -- [--benchmark] [--out FILE]
//!
//! The calibration set by default (`--benchmark`: the benchmark seeds).

use stiction_lab::catalogue_loop;
use stiction_lab::study_args;

use rayon::prelude::*;
use std::fmt::Write as _;
use stiction_core::diagnose::Thresholds;
use stiction_core::diagnose::{diagnose, noise_std, Family, Vote};
use stiction_lab::catalogue::{self, BenchmarkLoop, Set, Suite, Truth};
use study_args::StudyArgs;

struct Row {
    group: String,
    stuck: usize,
    visible: usize,
    quiet: usize,
    drifting: usize,
    family_votes: bool,
}

/// Centred moving average over `w` samples.
fn smooth(x: &[f64], w: usize) -> Vec<f64> {
    let h = w / 2;
    (0..x.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(h), (i + h + 1).min(x.len()));
            x[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
        })
        .collect()
}

/// The stuck intervals `[i, j)`: MV holds exactly for at least 3 samples, and the record goes on.
fn stuck_intervals(mv: &[f64]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i + 1 < mv.len() {
        let mut j = i + 1;
        while j < mv.len() && mv[j] == mv[i] {
            j += 1;
        }
        if j - i >= 3 && j < mv.len() {
            out.push((i, j));
        }
        i = j;
    }
    out
}

fn judge(l: &BenchmarkLoop) -> Row {
    let t = Thresholds::default();
    let d = &l.data;
    let ts = l.ts();
    // the process gain in units of the judged signal per OP unit (a level's rate per sample)
    let p = &l.setup.process;
    let gain = p.gain() * if p.is_integrating() { ts } else { 1.0 };
    // the judged signal: PV, or a level's smoothed rate of change (as the family judges it)
    let y = if l.integrating {
        let rate: Vec<f64> = std::iter::once(0.0)
            .chain(d.pv.windows(2).map(|w| w[1] - w[0]))
            .collect();
        smooth(&smooth(&rate, 5), 5)
    } else {
        d.pv.clone()
    };
    let band = t.pv_band_sigmas * noise_std(&y);
    let op_noise = noise_std(&d.op);
    let (op_s, y_s) = (smooth(&d.op, 5), smooth(&y, 5));
    let dead = (p.delay() / ts).round() as usize;
    let mut row = Row {
        group: format!("{} | {} at {} s", l.class, d.op.len(), ts),
        stuck: 0,
        visible: 0,
        quiet: 0,
        drifting: 0,
        family_votes: false,
    };
    for (i, j) in stuck_intervals(&d.mv) {
        row.stuck += 1;
        let travel = op_s[j - 1] - op_s[i];
        if travel.abs() < t.op_travel_sigmas * op_noise || (gain * travel).abs() < 2.0 * band {
            continue;
        }
        row.visible += 1;
        let (lo, hi) = y[i..j]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        if hi - lo <= 2.0 * band {
            row.quiet += 1;
        }
        // PV's largest move OP's way from its running extreme against OP, before the slip
        // can show (the last dead time of the interval left out)
        let push = travel.signum() * gain.signum();
        let end = j.saturating_sub(dead + 2).max(i + 2).min(j);
        let mut low = f64::INFINITY;
        let mut back: f64 = 0.0;
        for &v in &y_s[i..end] {
            low = low.min(v * push);
            back = back.max(v * push - low);
        }
        if back <= band {
            row.drifting += 1;
        }
    }
    let (record, req) = (catalogue_loop::record(l), catalogue_loop::request(l));
    row.family_votes = diagnose(&record, &req).is_ok_and(|g| {
        g.families
            .iter()
            .any(|f| f.family == Family::StickSlip && f.vote == Vote::Stiction)
    });
    row
}

fn main() {
    let t = Thresholds::default();
    // sticks a loop needs for the stick-slip family's stiction vote
    let needed = t.min_episodes;
    let op_travel_sigmas = t.op_travel_sigmas;
    let args = StudyArgs::from_env("stick_ceiling");
    let set = args.set();
    let loops: Vec<BenchmarkLoop> = catalogue::catalogue(Suite::Routine, set)
        .into_iter()
        .filter(|l| l.truth == Truth::Sticky)
        .collect();
    let rows: Vec<Row> = loops.par_iter().map(judge).collect();
    let mut groups: Vec<&str> = rows.iter().map(|r| r.group.as_str()).collect();
    groups.sort();
    groups.dedup();
    let mut md = String::new();
    let _ = writeln!(md, "# Stick-slip family: how many sticks the data show ({set:?} set, routine suite, sticky loops)\n");
    let _ = writeln!(md, "Generated by `cargo run --release -p stiction-lab --example stick_ceiling`{}. The recorded valve position says when the valve was stuck; a stuck interval is *visible* when OP travels at least {op_travel_sigmas} OP noise standard deviations in it and that travel, through the true process gain, would move PV by two PV bands ({} noise standard deviations); *quiet* when PV also stays inside one band (the family's rule today); *drifting* when PV never moves OP's way by more than a band (PV may drift with the load against OP). The family votes stiction from {needed} episodes, so the share with {needed} or more visible sticks is a ceiling for it on these records.\n", if set == Set::Benchmark { " -- --benchmark" } else { "" }, 2.0 * t.pv_band_sigmas);
    let _ = writeln!(md, "| class | record | loops | median stuck intervals | median visible sticks | >= {needed} visible | >= {needed} quiet | >= {needed} drifting | family votes stiction |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|");
    let mut all: Vec<&Row> = Vec::new();
    for g in groups {
        let of: Vec<&Row> = rows.iter().filter(|r| r.group == g).collect();
        all.extend(&of);
        let _ = writeln!(md, "| {g} | {} |", line(&of));
    }
    let _ = writeln!(md, "| all sticky | both | {} |", line(&all));
    args.emit(&md);
}

/// One table row's figures for the loops `of`.
fn line(of: &[&Row]) -> String {
    let needed = Thresholds::default().min_episodes;
    let n = of.len() as f64;
    let share = |f: &dyn Fn(&Row) -> bool| 100.0 * of.iter().filter(|r| f(r)).count() as f64 / n;
    let median = |f: &dyn Fn(&Row) -> usize| {
        let mut v: Vec<usize> = of.iter().map(|r| f(r)).collect();
        v.sort_unstable();
        v[v.len() / 2]
    };
    format!(
        "{} | {} | {} | {:.0} % | {:.0} % | {:.0} % | {:.0} %",
        of.len(),
        median(&|r| r.stuck),
        median(&|r| r.visible),
        share(&|r| r.visible >= needed),
        share(&|r| r.quiet >= needed),
        share(&|r| r.drifting >= needed),
        share(&|r| r.family_votes),
    )
}
