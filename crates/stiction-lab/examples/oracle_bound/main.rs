//! How well could any detector do? An oracle's likelihood-ratio test on the routine suite
//! (issue 10), a bound on the balanced accuracy of every method that sees the record.
//!
//! The oracle knows, for each loop, everything the simulator used except which valve is in it:
//! the process, the actuator lag, the controller, the noise's standard deviation, the setpoint,
//! the warm-up, the load's model (a load drift's slope variance, a ramp exactly), and, for the
//! sticky hypothesis, the very stiction model and band. It sees OP at every controller execution
//! and PV at every plant step (more than a historian stores). With all that, PV given OP is
//! linear and Gaussian under both hypotheses: the valve position is a known function of OP (the
//! stiction model, or a healthy valve), the load a Gaussian state (an integrated random walk
//! through the process), the noise white. A Kalman filter over the load gives the exact
//! likelihood of the record under each hypothesis; the controller's share of the likelihood is
//! the same under both and cancels. The test "stiction when the likelihood ratio exceeds 1" is
//! the Neyman-Pearson test that minimises missed sticky valves plus false alarms for each sticky
//! loop and its healthy twin, so no method that sees less (OP and PV as recorded, without the
//! process, the noise or the band) can reach a higher balanced accuracy on these pairs, up to the
//! sampling error of a finite set. On the records of 1 s the oracle's OP is the record's own (the
//! controllers run every 1 or 2 s); on those of 10 s it sees the OP between the samples too.
//!
//! Sticky loops: the suite's Stenman, Kano and He valves, each under its own valve. Healthy
//! loops: each sticky loop's twin (the same loop, seed and signals, with a healthy valve),
//! judged against the sticky valve it would have had; and the suite's `healthy` class, judged
//! against a valve drawn from the suite's ranges (a Stenman, Kano or He band log-uniform in
//! 0.5-5 % of span).
//!
//! Three oracles, from the most to the least informed: the load known sample by sample; the
//! load's model known, PV at every plant step; the load's model known, PV at the recorded
//! samples only.
//!
//! `--band-unknown N` adds, for the Stenman loops and their twins, the same oracles without the
//! band: the likelihood of a Stenman valve averaged over N bands log-uniform in the suite's range
//! (0.5-5 % of span), against a healthy valve. With the prior right, that is the best test of all
//! that do not know the band. Beside them, the oracles that know less (the table's text says
//! each): the process identified, profiled or searched under each hypothesis, or a fixed amount
//! wrong; OP too seen only at the recorded samples (held, or a straight line between them).
//! The rows that maximise a band (and the process) under the sticky hypothesis are no calibrated
//! test at ratio 1, so they are also read at every threshold: the area under the ROC curve and
//! the balanced accuracy at the threshold that does best on the pairs themselves (an upper bound
//! for that ratio under any threshold set elsewhere).
//!
//! `--sweep` (with `--band-unknown`) adds, for the same loops, the oracle under processes off
//! the truth by a sweep of amounts (`sweep.rs`): how near the truth an identified process must be.
//!
//! `--particles N` adds, for the Stenman loops of 10 s, the hidden-valve oracle: a particle
//! filter of N particles over the whole loop between the records (`particles.rs`, `hidden.rs`).

mod hidden;
use stiction_lab::oracle::kalman;
mod particles;
use stiction_lab::oracle::profile;
use stiction_lab::study_args;
mod sweep;
mod unknown;
mod unknown_tables;

use kalman::{full_run, llrs, Llr};
use rayon::prelude::*;
use std::fmt::Write as _;
use stiction_core::models::{He, Kano, Model, Stenman};
use stiction_lab::catalogue::{self, BenchmarkLoop, LoopClass, LoopKind, Suite, Truth};
use study_args::StudyArgs;
use unknown::{less_known, Unknown};
use unknown_tables::{by_kind_table, ranking_table, unknown_table};

/// A sticky valve from the suite's ranges, for a healthy loop's sticky hypothesis.
fn drawn_valve(seed: u64) -> Model {
    let mut s = seed;
    let mut u = || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    };
    let band = (0.5f64.ln() + u() * (5.0f64.ln() - 0.5f64.ln())).exp();
    match (u() * 3.0) as usize {
        0 => Model::Stenman(Stenman { d: band }),
        1 => Model::Kano(Kano {
            s: band,
            j: band * (0.2 + 0.7 * u()),
        }),
        _ => Model::He(He {
            fs: band,
            fd: band * (0.1 + 0.6 * u()),
        }),
    }
}

struct Row {
    class: LoopClass,
    kind: LoopKind,
    fine: bool,
    sticky: Llr,
    twin: Llr,
    /// The band-unknown oracle's (Stenman loops, when asked for).
    unknown: Option<Unknown>,
    /// The particle filter's log-likelihood ratios (sticky loop, twin), Stenman loops of 10 s,
    /// and whether the filter under the valve each record has kept track of it.
    /// (With the load's path known, with its model only.)
    hidden: Option<hidden::Hidden>,
    /// The oracle under processes off the truth (Stenman loops, with `--sweep`).
    sweep: Option<Vec<sweep::Step>>,
}

fn judge(l: &BenchmarkLoop, bands: usize, particles: usize, swept: bool) -> Row {
    let run = full_run(&l.setup);
    // the full-rate run is the record's: the same PV at every recorded step
    let same = run
        .recorded
        .iter()
        .zip(&l.data.pv)
        .all(|(&j, pv)| (run.pv[j] - pv).abs() <= 1e-9);
    assert!(same, "{}: the full-rate run differs from the record", l.id);
    let sticky = llrs(&l.setup, &l.setup.model, &run);
    let mut twin_setup = l.setup.clone();
    twin_setup.model = Model::Stenman(Stenman { d: 0.0 });
    let twin_run = full_run(&twin_setup);
    let twin = llrs(&twin_setup, &l.setup.model, &twin_run);
    let unknown = (bands > 0 && l.class == LoopClass::StenmanValve)
        .then(|| less_known(l, &twin_setup, &run, &twin_run, bands));
    let sweep = (swept && l.class == LoopClass::StenmanValve).then(|| {
        sweep::sweep(
            &l.setup,
            &l.setup.model,
            &twin_setup,
            (&run, &twin_run),
            bands,
        )
    });
    let hidden = (particles > 0 && l.class == LoopClass::StenmanValve && l.setup.ts >= 5.0)
        .then(|| hidden::hidden(l, &twin_setup, particles))
        .flatten();
    Row {
        hidden,
        sweep,
        class: l.class,
        kind: l.kind,
        fine: l.setup.ts < 5.0,
        sticky,
        twin,
        unknown,
    }
}

type Pick = fn(&Llr) -> f64;

const ORACLES: [(&str, Pick); 3] = [
    ("load known", |l| l.known_load),
    ("load's model known, PV every plant step", |l| l.every_step),
    ("load's model known, PV at the recorded samples", |l| {
        l.recorded
    }),
];

fn share(v: impl Iterator<Item = bool>) -> (usize, usize) {
    v.fold((0, 0), |(k, n), b| (k + b as usize, n + 1))
}

/// The balanced accuracy of sticky loops called sticky (`hit`) and twins called healthy (`twin`).
fn balanced(hit: (usize, usize), twin: (usize, usize)) -> f64 {
    0.5 * (hit.0 as f64 / hit.1.max(1) as f64 + twin.0 as f64 / twin.1.max(1) as f64)
}

fn pct((k, n): (usize, usize)) -> String {
    format!("{:.1} % ({k} of {n})", 100.0 * k as f64 / n.max(1) as f64)
}

fn table(md: &mut String, rows: &[&Row], healthy: &[Llr]) {
    let _ = writeln!(
        md,
        "| oracle | sticky called stiction | twins called healthy | `healthy` class called healthy | balanced accuracy (sticky, twins) |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|");
    for (name, pick) in ORACLES {
        let hit = share(rows.iter().map(|r| pick(&r.sticky) > 0.0));
        let twin = share(rows.iter().map(|r| pick(&r.twin) <= 0.0));
        let ba = balanced(hit, twin);
        let h = if healthy.is_empty() {
            "-".to_string()
        } else {
            pct(share(healthy.iter().map(|l| pick(l) <= 0.0)))
        };
        let _ = writeln!(
            md,
            "| {name} | {} | {} | {h} | {ba:.3} |",
            pct(hit),
            pct(twin)
        );
    }
}

fn main() {
    let args = StudyArgs::from_env("oracle_bound");
    let set = args.set();
    let loops: Vec<BenchmarkLoop> = (0..catalogue::size(Suite::Routine))
        .into_par_iter()
        .filter_map(|i| catalogue::generate(Suite::Routine, set, i))
        .collect();
    let sticky: Vec<&BenchmarkLoop> = loops.iter().filter(|l| l.truth == Truth::Sticky).collect();
    let bands: usize = args.value("--band-unknown").map_or(0, |v| {
        v.parse()
            .unwrap_or_else(|_| args.fail("--band-unknown needs a number of bands"))
    });
    let particles: usize = args.value("--particles").map_or(0, |v| {
        v.parse()
            .unwrap_or_else(|_| args.fail("--particles needs a number of particles"))
    });
    let swept = args.has("--sweep");
    if swept && bands == 0 {
        args.fail("--sweep needs --band-unknown N (the bands it averages over)");
    }
    let rows: Vec<Row> = sticky
        .par_iter()
        .map(|l| judge(l, bands, particles, swept))
        .collect();
    let healthy: Vec<Llr> = loops
        .par_iter()
        .filter(|l| l.class == LoopClass::Healthy)
        .map(|l| {
            let run = full_run(&l.setup);
            let seed = catalogue::set_seed(Suite::Routine, set) ^ l.setup.seed;
            llrs(&l.setup, &drawn_valve(seed), &run)
        })
        .collect();
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# An oracle's bound on the routine suite ({} set)\n\nGenerated by `cargo run --release -p stiction-lab --example oracle_bound -- {}{}{}{}--out FILE`. \
         The likelihood-ratio test of an oracle that knows each loop's process, actuator lag, controller, noise, setpoint, load model and, \
         for the sticky hypothesis, the very valve; it sees OP at every controller execution (on the records of 1 s, the record's own OP). For each sticky loop and its healthy twin \
         no test has a smaller sum of the two errors, so no method that sees less can have a higher balanced accuracy on these loops \
         (up to the sampling error of a finite set); what it does not bound is the look-alikes, which are not twins. Sticky loops: the suite's Stenman, Kano and He \
         valves. Twins: each sticky loop with a healthy valve (same process, seeds and signals), judged against the sticky valve it would \
         have had. `healthy` class: judged against a valve drawn from the suite's ranges. See the example's documentation.\n",
        if set == catalogue::Set::Benchmark { "benchmark" } else { "calibration" },
        if set == catalogue::Set::Benchmark { "--benchmark " } else { "" },
        if bands > 0 { format!("--band-unknown {bands} ") } else { String::new() },
        if swept { "--sweep " } else { "" },
        if particles > 0 { format!("--particles {particles} ") } else { String::new() },
    );
    let all: Vec<&Row> = rows.iter().collect();
    let _ = writeln!(md, "## All {} sticky loops\n", all.len());
    table(&mut md, &all, &healthy);
    for (fine, words) in [
        (true, "2,000 samples every 1 s"),
        (false, "750 samples every 10 s"),
    ] {
        let part: Vec<&Row> = rows.iter().filter(|r| r.fine == fine).collect();
        let _ = writeln!(
            md,
            "\n## Records of {words} ({} sticky loops)\n",
            part.len()
        );
        table(&mut md, &part, &[]);
    }
    let _ = writeln!(
        md,
        "\n## By valve model (load's model known, PV at the recorded samples)\n"
    );
    let _ = writeln!(
        md,
        "| valve | sticky called stiction | twins called healthy |"
    );
    let _ = writeln!(md, "|---|---|---|");
    for class in [
        LoopClass::StenmanValve,
        LoopClass::KanoValve,
        LoopClass::HeValve,
    ] {
        let part: Vec<&Row> = rows.iter().filter(|r| r.class == class).collect();
        let _ = writeln!(
            md,
            "| {class} | {} | {} |",
            pct(share(part.iter().map(|r| r.sticky.recorded > 0.0))),
            pct(share(part.iter().map(|r| r.twin.recorded <= 0.0)))
        );
    }
    if bands > 0 {
        unknown_table(&mut md, &rows, bands);
        ranking_table(&mut md, &rows);
        by_kind_table(&mut md, &rows);
        if swept {
            sweep::sweep_table(&mut md, &rows, bands);
        }
    }
    if particles > 0 {
        hidden::hidden_table(&mut md, &rows, particles);
    }
    args.emit(&md);
}
