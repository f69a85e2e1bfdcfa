//! How much of the model family's misses is the fit's, and how much the data's: on the catalogue's
//! routine loops (issue 10), a plain output-error test of "does this valve trajectory explain PV
//! better than OP does?" with the *recorded* valve position (the simulator's truth, a ceiling no
//! method that sees only OP and PV can beat), with the valve the closed-loop fit found
//! (`quantify::compare_fits`, what `diagnose`'s model family judges), and the model family's own
//! vote.
//!
//!     cargo run --release -p stiction-core --example model_ceiling -- [--benchmark] [--out FILE]
//!
//! The test: PV on its levels against a bank of first-order filters of the valve position (time
//! constants 0.3 to 128 samples, each delayed a sample, and pure delays of 2 to 8 samples; for a
//! level loop also the valve's running sum) and a piecewise-linear drift (a knot every 150
//! samples), by least squares; the statistic is the log-likelihood ratio
//! `n/2 ln(SSE with OP / SSE with the valve)`. The regressors hold only valve positions before
//! the PV sample, and the drift is smooth, so the PV's measurement noise (which the controller
//! feeds back into OP at once) cannot favour OP. The calibration set by default (`--benchmark`:
//! the benchmark seeds).

#[path = "common/catalogue_loop.rs"]
mod catalogue_loop;

use rayon::prelude::*;
use std::fmt::Write as _;
use stiction_core::diagnose::{diagnose, Vote};
use stiction_core::quantify::{compare_fits, CompareRequest};
use stiction_core::sim::catalogue::{self, BenchmarkLoop, Set, Suite, Truth};

/// The log-likelihood ratio a loop must reach to count as "the data show the valve".
const SHOWS: f64 = 20.0;
/// Samples between the drift's knots.
const KNOT_EVERY: usize = 150;

/// Columns of the regression, each `n` long.
fn regressors(valve: &[f64], integrating: bool) -> Vec<Vec<f64>> {
    let n = valve.len();
    let mean = valve.iter().sum::<f64>() / n as f64;
    let u: Vec<f64> = valve.iter().map(|v| v - mean).collect();
    let mut cols = Vec::new();
    for tau in [0.3, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0] {
        let a = (-1.0f64 / tau).exp();
        let mut s = u[0];
        let mut c = vec![0.0; n];
        for t in 1..n {
            c[t] = s;
            s = a * s + (1.0 - a) * u[t];
        }
        cols.push(c);
    }
    for d in [2, 3, 5, 8] {
        cols.push(
            (0..n)
                .map(|t| if t >= d { u[t - d] } else { 0.0 })
                .collect(),
        );
    }
    if integrating {
        let mut s = 0.0;
        cols.push(
            (0..n)
                .map(|t| {
                    let c = s;
                    s += u[t];
                    c
                })
                .collect(),
        );
    }
    let knots = (n / KNOT_EVERY).max(2);
    cols.push(vec![1.0; n]);
    for k in 0..knots {
        let at = k * n / knots;
        cols.push((0..n).map(|t| t.saturating_sub(at) as f64).collect());
    }
    cols
}

/// Residual sum of squares of `y` regressed on `cols` (normal equations, Cholesky, a small ridge).
fn sse(y: &[f64], cols: &[Vec<f64>]) -> f64 {
    let p = cols.len();
    let mut a = vec![vec![0.0; p]; p];
    let mut b = vec![0.0; p];
    for i in 0..p {
        b[i] = cols[i].iter().zip(y).map(|(x, y)| x * y).sum();
        for j in i..p {
            a[i][j] = cols[i].iter().zip(&cols[j]).map(|(x, z)| x * z).sum();
            a[j][i] = a[i][j];
        }
    }
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-9 * row[i].abs().max(1e-12);
    }
    // Cholesky a = l lᵀ
    let mut l = vec![vec![0.0; p]; p];
    for i in 0..p {
        for j in 0..=i {
            let s: f64 = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = if i == j {
                s.max(1e-300).sqrt()
            } else {
                s / l[j][j]
            };
        }
    }
    let mut z = vec![0.0; p];
    for i in 0..p {
        z[i] = (b[i] - (0..i).map(|k| l[i][k] * z[k]).sum::<f64>()) / l[i][i];
    }
    let mut th = vec![0.0; p];
    for i in (0..p).rev() {
        th[i] = (z[i] - (i + 1..p).map(|k| l[k][i] * th[k]).sum::<f64>()) / l[i][i];
    }
    (0..y.len())
        .map(|t| {
            let e = y[t] - (0..p).map(|i| th[i] * cols[i][t]).sum::<f64>();
            e * e
        })
        .sum()
}

/// The ratio for `valve`, against OP's residual sum of squares `with_op`.
fn llr(pv: &[f64], with_op: f64, valve: &[f64], integrating: bool) -> f64 {
    let with_valve = sse(pv, &regressors(valve, integrating));
    pv.len() as f64 / 2.0 * (with_op / with_valve.max(f64::MIN_POSITIVE)).ln()
}

struct Row {
    class: String,
    truth: Truth,
    oracle: f64,
    fitted: Option<f64>,
    model_vote: Option<Vote>,
}

fn judge(l: &BenchmarkLoop) -> Row {
    let d = &l.data;
    let with_op = sse(&d.pv, &regressors(&d.op, l.integrating));
    let oracle = llr(&d.pv, with_op, &d.mv, l.integrating);
    let req = CompareRequest {
        ts: l.ts(),
        integrating: Some(l.integrating),
        ..CompareRequest::default()
    };
    let fitted = compare_fits(&d.op, &d.pv, &req)
        .map(|f| llr(&d.pv, with_op, &f.mv_stiction, l.integrating));
    let (record, dreq) = (catalogue_loop::record(l), catalogue_loop::request(l));
    let model_vote = diagnose(&record, &dreq).ok().and_then(|g| {
        g.families
            .iter()
            .find(|f| f.family == stiction_core::diagnose::Family::Model)
            .map(|f| f.vote)
    });
    Row {
        class: l.class.to_string(),
        truth: l.truth,
        oracle,
        fitted,
        model_vote,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let set = if args.iter().any(|a| a == "--benchmark") {
        Set::Benchmark
    } else {
        Set::Calibration
    };
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1));
    let loops = catalogue::catalogue(Suite::Routine, set);
    let rows: Vec<Row> = loops.par_iter().map(judge).collect();
    let mut classes: Vec<&str> = Vec::new();
    for r in &rows {
        if !classes.contains(&r.class.as_str()) {
            classes.push(&r.class);
        }
    }
    let mut md = String::new();
    let _ = writeln!(md, "# Model family: what the data show against what the fit finds ({set:?} set, routine suite)\n");
    let _ = writeln!(md, "Generated by `cargo run --release -p stiction-core --example model_ceiling`{}. Share of each class's loops whose log-likelihood ratio (PV explained by a valve trajectory against by OP; levels, filter-bank dynamics, piecewise-linear drift; see the example's docs) reaches {SHOWS}: with the recorded valve position (the truth: a ceiling), with the valve the closed-loop fit found (`compare_fits`), and the model family's stiction votes.\n", if set == Set::Benchmark { " -- --benchmark" } else { "" });
    let _ = writeln!(md, "| class | truth | loops | recorded valve >= {SHOWS} | fitted valve >= {SHOWS} | model family votes stiction | median ratio, recorded valve |");
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for c in classes {
        let of: Vec<&Row> = rows.iter().filter(|r| r.class == c).collect();
        let n = of.len() as f64;
        let share =
            |f: &dyn Fn(&Row) -> bool| 100.0 * of.iter().filter(|r| f(r)).count() as f64 / n;
        let mut o: Vec<f64> = of.iter().map(|r| r.oracle).collect();
        o.sort_by(f64::total_cmp);
        let _ = writeln!(
            md,
            "| {c} | {} | {} | {:.0} % | {:.0} % | {:.0} % | {:.1} |",
            of[0].truth.name(),
            of.len(),
            share(&|r| r.oracle >= SHOWS),
            share(&|r| r.fitted.is_some_and(|v| v >= SHOWS)),
            share(&|r| r.model_vote == Some(Vote::Stiction)),
            o[o.len() / 2]
        );
    }
    match out {
        Some(path) => std::fs::write(path, &md).unwrap_or_else(|e| {
            eprintln!("model_ceiling: {path}: cannot write: {e}");
            std::process::exit(1)
        }),
        None => print!("{md}"),
    }
}
