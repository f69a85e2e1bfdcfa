//! How often `diagnose` is right: the 14 ISDB loops with OP and PV (skipped when the data are
//! absent) and a grid of simulated loops (sticky valve; healthy valve with aggressive tuning; with
//! an external sinusoidal disturbance; noise only), several processes, noise levels and seeds.
//!
//!     cargo run --release -p stiction-lab --example diagnose_benchmark -- \
//!         [--isdb ../shared/data/isdb] [--out crates/stiction-lab/results/diagnose-benchmark.md] [--no-quantify] [--thorough] [--verbose]
//!
//! The verdict is the calibrated model's (`stiction_core::diagnose::VerdictModel`): P is its
//! probability of a sticky valve; a family's vote is its statistics' share of the log-odds.
//! `--verbose` prints each row's reasons (the typed findings) to standard error.
//!
//! As `stiction diagnose` does by default, a stiction verdict is checked by the closed-loop
//! estimate (`--no-quantify` skips it, as the CLI flag of that name does).
//!
//! The thresholds are the library defaults (the papers' conventions): nothing is tuned per loop.
//! ISDB: International Stiction Data Base, Jelali and Huang (eds.), Detection and Diagnosis of
//! Stiction in Control Loops, Springer 2010; not part of this repository.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;
use stiction_core::diagnose::{
    diagnose, DiagnoseRequest, Diagnosis, Family, LoopRecord, Verdict, Vote, VOTE,
};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, Pi, Process, Signal};

use isdb::{column, read_csv};
use stiction_lab::isdb;

const LOOPS: [(&str, bool); 14] = [
    ("CHEM1", true),
    ("CHEM2", true),
    ("CHEM10", true),
    ("CHEM11", true),
    ("CHEM12", true),
    ("CHEM13", false),
    ("CHEM23", true),
    ("CHEM24", true),
    ("CHEM29", true),
    ("PAP2", true),
    ("PAP4", false),
    ("PAP5", true),
    ("PAP7", false),
    ("PAP9", false),
];

fn vote_letter(v: Vote) -> &'static str {
    match v {
        Vote::Stiction => "S",
        Vote::NoStiction => "N",
        Vote::Undetermined => "?",
    }
}

/// A family's value and vote, e.g. "0.31 S".
fn family_cell(d: &Diagnosis, family: Family) -> String {
    d.families
        .iter()
        .find(|f| f.family == family)
        .map_or("-".into(), |f| {
            format!(
                "{} {}",
                f.value.map_or("-".into(), |x| format!("{x:.2}")),
                vote_letter(f.vote)
            )
        })
}

/// The shape indices in one cell: short name, value, vote.
fn indices_cell(d: &Diagnosis) -> String {
    let short = |n: &str| match n {
        "cross_correlation" => "cc",
        "ddpv_histogram" => "dd",
        "bicoherence" => "bic",
        "curve_fitting" => "cf",
        "harmonics" => "h",
        "shape" => "sh",
        _ => "?",
    };
    let cells: Vec<String> = d
        .indices
        .iter()
        .map(|i| {
            format!(
                "{} {}{}",
                short(&i.name),
                i.value.map_or("-".into(), |x| format!("{x:.2}")),
                vote_letter(i.vote)
            )
        })
        .collect();
    if cells.is_empty() {
        "-".into()
    } else {
        cells.join(", ")
    }
}

const FAMILY_COLUMNS: [(Family, &str); 4] = [
    (Family::Model, "model"),
    (Family::StickSlip, "stick-slip"),
    (Family::Shape, "shape"),
    (Family::Loop, "loop"),
];

/// The verdict's reasons as their typed findings, for `--verbose`.
fn findings(d: &Diagnosis) -> String {
    let f: Vec<String> = d
        .reasons
        .iter()
        .map(|r| format!("{:?}", r.finding))
        .collect();
    f.join("; ")
}

fn right(truth: bool, v: Verdict) -> bool {
    if truth {
        v == Verdict::Stiction
    } else {
        v == Verdict::NoStiction
    }
}

/// Confusion counts: rows truth (stiction, not), columns verdict.
#[derive(Default)]
struct Confusion {
    counts: [[usize; 4]; 2],
}

impl Confusion {
    fn add(&mut self, truth: bool, v: Verdict) {
        let c = match v {
            Verdict::Stiction => 0,
            Verdict::NoStiction => 1,
            Verdict::Undetermined => 2,
            Verdict::InsufficientData => 3,
        };
        self.counts[usize::from(!truth)][c] += 1;
    }
    fn table(&self, md: &mut String) {
        let _ = writeln!(
            md,
            "| truth \\ verdict | stiction | no_stiction | undetermined | insufficient_data |"
        );
        let _ = writeln!(md, "|---|---|---|---|---|");
        for (i, name) in ["stiction", "not stiction"].iter().enumerate() {
            let c = self.counts[i];
            let _ = writeln!(md, "| {name} | {} | {} | {} | {} |", c[0], c[1], c[2], c[3]);
        }
        let right = self.counts[0][0] + self.counts[1][1];
        let total: usize = self.counts.iter().flatten().sum();
        let _ = writeln!(
            md,
            "\nRight: {right} of {total} ({:.0} %).\n",
            100.0 * right as f64 / total.max(1) as f64
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |flag: &str| {
        args.iter()
            .position(|a| a == flag)
            .map(|i| args[i + 1].clone())
    };
    let verbose = args.iter().any(|a| a == "--verbose");
    let with_quantify = !args.iter().any(|a| a == "--no-quantify");
    // the hidden-valve family besides (`diagnose --thorough`; it reports, the verdict does not read it)
    let thorough = args.iter().any(|a| a == "--thorough");
    let isdb = PathBuf::from(arg("--isdb").unwrap_or_else(|| "../shared/data/isdb".into()));
    // one JSON line per loop: set, loop, truth and the whole diagnosis (for offline analysis)
    let mut jsonl = String::new();
    let mut record = |set: &str, name: &str, truth: bool, d: &Diagnosis| {
        jsonl.push_str(
            &serde_json::json!({"set": set, "loop": name, "truth": truth, "diagnosis": d})
                .to_string(),
        );
        jsonl.push('\n');
    };
    let mut md = String::new();
    let _ = writeln!(md, "# Diagnose benchmark\n");
    let _ = writeln!(
        md,
        "Generated by `cargo run --release -p stiction-lab --example diagnose_benchmark -- --out crates/stiction-lab/results/diagnose-benchmark.md`. \
         Every loop is judged with the library defaults, as `stiction diagnose` judges it (the calibrated verdict's model, and a \
         stiction verdict's band from the closed-loop estimate{}); nothing is tuned per loop. P: the model's probability of a \
         sticky valve. Family cells: the family's value and vote (its statistics' share of the model's log-odds: S towards a \
         sticky valve by at least {VOTE}, N short of it, ? not measured): model, the improvement of the \
         closed-loop fit with stiction over the linear loop (share of the PV's variance above its noise); stick-slip, the \
         share of PV's steps that end a stick; shape, the indices' weighted score (-1 sinusoidal to 1 a sticky valve's) on an oscillating stretch; loop, the lag (degrees) \
         a valve must add for the identified linear loop to sustain the cycle. Indices: cc cross-correlation, dd \
         second-difference histogram, bic bicoherence (shown, not counted), cf curve fitting, h harmonics (votes N only), sh \
         shape (votes S only).\n",
        if with_quantify { "" } else { " — not in this run: `--no-quantify`" }
    );

    // ISDB
    if isdb.join("op_pv").is_dir() {
        let (lh, lrows) = read_csv(&isdb.join("isdb_labels.csv")).expect("labels");
        let labels: HashMap<String, Vec<String>> =
            lrows.into_iter().map(|r| (r[0].clone(), r)).collect();
        let idx = |name: &str| lh.iter().position(|h| h == name).expect("label column");
        let _ = writeln!(
            md,
            "## ISDB loops with OP and PV\n\nData: International Stiction Data Base, M. Jelali and B. Huang (eds.), \
             *Detection and Diagnosis of Stiction in Control Loops*, Springer 2010 (not in this repository; read from `{}`). \
             Sampling time and process type from the metadata; no setpoint in these files.\n",
            isdb.display()
        );
        let _ = writeln!(
            md,
            "| loop | label | period (s) | {} | indices | verdict | P | band (% of span) | right |",
            FAMILY_COLUMNS.map(|c| c.1).join(" | ")
        );
        let _ = writeln!(
            md,
            "|---|---|---|{}---|---|---|---|---|",
            "---|".repeat(FAMILY_COLUMNS.len())
        );
        let mut conf = Confusion::default();
        for (name, truth) in LOOPS {
            let Some((h, rows)) = read_csv(&isdb.join("op_pv").join(format!("{name}.csv"))) else {
                let _ = writeln!(md, "| {name} | missing file |");
                continue;
            };
            let op = column(&h, &rows, "OP");
            let pv = column(&h, &rows, "PV");
            let label = &labels[name];
            let req = DiagnoseRequest {
                ts: label[idx("Ts")].parse().unwrap_or(1.0),
                integrating: (label[idx("integrating")] == "True").then_some(true),
                quantify: with_quantify,
                thorough,
                ..DiagnoseRequest::default()
            };
            let rec = LoopRecord {
                op: &op,
                pv: &pv,
                sp: None,
                mv: None,
                time: None,
                auto: None,
            };
            let d = diagnose(&rec, &req).expect("valid request");
            record("isdb", name, truth, &d);
            conf.add(truth, d.verdict);
            let osc = d.oscillation.as_ref();
            let row = format!(
                "| {name} | {} | {} | {} | {} | {} | {} | {} | {} |",
                if truth { "stiction" } else { "not" },
                osc.filter(|o| o.oscillating)
                    .and_then(|o| o.period)
                    .map_or("-".into(), |p| format!("{p:.0}")),
                FAMILY_COLUMNS.map(|c| family_cell(&d, c.0)).join(" | "),
                indices_cell(&d),
                d.verdict,
                d.probability.map_or("-".into(), |p| format!("{p:.2}")),
                d.band.as_ref().map_or("-".into(), |b| format!(
                    "{:.2} ({:?})",
                    b.band_percent_of_span, b.source
                )),
                if right(truth, d.verdict) { "yes" } else { "no" },
            );
            if verbose {
                eprintln!("{row}\n   {}", findings(&d));
            }
            let _ = writeln!(md, "{row}");
        }
        let _ = writeln!(md);
        conf.table(&mut md);
    } else {
        let msg = format!(
            "ISDB part skipped: no data at {} (pass --isdb DIR)",
            isdb.display()
        );
        eprintln!("{msg}");
        let _ = writeln!(md, "{msg}\n");
    }

    // simulated loops
    let processes = [
        (
            "FOPTD K=3 tau=10 s delay=10 s",
            Process::Foptd {
                k: 3.0,
                tau: 10.0,
                delay: 10.0,
            },
            Pi { kc: 0.2, ti: 10.0 },
            Pi { kc: 0.4, ti: 12.0 },
        ),
        (
            "FOPTD K=1 tau=30 s delay=5 s",
            Process::Foptd {
                k: 1.0,
                tau: 30.0,
                delay: 5.0,
            },
            Pi { kc: 1.0, ti: 30.0 },
            Pi { kc: 6.0, ti: 12.0 },
        ),
        (
            "FOPTD K=2 tau=5 s delay=2 s",
            Process::Foptd {
                k: 2.0,
                tau: 5.0,
                delay: 2.0,
            },
            Pi { kc: 0.4, ti: 5.0 },
            Pi { kc: 1.2, ti: 4.0 },
        ),
    ];
    let families = [
        "sticky valve",
        "aggressive tuning",
        "external disturbance",
        "noise only",
    ];
    let noises = [0.02, 0.1, 0.3];
    let seeds = [1u64, 2, 3];
    let _ = writeln!(
        md,
        "## Simulated loops\n\n`stiction simulate --loop closed` loops of 2,000 samples, Ts = 1 s, with the setpoint column \
         (a step of 1 at 10 s, left out by the analysed-stretch rule). Sticky valve: Stenman d = 1, 2 or 4 % (by seed) with \
         the normal tuning; aggressive tuning: healthy valve, PI near the stability limit; external disturbance: healthy valve, \
         a sine of amplitude 1 and period 150 s added to the PV; noise only: healthy valve, normal tuning. PV noise standard \
         deviations {noises:?}, seeds {seeds:?}, processes: {}.\n",
        processes.map(|p| p.0).join("; ")
    );
    let _ = writeln!(
        md,
        "| family | process | noise | oscillating | right | verdicts |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|");
    let mut conf = Confusion::default();
    let mut secs = 0.0;
    for family in families {
        for (pname, process, normal, aggressive) in processes {
            for noise in noises {
                let mut verdicts = Vec::new();
                let mut ok = 0;
                let mut oscillating = 0;
                for seed in seeds {
                    let d = [1.0, 2.0, 4.0][(seed as usize - 1) % 3];
                    let sticky = family == "sticky valve";
                    let mut cl = ClosedLoop::new(Model::Stenman(Stenman {
                        d: if sticky { d } else { 0.0 },
                    }));
                    cl.process = process;
                    cl.pi = if family == "aggressive tuning" {
                        aggressive
                    } else {
                        normal
                    };
                    cl.samples = 2000;
                    cl.noise = noise;
                    cl.seed = seed;
                    if family == "external disturbance" {
                        cl.disturbance = Some(Signal::Sine {
                            amplitude: 1.0,
                            period: 150.0,
                            offset: 0.0,
                        });
                    }
                    let data = cl.run().expect("valid loop");
                    let rec = LoopRecord {
                        op: &data.op,
                        pv: &data.pv,
                        sp: Some(&data.sp),
                        mv: None,
                        time: Some(&data.t),
                        auto: None,
                    };
                    let req = DiagnoseRequest {
                        ts: 1.0,
                        quantify: with_quantify,
                        thorough,
                        ..DiagnoseRequest::default()
                    };
                    let t = Instant::now();
                    let dg = diagnose(&rec, &req).expect("valid request");
                    secs += t.elapsed().as_secs_f64();
                    record(
                        "oscillating",
                        &format!("{family} | {pname} | {noise} | {seed}"),
                        sticky,
                        &dg,
                    );
                    conf.add(sticky, dg.verdict);
                    if dg.oscillation.as_ref().is_some_and(|o| o.oscillating) {
                        oscillating += 1;
                    }
                    if right(sticky, dg.verdict) {
                        ok += 1;
                    }
                    if verbose && !right(sticky, dg.verdict) {
                        eprintln!(
                            "{family} | {pname} | {noise} | seed {seed}: {} (P {}) | {}\n   {}",
                            dg.verdict,
                            dg.probability.map_or("-".into(), |p| format!("{p:.2}")),
                            FAMILY_COLUMNS.map(|c| family_cell(&dg, c.0)).join(" | "),
                            findings(&dg)
                        );
                    }
                    verdicts.push(dg.verdict.to_string());
                }
                let _ = writeln!(
                    md,
                    "| {family} | {pname} | {noise} | {oscillating}/{n} | {ok}/{n} | {} |",
                    verdicts.join(", "),
                    n = seeds.len()
                );
            }
        }
    }
    let _ = writeln!(md);
    conf.table(&mut md);
    let _ = writeln!(
        md,
        "Time for all simulated diagnoses: {secs:.2} s (this machine, one run).\n"
    );
    let _ = writeln!(
        md,
        "## What the misses are, and what was tried\n\n\
         Written for the rule-based verdict before issue 69's calibrated model, kept for the record (the tables above are \
         today's).\n\n\
         - **CHEM11** (stiction, called `no_stiction`): OP and PV are sinusoids (harmonics below 1 % of the fundamental in both, \
         curve fitting 0.31), with PV 57 degrees behind OP (cross-correlation 0.63, just under its 2/3). By shape and phase it is a \
         linear oscillation; its stiction shows only as short PV plateaus within noise. No index here sees them.\n\
         - **CHEM2, CHEM29** (stiction, `undetermined`): CHEM2's PV follows OP nearly in phase between stuck stretches \
         (cross-correlation votes no, curve fitting and shape yes); CHEM29 (60 s samples) has a broadband spectrum and no index decides.\n\
         - **Simulated**: three sticky loops on the slow process (K=1, tau=30 s) do not show an oscillation above the noise \
         (one does not cycle within 2,000 samples; two at noise 0.3 cycle irregularly or below three noise standard deviations).\n\
         - Tried, measured on both sets, not kept: bicoherence as a voter (its NGI is about 0 or negative on the ISDB stiction loops); \
         \"two indices must clear a loop\"; detecting oscillations by regularity and an amplitude of 2 noise standard deviations \
         (finds the noisy disturbance loops, which the indices then cannot tell from stiction: 100 of 108); a harmonic noise \
         floor from the gaps beside each harmonic (calls PAP5 and CHEM2 sinusoidal); a sine-vs-trapezoid fit of PV half cycles, \
         a stuck-PV-while-OP-moves fraction and the cross-correlation of OP and PV changes (none separates the ISDB classes).\n\
         - Tried, measured, not kept (for issue 14's example, which stays `no_stiction`): on a regular limit cycle in which OP, at \
         its median speed, crosses more than 1 % of span within the samples a stick needs (the fitted dead time and two), the \
         stick-slip and shape families withheld their votes against stiction. Issue 14's example became `undetermined`, but the \
         ISDB fell from 11 to 9 of 14 (CHEM13 and PAP4 undetermined) and this set from 98 to 90 of 108 (aggressive tuning and \
         disturbances undetermined).\n"
    );
    if let Some(path) = arg("--jsonl") {
        std::fs::write(&path, &jsonl).expect("write the JSON lines");
        eprintln!("wrote {path}");
    }
    println!("{md}");
    if let Some(out) = arg("--out") {
        std::fs::write(&out, md).expect("write the table");
        eprintln!("wrote {out}");
    }
}
