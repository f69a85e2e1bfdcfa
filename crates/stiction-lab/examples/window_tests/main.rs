//! The simple published tests beside `diagnose`, on the catalogue's loops (issue 10: "simple
//! published window tests and a Kano-style stick, then jump check found far more of the sticky
//! valves than we did, though with many false alarms on healthy loops; we must find what they
//! find without their false alarms").
//!
//!     cargo run --release -p stiction-lab --example window_tests -- [--set routine|fast|all]
//!         [--draws N] [--out crates/stiction-lab/results/window-tests.md]
//!
//! Each baseline (`baselines.rs`) gives a count per record and flags it sticky either from a
//! count of one (the naive reading: any window fires) or from a rate (the share of windows that
//! fire; sticks per 1,000 samples, since records differ in length) calibrated as `diagnose`'s
//! thresholds were: on the calibration set and the first `--draws` further draws (3 by default;
//! other seeds than the benchmark's), the smallest count at which the baseline calls no more of
//! the not-sticky loops sticky than `diagnose` does on the same loops. Then the benchmark set is
//! judged by all of them. Backlash-only valves are left out of every figure, as in the goals.

mod baselines;
use stiction_lab::catalogue_loop;
mod tables;

use rayon::prelude::*;
use std::process::exit;
use stiction_core::diagnose::{diagnose, Verdict};
use stiction_lab::catalogue::{self, BenchmarkLoop, LoopClass, Set, Suite, Truth};

/// What one loop gave: its class and truth, the baselines' counts, and `diagnose`'s verdict.
pub struct Judged {
    pub class: LoopClass,
    pub truth: Truth,
    /// Windows where OP changes while PV stays steady, with each window length of
    /// [`baselines::WINDOWS`].
    pub windows: Vec<usize>,
    /// The share of the record's windows that fire, with each window length.
    pub window_share: Vec<f64>,
    /// Sticks ended by a jump.
    pub sticks: usize,
    /// Sticks per 1,000 samples.
    pub stick_rate: f64,
    /// `diagnose` called it `stiction`.
    pub ours: bool,
}

fn judge(l: &BenchmarkLoop) -> Judged {
    let (rec, req) = (catalogue_loop::record(l), catalogue_loop::request(l));
    let d = diagnose(&rec, &req).expect("catalogue records are valid requests");
    let counts: Vec<(usize, usize)> = (0..baselines::WINDOWS.len())
        .map(|k| baselines::window_count(&l.data.op, &l.data.pv, k))
        .collect();
    let sticks = baselines::stick_jump_count(&l.data.op, &l.data.pv);
    Judged {
        class: l.class,
        truth: l.truth,
        windows: counts.iter().map(|c| c.0).collect(),
        window_share: counts
            .iter()
            .map(|&(n, of)| n as f64 / of.max(1) as f64)
            .collect(),
        sticks,
        stick_rate: 1000.0 * sticks as f64 / l.data.op.len().max(1) as f64,
        ours: d.verdict == Verdict::Stiction,
    }
}

fn fail(msg: &str) -> ! {
    eprintln!("window_tests: {msg}");
    exit(2)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter().position(|a| a == flag).map(|i| {
            args.get(i + 1)
                .cloned()
                .unwrap_or_else(|| fail(&format!("{flag} needs a value")))
        })
    };
    let suites = match value("--set").as_deref() {
        None | Some("all") => vec![Suite::Routine, Suite::Fast],
        Some("routine") => vec![Suite::Routine],
        Some("fast") => vec![Suite::Fast],
        Some(other) => fail(&format!("--set {other}: use routine, fast or all")),
    };
    let draws: u8 = value("--draws")
        .map(|v| {
            v.parse()
                .unwrap_or_else(|_| fail("--draws needs a number from 0 to 255"))
        })
        .unwrap_or(3);
    let mut md = tables::header(draws);
    for suite in suites {
        let mut calibration: Vec<BenchmarkLoop> = catalogue::catalogue(suite, Set::Calibration);
        for k in 1..=draws {
            calibration.extend(catalogue::catalogue(suite, Set::Extra(k)));
        }
        let cal: Vec<Judged> = calibration.par_iter().map(judge).collect();
        drop(calibration);
        let bench: Vec<Judged> = catalogue::catalogue(suite, Set::Benchmark)
            .par_iter()
            .map(judge)
            .collect();
        tables::suite(&mut md, suite, &cal, &bench);
    }
    match value("--out") {
        Some(path) => std::fs::write(&path, &md)
            .unwrap_or_else(|e| fail(&format!("{path}: cannot write: {e}"))),
        None => print!("{md}"),
    }
}
