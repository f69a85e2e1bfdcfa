//! The verdict's model: train it, and judge it on real records first, simulated ones second.
//!
//!     cargo run --release -p stiction-lab --example verdict -- [--extra N] [--real-weight W]
//!         [--ridge R] [--plain-share S] [--read STATISTIC,...] [--without STATISTIC,...]
//!         [--samples FILE] [--no-write]
//!         [--out FILE]
//!
//! Every record is diagnosed as `stiction diagnose` would (real: plant-dev's 20 windows and the
//! ISDB's 14 OP+PV loops under `../shared/data`; simulated: the catalogue's calibration sets of the
//! routine, fast and plant-window suites, and `--extra N` further draws of each), and reduced to
//! the statistics the model reads. The model is fitted to the simulated records (sticky valves
//! whose slips PV shows, visibility >= 3 noise standard deviations) together with the real ones,
//! each real record weighing `--real-weight` simulated ones (within balanced halves). Then:
//! - the real records out of fold: each real loop (a plant tag's windows together) predicted by the
//!   model fitted without it; the verdicts, their balanced accuracy, the probability's reliability;
//! - the catalogue's benchmark sets (never trained on) under the model fitted to everything;
//! - each statistic's separation on real and simulated records.
//!
//! It writes the model to `crates/stiction-core/src/diagnose/verdict/model.json` (unless
//! `--no-write`) and the tables to `--out` (default `crates/stiction-lab/results/verdict.md`).
//! `--samples FILE` keeps the diagnosed records between runs (read when the file exists). Without
//! `../shared` it trains on the simulated records alone and says so.

mod fit;
mod samples;
mod tables;

use fit::Plan;
use samples::Sample;
use std::fmt::Write as _;
use std::path::Path;
use stiction_core::diagnose::{Statistic, Training};
use stiction_lab::catalogue::{Set, Suite};
use stiction_lab::study_args::StudyArgs;

const MODEL: &str = "crates/stiction-core/src/diagnose/verdict/model.json";
const OUT: &str = "crates/stiction-lab/results/verdict.md";
const SHARED: &str = "../shared";

/// The statistics the model reads: the few that separate sticky valves from healthy ones on the
/// real records first (each one's effect is in the ablation table). The sticks' count grows with
/// the record's length (their share is read instead). The fit's test ratio separates the
/// simulated records better than its gain, and the real ones worse (a healthy loop's large
/// setpoint step makes a small model mismatch significant): its gain is read. The loop's lag
/// finds simulated limit cycles a linear loop cannot sustain but calls a real healthy level loop
/// sticky; the fit's band adds nothing.
const READ: [Statistic; 4] = [
    Statistic::StickShare,
    Statistic::Stuck,
    Statistic::FitGain,
    Statistic::CycleShape,
];

/// Every sample: real (if present), the calibration and extra draws, the benchmark sets.
fn collect(extra: u8) -> (Vec<Sample>, Vec<Sample>, bool) {
    let suites = [Suite::Routine, Suite::Fast, Suite::Plant];
    let mut train = Vec::new();
    let real = samples::real(Path::new(SHARED));
    let have_real = real.is_some();
    train.extend(real.unwrap_or_default());
    for s in suites {
        train.extend(samples::simulated(s, Set::Calibration));
        for n in 1..=extra {
            train.extend(samples::simulated(s, Set::Extra(n)));
        }
    }
    let bench = suites
        .iter()
        .flat_map(|&s| samples::simulated(s, Set::Benchmark))
        .collect();
    (train, bench, have_real)
}

fn main() {
    let args = StudyArgs::from_env("verdict");
    let num = |flag: &str, default: f64| args.number(flag, default);
    let extra = num("--extra", 2.0) as u8;
    let plan = Plan {
        statistics: args
            .value("--read")
            .map_or(READ.to_vec(), |list| {
                Statistic::ALL
                    .into_iter()
                    .filter(|s| list.split(',').any(|n| n == format!("{s:?}")))
                    .collect()
            })
            .into_iter()
            .filter(|s| {
                !args
                    .value("--without")
                    .is_some_and(|w| w.split(',').any(|n| n == format!("{s:?}")))
            })
            .collect(),
        real_weight: num("--real-weight", 10.0),
        ridge: num("--ridge", 1.0),
        min_visibility: 3.0,
        plain_share: num("--plain-share", 0.7),
        stiction_from: num("--stiction-from", 0.6),
        no_stiction_below: num("--no-stiction-below", 0.4),
    };
    let cache = args.value("--samples");
    let (train, bench, have_real) = match cache.and_then(|c| std::fs::read_to_string(c).ok()) {
        Some(text) => serde_json::from_str(&text).expect("a samples file this program wrote"),
        None => {
            let got = collect(extra);
            if let Some(c) = cache {
                std::fs::write(c, serde_json::to_string(&got).expect("serialisable"))
                    .unwrap_or_else(|e| args.fail(&format!("{c}: {e}")));
            }
            got
        }
    };
    if !have_real {
        eprintln!(
            "verdict: no real records under {SHARED}/data: training on the simulated records alone"
        );
    }
    let md = report(&plan, &train, &bench, extra);
    if !args.has("--no-write") {
        let refs: Vec<&Sample> = train.iter().collect();
        let model = fit::fit(&plan, &refs, training(&plan, &train, extra, &md));
        let json = serde_json::to_string_pretty(&model).expect("serialisable") + "\n";
        std::fs::write(MODEL, json).unwrap_or_else(|e| args.fail(&format!("{MODEL}: {e}")));
        eprintln!("verdict: wrote {MODEL}");
    }
    match args.value("--out") {
        Some(_) => args.emit(&md),
        None => {
            std::fs::write(OUT, &md).unwrap_or_else(|e| args.fail(&format!("{OUT}: {e}")));
            eprintln!("verdict: wrote {OUT}");
        }
    }
}

/// How the written model was trained, in the file.
fn training(plan: &Plan, train: &[Sample], extra: u8, md: &str) -> Training {
    let real = train.iter().filter(|s| s.source.real()).count();
    let trained = train.iter().filter(|s| fit::trains(plan, s)).count();
    let checked = md
        .lines()
        .find(|l| l.starts_with("| all |"))
        .map_or("no real records".into(), |l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            format!(
                "the {} real records out of fold (leave one loop out): balanced accuracy {} (sensitivity {}, specificity {}); the tables: crates/stiction-lab/results/verdict.md",
                cells[2],
                cells[7].trim_matches('*'),
                cells[5],
                cells[6]
            )
        });
    Training {
        command: format!(
            "cargo run --release -p stiction-lab --example verdict -- --extra {extra} --real-weight {} --ridge {}",
            plan.real_weight, plan.ridge
        ),
        records: format!(
            "{trained} records: the catalogue's calibration sets and {extra} further draws of the routine, fast and plant-window suites (sticky valves whose slips move PV by at least {} noise standard deviations), and {real} real records (plant-dev's windows, the ISDB's OP+PV loops)",
            plan.min_visibility
        ),
        real_weight: plan.real_weight,
        ridge: plan.ridge,
        checked,
    }
}

/// The tables.
fn report(plan: &Plan, train: &[Sample], bench: &[Sample], extra: u8) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# The verdict's model on real and simulated records\n\nGenerated by `cargo run --release -p stiction-lab --example verdict -- --extra {extra} --real-weight {} --ridge {}`: \
         the model is fitted to the catalogue's calibration draws and the real records; real records are judged out of fold, each real loop (all windows of a plant tag together) \
         predicted by the model fitted without it; the benchmark sets were never trained on. Thresholds: `stiction` from P {:.2}, `no_stiction` under {:.2}. \
         Real data: the plant windows of Xue et al.'s StictionGPT study (Apache 2.0) and the ISDB (Jelali and Huang 2010).\n",
        plan.real_weight, plan.ridge, plan.stiction_from, plan.no_stiction_below
    );
    let oof = fit::leave_one_loop_out(plan, train);
    let real: Vec<(&Sample, Option<f64>)> = oof
        .iter()
        .filter(|(i, _)| train[*i].source.real())
        .map(|(i, p)| (&train[*i], *p))
        .collect();
    let refs: Vec<&Sample> = train.iter().collect();
    let model = fit::fit(plan, &refs, fit::placeholder());
    if !real.is_empty() {
        let _ = writeln!(md, "## Real records, out of fold\n");
        tables::real_table(&mut md, &model, &real);
        let _ = writeln!(
            md,
            "How far the probability means what it says (real records, out of fold):\n"
        );
        tables::reliability(&mut md, &real);
    }
    let _ = writeln!(md, "## The catalogue's benchmark sets (never trained on)\n");
    let sims: Vec<(&Sample, f64)> = bench
        .iter()
        .map(|s| (s, fit::probability(&model, s)))
        .collect();
    tables::simulated_table(&mut md, &model, &sims);
    let _ = writeln!(
        md,
        "## Each statistic on real and simulated records\n\nArea under the ROC curve, sticky against healthy (medians sticky / healthy in brackets); simulated sticky valves whose slips PV does not show (visibility under 3) left out.\n"
    );
    let all: Vec<Sample> = train.iter().chain(bench).cloned().collect();
    tables::separation(&mut md, &all);
    ablation(&mut md, plan, train, bench);
    let _ = writeln!(md, "## The model fitted to every training record\n");
    for i in &model.inputs {
        let _ = writeln!(
            md,
            "- {:?}: reference {:.3}, range {:.3} to {:.3}; hinges at {} with weights {}",
            i.statistic,
            i.reference,
            i.range[0],
            i.range[1],
            i.knots
                .iter()
                .map(|k| format!("{k:.3}"))
                .collect::<Vec<_>>()
                .join(", "),
            i.weights
                .iter()
                .map(|w| format!("{w:.3}"))
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    let _ = writeln!(
        md,
        "- intercept (log-odds at the references): {:.3}",
        model.intercept
    );
    md
}

/// Balanced accuracy on the real records out of fold and on the benchmark sets, under `plan`.
fn scores(plan: &Plan, train: &[Sample], bench: &[Sample]) -> (f64, Vec<f64>) {
    let oof = fit::leave_one_loop_out(plan, train);
    let refs: Vec<&Sample> = train.iter().collect();
    let m = fit::fit(plan, &refs, fit::placeholder());
    let real: Vec<(bool, stiction_core::diagnose::Verdict)> = oof
        .iter()
        .filter(|(i, _)| train[*i].source.real())
        .map(|(i, p)| (train[*i].sticky, tables::verdict(&m, *p)))
        .collect();
    let sims = [
        samples::Source::Routine,
        samples::Source::Fast,
        samples::Source::PlantSim,
    ]
    .iter()
    .map(|src| {
        let pairs: Vec<_> = bench
            .iter()
            .filter(|s| s.source == *src)
            .map(|s| {
                let p = s.judged.then(|| fit::probability(&m, s));
                (s.sticky, tables::verdict(&m, p))
            })
            .collect();
        tables::accuracy(&pairs).2
    })
    .collect();
    (tables::accuracy(&real).2, sims)
}

/// Each statistic's effect: the balanced accuracies without each one the model reads, and with
/// each one it does not read added.
fn ablation(md: &mut String, plan: &Plan, train: &[Sample], bench: &[Sample]) {
    let _ = writeln!(
        md,
        "## Each statistic's effect\n\nBalanced accuracy, real records out of fold and the benchmark sets, with the model refitted without (or with) one statistic:\n\n| model | real, out of fold | routine | fast | plant windows |\n|---|---|---|---|---|"
    );
    let row = |md: &mut String, label: String, p: &Plan| {
        let (real, sims) = scores(p, train, bench);
        let _ = writeln!(
            md,
            "| {label} | {real:.3} | {:.3} | {:.3} | {:.3} |",
            sims[0], sims[1], sims[2]
        );
    };
    row(md, "as trained".into(), plan);
    for s in &plan.statistics {
        let mut p = plan.clone();
        p.statistics.retain(|t| t != s);
        row(md, format!("without {s:?}"), &p);
    }
    for s in Statistic::ALL
        .iter()
        .filter(|s| !plan.statistics.contains(s))
    {
        let mut p = plan.clone();
        p.statistics.push(*s);
        row(md, format!("with {s:?}"), &p);
    }
    let _ = writeln!(md);
}
