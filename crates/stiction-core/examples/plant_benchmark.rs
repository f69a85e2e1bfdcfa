//! How `diagnose` does on the catalogue of simulated plant loops (`stiction_core::sim::catalogue`):
//! the routine historian windows of issue 10 and the fast limit-cycling loops of issue 14, with
//! the goals of both issues computed.
//!
//!     cargo run --release -p stiction-core --example plant_benchmark -- [--set routine|fast|all]
//!         [--calibration] [--thorough] [--only CLASS] [--out docs/plant-benchmark.md] [--jsonl FILE] [--threads N]
//!
//! Every loop is judged as `stiction diagnose loop.csv --sp sp` judges it: the setpoint and the
//! time column given, `integrating` from the loop, the default request otherwise (the closed-loop
//! check of a stiction verdict on). Loops run in parallel (rayon); the results keep catalogue
//! order and do not depend on the thread count. `--calibration` uses the calibration seeds (for
//! setting thresholds); without it, the benchmark seeds. `--only` keeps one class (its name as in
//! the tables). `--jsonl` writes one line per loop: id, class, truth, parameters, slip count and the
//! whole `Diagnosis`.
//!
//! The tables read only `verdict`, `confidence`, `reason` and `indices` (name, vote) of each
//! diagnosis, so they keep working while the evidence `diagnose` reports changes.
//!
//! Goals (issue 10, routine): balanced accuracy over sticky vs not-sticky loops at least 0.95,
//! where a sticky loop is right only when called `stiction` and a not-sticky one only when called
//! `no_stiction` (undecided answers count as wrong both ways); every look-alike class at least
//! 90 % not called `stiction`; `undetermined` plus `insufficient_data` at most 10 % of the loops.
//! The backlash-only valve is reported outside the goals. (Issue 14, fast): at least 95 % of the
//! sticky loops called `stiction`; every look-alike class at least 95 % not called `stiction`.

#[path = "common/catalogue_loop.rs"]
mod catalogue_loop;
#[path = "common/confidence_table.rs"]
mod confidence_table;

use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::process::exit;
use std::time::Instant;
use stiction_core::diagnose::{diagnose, Diagnosis, Verdict, Vote};
use stiction_core::sim::catalogue::{
    self, BenchmarkLoop, LoopClass, NoiseLevel, Set, Suite, Truth,
};

const VERDICTS: [Verdict; 4] = [
    Verdict::Stiction,
    Verdict::NoStiction,
    Verdict::Undetermined,
    Verdict::InsufficientData,
];

/// `--thorough`: the model family also runs the levels test (`DiagnoseRequest::thorough`).
static THOROUGH: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

struct Options {
    suites: Vec<Suite>,
    set: Set,
    only: Option<LoopClass>,
    out: Option<String>,
    jsonl: Option<String>,
    threads: Option<usize>,
}

fn fail(msg: &str) -> ! {
    eprintln!("plant_benchmark: {msg}");
    exit(2)
}

fn options() -> Options {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut o = Options {
        suites: vec![Suite::Routine, Suite::Fast],
        set: Set::Benchmark,
        only: None,
        out: None,
        jsonl: None,
        threads: None,
    };
    let mut i = 0;
    let value = |i: usize, flag: &str| -> String {
        args.get(i + 1)
            .cloned()
            .unwrap_or_else(|| fail(&format!("{flag} needs a value")))
    };
    while i < args.len() {
        let flag = args[i].as_str();
        match flag {
            "--set" => {
                o.suites = match value(i, flag).as_str() {
                    "routine" => vec![Suite::Routine],
                    "fast" => vec![Suite::Fast],
                    "all" => vec![Suite::Routine, Suite::Fast],
                    other => fail(&format!("--set {other}: use routine, fast or all")),
                }
            }
            "--only" => {
                o.only = Some(
                    value(i, flag)
                        .parse()
                        .unwrap_or_else(|e: String| fail(&format!("--only: {e}"))),
                )
            }
            "--out" => o.out = Some(value(i, flag)),
            "--jsonl" => o.jsonl = Some(value(i, flag)),
            "--threads" => {
                o.threads = Some(
                    value(i, flag)
                        .parse()
                        .ok()
                        .filter(|&n: &usize| n > 0)
                        .unwrap_or_else(|| fail("--threads needs a whole number above 0")),
                )
            }
            "--calibration" => {
                o.set = Set::Calibration;
                i += 1;
                continue;
            }
            "--thorough" => {
                THOROUGH.store(true, std::sync::atomic::Ordering::Relaxed);
                i += 1;
                continue;
            }
            other => fail(&format!(
                "unknown argument '{other}'; the flags are --set, --calibration, --thorough, --only, --out, --jsonl, --threads"
            )),
        }
        i += 2;
    }
    o
}

/// A loop's diagnosis, judged as the CLI judges a file with t, sp, op, pv columns.
fn judge(l: &BenchmarkLoop) -> (Diagnosis, f64) {
    let (rec, mut req) = (catalogue_loop::record(l), catalogue_loop::request(l));
    req.thorough = THOROUGH.load(std::sync::atomic::Ordering::Relaxed);
    let t = Instant::now();
    let dg = diagnose(&rec, &req).expect("catalogue records are valid requests");
    (dg, t.elapsed().as_secs_f64())
}

/// One line of `--jsonl`.
#[derive(Serialize)]
struct Line<'a> {
    id: &'a str,
    suite: Suite,
    set: Set,
    class: LoopClass,
    truth: Truth,
    kind: catalogue::LoopKind,
    integrating: bool,
    noise_level: NoiseLevel,
    description: &'a str,
    parameters: &'a stiction_core::sim::ClosedLoop,
    tuning: catalogue::Tuning,
    excitation: catalogue::Excitation,
    slips: usize,
    saturated: f64,
    attempts: u64,
    seconds: f64,
    diagnosis: &'a Diagnosis,
}

fn pct(n: usize, of: usize) -> String {
    if of == 0 {
        "-".into()
    } else {
        format!("{:.0} %", 100.0 * n as f64 / of as f64)
    }
}

fn count(ds: &[&Diagnosis], v: Verdict) -> usize {
    ds.iter().filter(|d| d.verdict == v).count()
}

/// Results grouped by class, in the catalogue's class order.
fn by_class<'a>(
    loops: &'a [BenchmarkLoop],
    res: &'a [(Diagnosis, f64)],
) -> BTreeMap<LoopClass, Vec<(&'a BenchmarkLoop, &'a Diagnosis)>> {
    let mut m: BTreeMap<LoopClass, Vec<_>> = BTreeMap::new();
    for (l, (d, _)) in loops.iter().zip(res) {
        m.entry(l.class).or_default().push((l, d));
    }
    m
}

/// With `--thorough`: the levels test's ratio per class (loops where it ran).
fn levels_table(md: &mut String, groups: &BTreeMap<LoopClass, Vec<(&BenchmarkLoop, &Diagnosis)>>) {
    let _ = writeln!(
        md,
        "The levels test's ratio (loops where it ran; it votes stiction from {:.0}):\n",
        stiction_core::diagnose::evidence::model::LEVELS_STICTION
    );
    let _ = writeln!(
        md,
        "| class | tested | median | 95th percentile | at or above the threshold |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for (class, of) in groups {
        let mut r: Vec<f64> = of
            .iter()
            .filter_map(|(_, d)| {
                d.families
                    .iter()
                    .find_map(|f| f.model.as_ref().and_then(|m| m.levels.as_ref()))
                    .map(|l| l.ratio)
            })
            .collect();
        r.sort_by(f64::total_cmp);
        let at = |q: f64| {
            r.get(((r.len() as f64 - 1.0) * q).round() as usize)
                .copied()
                .unwrap_or(f64::NAN)
        };
        let above = r
            .iter()
            .filter(|&&x| x >= stiction_core::diagnose::evidence::model::LEVELS_STICTION)
            .count();
        let _ = writeln!(
            md,
            "| {class} | {} of {} | {:.1} | {:.1} | {above} |",
            r.len(),
            of.len(),
            at(0.5),
            at(0.95)
        );
    }
    let _ = writeln!(md);
}

fn verdict_table(md: &mut String, groups: &BTreeMap<LoopClass, Vec<(&BenchmarkLoop, &Diagnosis)>>) {
    let _ = writeln!(
        md,
        "| class | truth | loops | stiction | no_stiction | undetermined | insufficient_data | right | mean confidence | slips (median) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|");
    for (class, items) in groups {
        let ds: Vec<&Diagnosis> = items.iter().map(|i| i.1).collect();
        let n = ds.len();
        let c = VERDICTS.map(|v| count(&ds, v));
        let right = match class.truth() {
            Truth::Sticky => pct(c[0], n),
            Truth::NotSticky => pct(c[1], n),
            Truth::BacklashOnly => "(outside the goals)".into(),
        };
        // the mean confidence of the decided verdicts
        let decided: Vec<f64> = ds.iter().filter_map(|d| d.confidence).collect();
        let conf = decided.iter().sum::<f64>() / decided.len().max(1) as f64;
        let mut slips: Vec<usize> = items.iter().map(|i| i.0.slips).collect();
        slips.sort_unstable();
        let _ = writeln!(
            md,
            "| {class} | {} | {n} | {} | {} | {} | {} | {right} | {conf:.2} | {} |",
            class.truth().name(),
            c[0],
            c[1],
            c[2],
            c[3],
            slips[slips.len() / 2]
        );
    }
    let _ = writeln!(md);
}

fn goal(md: &mut String, what: &str, value: String, target: &str, met: bool) {
    let _ = writeln!(
        md,
        "| {what} | {value} | {target} | {} |",
        if met { "met" } else { "missed" }
    );
}

fn goals(
    md: &mut String,
    suite: Suite,
    groups: &BTreeMap<LoopClass, Vec<(&BenchmarkLoop, &Diagnosis)>>,
) {
    let of = |t: Truth| -> Vec<&Diagnosis> {
        groups
            .iter()
            .filter(|(c, _)| c.truth() == t)
            .flat_map(|(_, v)| v.iter().map(|i| i.1))
            .collect()
    };
    let (sticky, healthy) = (of(Truth::Sticky), of(Truth::NotSticky));
    let _ = writeln!(md, "| goal | value | target | |\n|---|---|---|---|");
    let share = |n: usize, of: usize| n as f64 / of.max(1) as f64;
    let look_alike_target = if suite == Suite::Routine { 0.90 } else { 0.95 };
    if sticky.is_empty() || healthy.is_empty() && suite == Suite::Routine {
        // one side only (--only): no balanced accuracy or sticky share to compute
    } else if suite == Suite::Routine {
        let tpr = share(count(&sticky, Verdict::Stiction), sticky.len());
        let tnr = share(count(&healthy, Verdict::NoStiction), healthy.len());
        let ba = (tpr + tnr) / 2.0;
        goal(
            md,
            "balanced accuracy (sticky called stiction, not-sticky called no_stiction)",
            format!("{ba:.3} ({tpr:.3} / {tnr:.3})"),
            ">= 0.95",
            ba >= 0.95,
        );
    } else {
        let tpr = share(count(&sticky, Verdict::Stiction), sticky.len());
        goal(
            md,
            "sticky loops called stiction",
            format!("{:.1} %", 100.0 * tpr),
            ">= 95 %",
            tpr >= 0.95,
        );
    }
    for (class, items) in groups.iter().filter(|(c, _)| c.truth() == Truth::NotSticky) {
        let ds: Vec<&Diagnosis> = items.iter().map(|i| i.1).collect();
        let not = share(ds.len() - count(&ds, Verdict::Stiction), ds.len());
        goal(
            md,
            &format!("{class}: not called stiction"),
            format!("{:.1} %", 100.0 * not),
            &format!(">= {:.0} %", 100.0 * look_alike_target),
            not >= look_alike_target,
        );
    }
    if suite == Suite::Routine {
        let all: Vec<&Diagnosis> = sticky.iter().chain(&healthy).copied().collect();
        let undecided = share(
            count(&all, Verdict::Undetermined) + count(&all, Verdict::InsufficientData),
            all.len(),
        );
        goal(
            md,
            "undetermined + insufficient_data (backlash left out)",
            format!("{:.1} %", 100.0 * undecided),
            "<= 10 %",
            undecided <= 0.10,
        );
    }
    let _ = writeln!(md);
}

/// Per class, how often each index voted stiction (S) and no stiction (N); index names as the
/// diagnoses report them.
fn vote_table(md: &mut String, groups: &BTreeMap<LoopClass, Vec<(&BenchmarkLoop, &Diagnosis)>>) {
    let mut names: Vec<String> = Vec::new();
    for d in groups.values().flatten().map(|i| i.1) {
        for ix in &d.indices {
            if !names.contains(&ix.name) {
                names.push(ix.name.clone());
            }
        }
    }
    if names.is_empty() {
        return;
    }
    let _ = writeln!(
        md,
        "Index votes per class (share of the class's loops voting S stiction / N no stiction):\n"
    );
    let _ = writeln!(md, "| class | {} |", names.join(" | "));
    let _ = writeln!(md, "|---|{}", "---|".repeat(names.len()));
    for (class, items) in groups {
        let n = items.len();
        let cells: Vec<String> = names
            .iter()
            .map(|name| {
                let votes = |v: Vote| {
                    items
                        .iter()
                        .filter(|i| i.1.indices.iter().any(|x| &x.name == name && x.vote == v))
                        .count()
                };
                format!(
                    "S {} / N {}",
                    pct(votes(Vote::Stiction), n),
                    pct(votes(Vote::NoStiction), n)
                )
            })
            .collect();
        let _ = writeln!(md, "| {class} | {} |", cells.join(" | "));
    }
    let _ = writeln!(md);
}

/// A reason with every number (digits, a decimal point, a sign) shown as one `#`.
fn blank_numbers(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        let starts = c.is_ascii_digit()
            || (c == '-' || c == '.') && chars.peek().is_some_and(|n| n.is_ascii_digit());
        if starts {
            while chars
                .peek()
                .is_some_and(|n| n.is_ascii_digit() || *n == '.' || *n == 'e')
            {
                chars.next();
            }
            out.push('#');
        } else {
            out.push(c);
        }
    }
    out
}

/// The most frequent reasons given per class (numbers blanked so alike reasons group).
fn reason_table(md: &mut String, groups: &BTreeMap<LoopClass, Vec<(&BenchmarkLoop, &Diagnosis)>>) {
    let _ = writeln!(
        md,
        "Most frequent reasons (for verdicts that give one; numbers shown as #):\n"
    );
    let _ = writeln!(md, "| class | reason | loops |\n|---|---|---|");
    for (class, items) in groups {
        let mut counts: BTreeMap<String, usize> = BTreeMap::new();
        for (_, d) in items {
            if let Some(r) = &d.reason {
                let key = blank_numbers(r);
                *counts.entry(key).or_default() += 1;
            }
        }
        let mut top: Vec<(String, usize)> = counts.into_iter().collect();
        top.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(&b.0)));
        for (reason, n) in top.into_iter().take(2) {
            let _ = writeln!(md, "| {class} | {} | {n} |", reason.replace('|', "/"));
        }
    }
    let _ = writeln!(md);
}

/// Sticky loops called stiction, by band size and noise level.
fn sticky_table(md: &mut String, loops: &[BenchmarkLoop], res: &[(Diagnosis, f64)]) {
    let bins = [
        (0.0, 1.0, "0.5-1 %"),
        (1.0, 2.0, "1-2 %"),
        (2.0, 99.0, "2-5 %"),
    ];
    let _ = writeln!(
        md,
        "Sticky loops called stiction, by band (Stenman d, Kano S, He fs) and PV noise:\n"
    );
    let _ = writeln!(
        md,
        "| band | low noise | medium noise | high noise |\n|---|---|---|---|"
    );
    for (lo, hi, label) in bins {
        let cells: Vec<String> = NoiseLevel::ALL
            .iter()
            .map(|&nl| {
                let sel: Vec<&Diagnosis> = loops
                    .iter()
                    .zip(res)
                    .filter(|(l, _)| {
                        let band = l.setup.model.values()[0];
                        l.truth == Truth::Sticky && l.noise_level == nl && band >= lo && band < hi
                    })
                    .map(|(_, r)| &r.0)
                    .collect();
                format!("{} of {}", count(&sel, Verdict::Stiction), sel.len())
            })
            .collect();
        let _ = writeln!(md, "| {label} | {} |", cells.join(" | "));
    }
    let _ = writeln!(md);
}

fn suite_title(suite: Suite) -> &'static str {
    match suite {
        Suite::Routine => "Routine plant historian windows (issue 10)",
        Suite::Fast => "Fast loops that limit-cycle (issue 14)",
    }
}

fn run_suite(o: &Options, suite: Suite, md: &mut String, jsonl: &mut String) {
    let t0 = Instant::now();
    let mut loops = catalogue::catalogue(suite, o.set);
    if let Some(c) = o.only {
        loops.retain(|l| l.class == c);
    }
    let generated = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let res: Vec<(Diagnosis, f64)> = loops.par_iter().map(judge).collect();
    let wall = t1.elapsed().as_secs_f64();
    let cpu: f64 = res.iter().map(|r| r.1).sum();
    let _ = writeln!(md, "## {}\n", suite_title(suite));
    if loops.is_empty() {
        let _ = writeln!(md, "No loop of this class in this suite.\n");
        return;
    }
    let groups = by_class(&loops, &res);
    verdict_table(md, &groups);
    goals(md, suite, &groups);
    if suite == Suite::Fast && o.only.is_none_or(|c| c == LoopClass::StenmanValve) {
        let (d, _) = judge(&catalogue::issue14_example());
        let _ = writeln!(
            md,
            "Issue 14's example (`issue14`, not counted above): {}{}{}.\n",
            d.verdict,
            d.confidence
                .map_or(String::new(), |c| format!(" (confidence {c:.2})")),
            d.reason.map_or(String::new(), |r| format!("; {r}"))
        );
    }
    sticky_table(md, &loops, &res);
    confidence_table::confidence_table(md, &groups);
    if THOROUGH.load(std::sync::atomic::Ordering::Relaxed) {
        levels_table(md, &groups);
    }
    vote_table(md, &groups);
    reason_table(md, &groups);
    let _ = writeln!(
        md,
        "{} loops; generated in {generated:.2} s; diagnosed in {wall:.1} s on {} threads ({:.2} s per loop on average, one run on this machine).\n",
        loops.len(),
        rayon::current_num_threads(),
        cpu / loops.len() as f64
    );
    for (l, (d, secs)) in loops.iter().zip(&res) {
        let line = Line {
            id: &l.id,
            suite: l.suite,
            set: l.set,
            class: l.class,
            truth: l.truth,
            kind: l.kind,
            integrating: l.integrating,
            noise_level: l.noise_level,
            description: &l.description,
            parameters: &l.setup,
            tuning: l.tuning,
            excitation: l.excitation,
            slips: l.slips,
            saturated: l.saturated,
            attempts: l.attempts,
            seconds: *secs,
            diagnosis: d,
        };
        jsonl.push_str(&serde_json::to_string(&line).expect("serialisable"));
        jsonl.push('\n');
    }
}

fn main() {
    let o = options();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(o.threads.unwrap_or(0))
        .build()
        .unwrap_or_else(|e| fail(&format!("cannot start the threads: {e}")));
    let mut md = String::new();
    let mut jsonl = String::new();
    let thorough = THOROUGH.load(std::sync::atomic::Ordering::Relaxed);
    let set = match o.set {
        Set::Benchmark => "benchmark",
        Set::Calibration => "calibration",
    };
    let _ = writeln!(
        md,
        "# Plant benchmark ({set} set)\n\n\
         Generated by `cargo run --release -p stiction-core --example plant_benchmark -- {}--out docs/plant-benchmark{}.md`{}. {}\
         The loops are the catalogue's (`stiction_core::sim::catalogue`; classes, ranges and seeds are documented there), \
         each judged as `stiction diagnose loop.csv --sp sp` judges it (setpoint and time given, `--integrating` for level \
         loops, defaults otherwise). A loop's record is written as CSV by `cargo run -p stiction-core --example plant_loop -- ID FILE`.\n\n\
         Right: a sticky loop called `stiction`, a not-sticky one called `no_stiction`.\n",
        if thorough { "--thorough " } else { "" },
        if thorough { "-thorough" } else { "" },
        if o.set == Set::Calibration { " with `--calibration`" } else { "" },
        if thorough {
            "Every loop is judged with `--thorough`: the model family also runs the levels test (every distinct Stenman \
             valve scored on PV's levels, AR noise model; `stiction_core::identify::levels`). Beside \
             [plant-benchmark.md](plant-benchmark.md), the same loops judged without it. "
        } else {
            ""
        }
    );
    pool.install(|| {
        for &suite in &o.suites {
            run_suite(&o, suite, &mut md, &mut jsonl);
        }
    });
    println!("{md}");
    if let Some(out) = &o.out {
        std::fs::write(out, &md).unwrap_or_else(|e| fail(&format!("{out}: cannot write: {e}")));
        eprintln!("wrote {out}");
    }
    if let Some(path) = &o.jsonl {
        std::fs::write(path, &jsonl)
            .unwrap_or_else(|e| fail(&format!("{path}: cannot write: {e}")));
        eprintln!("wrote {path}");
    }
}
