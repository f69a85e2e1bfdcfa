//! Does a band search under a clean cost find what the model family misses? (issue 10, after
//! `model_ceiling`.) On the catalogue's loops, every distinct Stenman valve trajectory from OP
//! (the exact partition of the band's range, `estimate::exact::stenman_walk`, the valve at the
//! first OP) is scored with the plain output-error test on levels (`stiction_lab::clean_fit`: a
//! filter bank beside a piecewise-linear drift, which the controller's proportional kick cannot
//! bias), and the best band's log-likelihood ratio against OP is held to the thresholds. Beside
//! it: the same test with the recorded valve position (a ceiling), the model family's vote (since
//! issue 69 its statistics' share of the verdict model's log-odds, stiction from `diagnose::VOTE`) and
//! `diagnose`'s verdict, and what the verdict would be with the walk's test added.
//!
//!     cargo run --release -p stiction-lab --example clean_walk -- [--suite routine|fast] [--benchmark] [--out FILE] [--jsonl FILE]
//!
//! `--jsonl FILE` also writes a line per loop with the walked ratio, the same walk whitened by an
//! AR noise model (`identify::levels`, the levels test `diagnose --thorough` ran before issue 69), the whitened
//! walk held to 40 bands of a geometric grid only (`coarse`: a cheap walk loses most of what the
//! exact one finds), the recorded valve's ratios and `diagnose`'s result.
//!
//! Slow on purpose (every trajectory fitted in full, about 0.15 s for 750 samples and 2 s for
//! 2,000 on one core): a study, not a method `diagnose` can afford as it stands.

use stiction_lab::catalogue_loop;
use stiction_lab::clean_fit;
use stiction_lab::study_args;

use clean_fit::CleanFit;
use rayon::prelude::*;
use std::fmt::Write as _;
use stiction_core::diagnose::{diagnose, Family, Verdict, Vote};
use stiction_core::estimate::exact::stenman_walk;
use stiction_core::identify::levels::LevelsFit;
/// The filter bank: the levels test's (time constants 0.5-160 samples, delays 3 and 8).
use stiction_core::identify::levels::BANK;
use stiction_core::models::Model;
use stiction_lab::catalogue::{self, BenchmarkLoop, Set, Suite, Truth};
use study_args::StudyArgs;

/// The ratios reported; [`ADDED`] is the one the "added" verdicts use.
const SHOWS: [f64; 2] = [20.0, 30.0];
const ADDED: f64 = 30.0;
/// Bands on the coarse geometric grid (0.2 % to half of OP's range).
const COARSE: usize = 40;

struct Row {
    id: String,
    walked_white: f64,
    recorded_white: f64,
    coarse: f64,
    coarse_cells: usize,
    diagnosis: Option<String>,
    class: String,
    truth: Truth,
    samples: usize,
    walked: f64,
    recorded: f64,
    band: f64,
    /// Stenman's d of the simulated valve (OP units), for Stenman loops.
    true_d: Option<f64>,
    cells: usize,
    seconds: f64,
    model_vote: Option<Vote>,
    verdict: Option<Verdict>,
}

fn judge(l: &BenchmarkLoop) -> Row {
    let d = &l.data;
    let clock = std::time::Instant::now();
    let fit = CleanFit::new(&d.pv, l.integrating, BANK);
    let with_op = fit.sse(&d.op);
    // the same test whitened by an AR noise model (`identify::levels`, what `--thorough` ran)
    let white = LevelsFit::new(&d.pv, &d.op, l.integrating);
    let mut scratch = white.scratch();
    let white_op = white.sse(&d.op, &mut scratch);
    let mut white_best = f64::INFINITY;
    let mut coarse_best = f64::INFINITY;
    let mut coarse_cells = 0usize;
    let (lo, hi) =
        d.op.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
    let range = (hi - lo).max(f64::MIN_POSITIVE);
    let grid: Vec<f64> = (0..COARSE)
        .map(|i| range * 0.002 * (250.0f64).powf(i as f64 / (COARSE - 1) as f64))
        .collect();
    let (mut best, mut band, mut cells) = (f64::INFINITY, 0.0, 0);
    let mut valve = vec![0.0; d.op.len()];
    let whole = (0.0, range * (1.0 + 1e-9));
    stenman_walk(
        &d.op,
        d.op[0],
        (range * 1e-4, range),
        whole,
        &mut valve,
        |cell, mv| {
            cells += 1;
            let s = fit.sse(mv);
            if s < best {
                (best, band) = (s, 0.5 * (cell.0 + cell.1));
            }
            let w = white.sse(mv, &mut scratch);
            white_best = white_best.min(w);
            if grid.iter().any(|&g| g >= cell.0 && g < cell.1) {
                coarse_best = coarse_best.min(w);
                coarse_cells += 1;
            }
        },
    );
    let n = d.pv.len() as f64;
    let walked = n / 2.0 * (with_op / best.max(f64::MIN_POSITIVE)).ln();
    let walked_white = white.ratio(white_op, white_best);
    let recorded_white = white.ratio(white_op, white.sse(&d.mv, &mut scratch));
    let coarse = white.ratio(white_op, coarse_best);
    let seconds = clock.elapsed().as_secs_f64();
    let recorded = fit.llr(with_op, &d.mv);
    let diagnosis = diagnose(&catalogue_loop::record(l), &catalogue_loop::request(l)).ok();
    Row {
        id: l.id.clone(),
        walked_white,
        recorded_white,
        coarse,
        coarse_cells,
        diagnosis: diagnosis
            .as_ref()
            .and_then(|g| serde_json::to_string(g).ok()),
        class: l.class.to_string(),
        truth: l.truth,
        samples: d.pv.len(),
        walked,
        recorded,
        band,
        true_d: match l.setup.model {
            Model::Stenman(m) => Some(m.d),
            _ => None,
        },
        cells,
        seconds,
        model_vote: diagnosis.as_ref().and_then(|g| {
            g.families
                .iter()
                .find(|f| f.family == Family::Model)
                .map(|f| f.vote)
        }),
        verdict: diagnosis.map(|g| g.verdict),
    }
}

/// The verdict with the walk's test added: `everywhere`, or only where `diagnose` did not decide.
fn added(r: &Row, everywhere: bool) -> Option<Verdict> {
    let undecided = matches!(
        r.verdict,
        Some(Verdict::Undetermined | Verdict::InsufficientData) | None
    );
    if r.walked >= ADDED && (everywhere || undecided) {
        Some(Verdict::Stiction)
    } else {
        r.verdict
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn share(of: &[&Row], f: impl Fn(&Row) -> bool) -> f64 {
    100.0 * of.iter().filter(|r| f(r)).count() as f64 / of.len().max(1) as f64
}

/// Balanced accuracy and each not-sticky class's share not called stiction, under `verdict`.
fn goals(rows: &[Row], classes: &[&str], verdict: impl Fn(&Row) -> Option<Verdict>) -> String {
    let sticky: Vec<&Row> = rows.iter().filter(|r| r.truth == Truth::Sticky).collect();
    let healthy: Vec<&Row> = rows
        .iter()
        .filter(|r| r.truth == Truth::NotSticky)
        .collect();
    let hit = share(&sticky, |r| verdict(r) == Some(Verdict::Stiction)) / 100.0;
    let right = share(&healthy, |r| verdict(r) == Some(Verdict::NoStiction)) / 100.0;
    let mut s = format!("{:.3} ({hit:.3} / {right:.3})", 0.5 * (hit + right));
    for c in classes {
        let of: Vec<&Row> = healthy.iter().copied().filter(|r| r.class == *c).collect();
        if !of.is_empty() {
            let _ = write!(
                s,
                " | {:.0} %",
                share(&of, |r| verdict(r) != Some(Verdict::Stiction))
            );
        }
    }
    s
}

fn table(rows: &[Row], set: Set, suite: Suite) -> String {
    let mut classes: Vec<&str> = Vec::new();
    for r in rows {
        if !classes.contains(&r.class.as_str()) {
            classes.push(&r.class);
        }
    }
    let mut md = String::new();
    let _ = writeln!(md, "# Model family: the Stenman band walked under a clean cost ({set:?} set, {suite:?} suite)\n");
    let _ = writeln!(md, "Generated by `cargo run --release -p stiction-lab --example clean_walk -- --suite {}{} --out FILE`. Every distinct Stenman valve trajectory from OP is scored by the output-error test on levels of `model_ceiling` (filter bank and piecewise-linear drift; see the example's docs); the best band's log-likelihood ratio against OP is held to {} and {}. Beside it the same ratio with the recorded valve position (the truth: a ceiling), the model family's stiction votes and `diagnose`'s stiction verdicts as they stand.\n", if suite == Suite::Fast { "fast" } else { "routine" }, if set == Set::Benchmark { " --benchmark" } else { "" }, SHOWS[0], SHOWS[1]);
    let _ = writeln!(md, "| class | truth | loops | walked band >= {} | walked band >= {} | recorded valve >= {} | model family votes stiction | verdict stiction | trajectories (median) | seconds per loop (median) |", SHOWS[0], SHOWS[1], SHOWS[0]);
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for c in &classes {
        let of: Vec<&Row> = rows.iter().filter(|r| r.class == *c).collect();
        let _ = writeln!(
            md,
            "| {c} | {} | {} | {:.0} % | {:.0} % | {:.0} % | {:.0} % | {:.0} % | {:.0} | {:.2} |",
            of[0].truth.name(),
            of.len(),
            share(&of, |r| r.walked >= SHOWS[0]),
            share(&of, |r| r.walked >= SHOWS[1]),
            share(&of, |r| r.recorded >= SHOWS[0]),
            share(&of, |r| r.model_vote == Some(Vote::Stiction)),
            share(&of, |r| r.verdict == Some(Verdict::Stiction)),
            median(of.iter().map(|r| r.cells as f64).collect()),
            median(of.iter().map(|r| r.seconds).collect()),
        );
    }
    let _ = writeln!(md, "\nSticky loops by record length (routine suite: 750 samples every 10 s with the controller running faster, 2,000 every 1 s; fast suite: every 1-5 s):\n");
    let _ = writeln!(md, "| samples | sticky loops | walked band >= {ADDED} | recorded valve >= {ADDED} | Stenman loops | walked band within 25 % of the true d |");
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    let mut lengths: Vec<usize> = rows.iter().map(|r| r.samples).collect();
    lengths.sort_unstable();
    lengths.dedup();
    for n in lengths {
        let of: Vec<&Row> = rows
            .iter()
            .filter(|r| r.samples == n && r.truth == Truth::Sticky)
            .collect();
        if !of.is_empty() {
            let stenman: Vec<&Row> = of.iter().copied().filter(|r| r.true_d.is_some()).collect();
            let close = |r: &Row| r.true_d.is_some_and(|d| (r.band - d).abs() <= 0.25 * d);
            let _ = writeln!(
                md,
                "| {n} | {} | {:.0} % | {:.0} % | {} | {:.0} % |",
                of.len(),
                share(&of, |r| r.walked >= ADDED),
                share(&of, |r| r.recorded >= ADDED),
                stenman.len(),
                share(&stenman, close)
            );
        }
    }
    let not_sticky: Vec<&str> = classes
        .iter()
        .copied()
        .filter(|c| {
            rows.iter()
                .any(|r| r.class == *c && r.truth == Truth::NotSticky)
        })
        .collect();
    let _ = writeln!(md, "\nThe verdict with the walk's test added (a walked band's ratio of {ADDED} or more calls stiction), against `diagnose` as it stands: balanced accuracy (sticky called stiction / not-sticky called no_stiction), then each look-alike class's share not called stiction.\n");
    let _ = writeln!(
        md,
        "| verdict | balanced accuracy | {} |",
        not_sticky.join(" | ")
    );
    let _ = writeln!(md, "|---|---|{}", "---|".repeat(not_sticky.len()));
    let _ = writeln!(
        md,
        "| `diagnose` as it stands | {} |",
        goals(rows, &not_sticky, |r| r.verdict)
    );
    let _ = writeln!(
        md,
        "| test added where `diagnose` says undetermined or insufficient_data | {} |",
        goals(rows, &not_sticky, |r| added(r, false))
    );
    let _ = writeln!(
        md,
        "| test added everywhere | {} |",
        goals(rows, &not_sticky, |r| added(r, true))
    );
    md
}

fn main() {
    let args = StudyArgs::from_env("clean_walk");
    let set = args.set();
    let suite = args.suite();
    let loops = catalogue::catalogue(suite, set);
    let rows: Vec<Row> = loops.par_iter().map(judge).collect();
    if let Some(path) = args.value("--jsonl") {
        let mut out = String::new();
        for r in &rows {
            let _ = writeln!(out, "{{\"id\":\"{}\",\"class\":\"{}\",\"truth\":\"{}\",\"samples\":{},\"walked\":{},\"walked_white\":{},\"coarse\":{},\"coarse_cells\":{},\"recorded\":{},\"recorded_white\":{},\"band\":{},\"true_d\":{},\"diagnosis\":{}}}", r.id, r.class, r.truth.name(), r.samples, r.walked, r.walked_white, r.coarse, r.coarse_cells, r.recorded, r.recorded_white, r.band, r.true_d.map_or("null".into(), |d| d.to_string()), r.diagnosis.as_deref().unwrap_or("null"));
        }
        std::fs::write(path, out).unwrap_or_else(|e| args.fail(&format!("{path}: {e}")));
    }
    args.emit(&table(&rows, set, suite));
}
