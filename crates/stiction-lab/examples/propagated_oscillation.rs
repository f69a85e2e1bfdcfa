//! A plant-wide oscillation: healthy loops disturbed by another loop's sticky valve. The
//! catalogue's external-oscillation look-alikes (routine and fast, benchmark and calibration
//! sets) are a sine or narrow-band noise; the oscillation most often met in plants is another
//! loop's stiction limit cycle, propagated through the process: not sinusoidal (the upstream
//! valve's jumps, filtered by its process), steady in amplitude, free in phase. Here each
//! external-oscillation loop is simulated again with its oscillation replaced by such a cycle of
//! the same period, standard deviation and place (load or PV): an upstream PI loop with a
//! Stenman valve (band 1-5 %, first-order process with dead time, PV noise 0.03-0.3 %, drawn from
//! the loop's seed until its own cycle is regular: Thornhill's r at least 5 once settled) is
//! simulated, and its PV's deviation, stretched in time to the loop's period, is the oscillation.
//! Every other part of each loop is the same; each is judged as `stiction diagnose loop.csv --sp
//! sp` judges it. Outside the benchmark's goals.
//!
//!     cargo run --release -p stiction-lab --example propagated_oscillation -- [--out crates/stiction-lab/results/propagated-oscillation.md] [--jsonl FILE] [--extra 10,11,...]
//!
//! `--extra`: the catalogue's further draws instead of its calibration and benchmark sets (the
//! loops `stiction-lab/scripts/train_combined.py` trains on; the document's tables then name them "extra").
//!
//! Two sections: the cycle where the loop's own oscillation was (load or PV), judged with the setpoint,
//! and the cycle in the setpoint of a cascade's inner loop, judged without it.

use stiction_lab::catalogue_loop;
use stiction_lab::study_args;
use stiction_lab::tally;
use study_args::StudyArgs;
use tally::Tally;

use rand::RngExt;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use stiction_core::diagnose::{diagnose, Diagnosis, Verdict, Vote};
use stiction_core::models::{Model, Stenman};
use stiction_core::rng::seeded;
use stiction_core::sim::{ClosedLoop, Pi, Process, Signal};
use stiction_lab::catalogue::{catalogue, BenchmarkLoop, LoopClass, Set, Suite};

/// The oscillation in a signal: a sine or narrow-band part, alone or in a sum.
fn oscillation_of(s: &Signal) -> Option<(f64, f64)> {
    match s {
        Signal::Sine {
            amplitude, period, ..
        }
        | Signal::NarrowBand {
            amplitude, period, ..
        } => Some((*amplitude, *period)),
        Signal::Sum { parts } => parts.iter().find_map(oscillation_of),
        _ => None,
    }
}

/// `s` with its oscillation replaced by `by`.
fn replaced(s: &Signal, by: &Signal) -> Signal {
    match s {
        Signal::Sine { .. } | Signal::NarrowBand { .. } => by.clone(),
        Signal::Sum { parts } => Signal::Sum {
            parts: parts.iter().map(|p| replaced(p, by)).collect(),
        },
        other => other.clone(),
    }
}

/// An upstream loop is kept when its own cycle has at least this regularity (Thornhill's r: a
/// limit cycle, not noise the loop merely colours) ...
const UPSTREAM_REGULARITY: f64 = 5.0;
/// ... in at most this many draws.
const UPSTREAM_TRIES: usize = 64;

/// The upstream loop's samples (1 s) left out before its cycle is measured and used: a sticky loop
/// started at rest takes a while to settle into its cycle.
const UPSTREAM_SETTLE: usize = 3000;

/// What the upstream loop was, in words for the table's key.
struct Upstream {
    band: f64,
    tau: f64,
    delay: f64,
}

/// An upstream sticky loop's PV deviation with the standard deviation of a sine of `amplitude`,
/// stretched to `period` seconds and long enough for `seconds`; `None` when the drawn loop does
/// not cycle regularly.
fn upstream_cycle(
    seed: u64,
    amplitude: f64,
    period: f64,
    seconds: f64,
) -> Option<(Signal, Upstream)> {
    let mut rng = seeded(seed ^ 0x005E_ED0F_0A1E_0A57);
    for _ in 0..UPSTREAM_TRIES {
        let tau = 5.0 + 25.0 * rng.random::<f64>();
        let delay = 1.0 + 9.0 * rng.random::<f64>();
        let band = 1.0 + 4.0 * rng.random::<f64>();
        let mut up = ClosedLoop::new(Model::Stenman(Stenman::new(band).ok()?));
        up.process = Process::Foptd { k: 1.0, tau, delay };
        // SIMC with the closed-loop time constant equal to the delay
        up.pi = Pi {
            kc: 0.5 * tau / delay,
            ti: tau.min(8.0 * delay),
        };
        up.setpoint = Signal::Constant { value: 50.0 };
        // as noisy as the catalogue's loops (0.03 to 0.3 % of span): the noise is what lets a
        // limit cycle's phase run free
        up.noise = 0.03 * 10f64.powf(rng.random::<f64>());
        up.ts = 1.0;
        up.seed = rng.random();
        // its own period in samples first, on a short run
        up.samples = 2 * UPSTREAM_SETTLE;
        let probe = up.run().ok()?;
        let pv = &probe.pv[UPSTREAM_SETTLE..];
        let reg = stiction_core::detect::regularity(&centred(pv), 1.0);
        let Some(own) = reg.period.filter(|_| reg.regularity >= UPSTREAM_REGULARITY) else {
            continue;
        };
        let dt = period / own;
        up.samples = UPSTREAM_SETTLE + (seconds / dt) as usize + 10;
        let data = up.run().ok()?;
        let mut values = centred(&data.pv[UPSTREAM_SETTLE..]);
        let sd = (values.iter().map(|v| v * v).sum::<f64>() / values.len() as f64).sqrt();
        if sd <= 0.0 {
            continue;
        }
        let scale = amplitude / std::f64::consts::SQRT_2 / sd;
        values.iter_mut().for_each(|v| *v *= scale);
        return Some((
            Signal::Recorded { dt, values },
            Upstream { band, tau, delay },
        ));
    }
    None
}

fn centred(x: &[f64]) -> Vec<f64> {
    let m = x.iter().sum::<f64>() / x.len().max(1) as f64;
    x.iter().map(|v| v - m).collect()
}

/// The loop's oscillation (a sine or narrow-band part of its load or of the disturbance on PV)
/// with its amplitude and period.
fn its_oscillation(setup: &ClosedLoop) -> Option<(Signal, f64, f64)> {
    let find = |s: &Signal| -> Option<Signal> {
        match s {
            Signal::Sine { .. } | Signal::NarrowBand { .. } => Some(s.clone()),
            Signal::Sum { parts } => parts.iter().find_map(|p| match p {
                Signal::Sine { .. } | Signal::NarrowBand { .. } => Some(p.clone()),
                _ => None,
            }),
            _ => None,
        }
    };
    let signal = setup
        .load
        .as_ref()
        .and_then(find)
        .or_else(|| setup.disturbance.as_ref().and_then(find))?;
    let (amplitude, period) = oscillation_of(&signal)?;
    Some((signal, amplitude, period))
}

/// The loop with its oscillation replaced by `by` (the same place), or with `via_setpoint`
/// taken out of the load and PV and added to the setpoint instead (a cascade's inner loop whose
/// outer loop carries the cycle).
fn disturbed(l: &BenchmarkLoop, by: &Signal, via_setpoint: bool) -> Option<BenchmarkLoop> {
    let mut setup = l.setup.clone();
    let quiet = Signal::Constant { value: 0.0 };
    let put = if via_setpoint { &quiet } else { by };
    if setup.load.as_ref().and_then(oscillation_of).is_some() {
        setup.load = setup.load.as_ref().map(|s| replaced(s, put));
    } else {
        setup.disturbance = setup.disturbance.as_ref().map(|s| replaced(s, put));
    }
    if via_setpoint {
        setup.setpoint = Signal::Sum {
            parts: vec![setup.setpoint.clone(), by.clone()],
        };
    }
    let data = setup.run().ok()?;
    Some(BenchmarkLoop {
        setup,
        data,
        ..l.clone()
    })
}

/// The loop with its own oscillation and with an upstream loop's stiction cycle in its place
/// (both moved to the setpoint with `via_setpoint`).
fn both(l: &BenchmarkLoop, via_setpoint: bool) -> Option<(BenchmarkLoop, BenchmarkLoop, Upstream)> {
    let (own, amplitude, period) = its_oscillation(&l.setup)?;
    let seconds = l.setup.warmup + l.setup.ts * l.setup.samples as f64;
    let (cycle, up) = upstream_cycle(l.setup.seed, amplitude, period, seconds)?;
    let plain = if via_setpoint {
        disturbed(l, &own, true)?
    } else {
        l.clone()
    };
    Some((plain, disturbed(l, &cycle, via_setpoint)?, up))
}

/// The diagnosis, with the setpoint given (`--sp sp`) or, `via_setpoint`, not (a cascade's inner
/// loop exported without its moving setpoint).
fn judge(l: &BenchmarkLoop, via_setpoint: bool) -> Diagnosis {
    let mut record = catalogue_loop::record(l);
    if via_setpoint {
        record.sp = None;
    }
    diagnose(&record, &catalogue_loop::request(l)).expect("catalogue records are valid requests")
}

/// The loops of both suites and sets, each with its own oscillation and with the upstream cycle,
/// judged (`via_setpoint`: both moved to the setpoint and judged without it); one line each
/// appended to `jsonl`, and the section's tables.
fn section(via_setpoint: bool, sets: &[Set], jsonl: &mut String) -> String {
    let mut rows: BTreeMap<String, (Tally, Tally)> = BTreeMap::new();
    let mut skipped = 0;
    // which families voted stiction in the false alarms, each way of disturbing the loop
    let mut voters: BTreeMap<(&str, String), usize> = BTreeMap::new();
    for suite in [Suite::Routine, Suite::Fast] {
        for &set in sets {
            let loops: Vec<BenchmarkLoop> = catalogue(suite, set)
                .into_iter()
                .filter(|l| l.class == LoopClass::ExternalOscillation)
                .collect();
            let judged: Vec<_> = loops
                .par_iter()
                .map(|l| {
                    both(l, via_setpoint).map(|(plain, p, up)| {
                        (
                            l.id.clone(),
                            judge(&plain, via_setpoint),
                            judge(&p, via_setpoint),
                            up,
                        )
                    })
                })
                .collect();
            let name = format!(
                "{} loops, {} set",
                match suite {
                    Suite::Routine => "routine",
                    Suite::Fast => "fast",
                    Suite::Plant => "plant",
                },
                match set {
                    Set::Calibration => "calibration",
                    Set::Benchmark => "benchmark",
                    Set::Extra(_) => "extra",
                }
            );
            for j in judged {
                let Some((id, plain, spread, up)) = j else {
                    skipped += 1;
                    continue;
                };
                let line = serde_json::json!({
                    "id": id, "via_setpoint": via_setpoint, "upstream_band": up.band,
                    "upstream_tau": up.tau, "upstream_delay": up.delay, "sine": &plain, "propagated": &spread,
                });
                let _ = writeln!(jsonl, "{line}");
                for (how, d) in [
                    ("sine or narrow-band", &plain),
                    ("another loop's stiction cycle", &spread),
                ] {
                    if d.verdict == Verdict::Stiction {
                        *voters.entry((how, voters_of(d))).or_default() += 1;
                    }
                }
                let (plain, spread) = (plain.verdict, spread.verdict);
                let bands = if up.band < 2.5 { "1-2.5" } else { "2.5-5" };
                let speed = if up.tau / up.delay < 4.0 {
                    "under 4"
                } else {
                    "4 or more"
                };
                for key in [
                    format!("a {name}"),
                    format!("b all, upstream band {bands} %"),
                    format!("c all, upstream time constant over dead time {speed}"),
                ] {
                    let e = rows.entry(key).or_default();
                    e.0.add(plain);
                    e.1.add(spread);
                }
            }
        }
    }
    let mut md = String::new();
    let _ = writeln!(
        md,
        "| loops | sine or narrow-band: called `stiction` | `no_stiction` | `undetermined` or `insufficient_data` | another loop's stiction cycle: called `stiction` | `no_stiction` | `undetermined` or `insufficient_data` |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|");
    for (key, (plain, spread)) in &rows {
        // the key's first letter orders the rows: the sets, then the upstream loops
        let _ = writeln!(
            md,
            "| {} | {} | {} |",
            &key[2..],
            plain.cells(),
            spread.cells()
        );
    }
    let _ = writeln!(
        md,
        "\nThe false alarms (both sets, routine and fast), by the families that voted stiction:\n\n| oscillation | families voting stiction | loops |\n|---|---|---|"
    );
    for ((how, who), n) in &voters {
        let _ = writeln!(md, "| {how} | {who} | {n} |");
    }
    if skipped > 0 {
        let _ = writeln!(
            md,
            "\n{skipped} loops left out: no upstream loop drawn for them cycled regularly (r >= {UPSTREAM_REGULARITY}) in {UPSTREAM_TRIES} tries."
        );
    }
    md
}

/// The families that voted stiction, by name, joined.
fn voters_of(d: &Diagnosis) -> String {
    let who: Vec<String> = d
        .families
        .iter()
        .filter(|f| f.vote == Vote::Stiction)
        .map(|f| {
            serde_json::to_string(&f.family)
                .unwrap_or_default()
                .replace('"', "")
        })
        .collect();
    who.join(" and ")
}

fn main() {
    let args = StudyArgs::from_env("propagated_oscillation");
    let sets: Vec<Set> = match args.value("--extra") {
        None => vec![Set::Calibration, Set::Benchmark],
        Some(list) => list
            .split(',')
            .map(|n| {
                n.trim().parse().map(Set::Extra).unwrap_or_else(|_| {
                    args.fail(&format!(
                        "--extra {list}: draws are numbers from 1 to 255, comma-separated"
                    ))
                })
            })
            .collect(),
    };
    let mut jsonl = String::new();
    let mut md = String::from("# A plant-wide oscillation: another loop's sticky valve\n\n");
    md.push_str(
        "Generated by `cargo run --release -p stiction-lab --example propagated_oscillation -- --out crates/stiction-lab/results/propagated-oscillation.md`. \
         The catalogue's external-oscillation look-alikes (healthy valves; routine and fast loops, benchmark and calibration sets) \
         simulated again with their oscillation (a sine or narrow-band noise, on the load or on PV) replaced by another loop's \
         stiction limit cycle of the same period and standard deviation: an upstream PI loop with a Stenman valve \
         (band 1-5 %, process gain 1, time constant 5-30 s, dead time 1-10 s, PV noise 0.03-0.3 % of span, drawn from the loop's seed \
         until its own cycle is regular: Thornhill's r at least 5 after 3,000 s to settle) is simulated and its PV's deviation, \
         stretched in time to the loop's period, is the oscillation (not sinusoidal, steady in amplitude, free in phase, as a \
         propagated plant-wide oscillation is). Every other part of each loop is the same. The \
         valve judged is healthy in every loop: a `stiction` verdict is a false alarm. Outside the benchmark's goals (the \
         catalogue has no such look-alike).\n\n\
         ## Through the process: on the load or on PV, where the loop's own oscillation was\n\n\
         Each loop judged as `stiction diagnose loop.csv --sp sp` judges it.\n\n",
    );
    md.push_str(&section(false, &sets, &mut jsonl));
    md.push_str(
        "\n## Through the setpoint: a cascade's inner loop exported without its setpoint\n\n\
         The loop's oscillation (its own, and the upstream cycle in its place) taken off the load and PV and added to its \
         setpoint, as an outer loop that carries the cycle moves an inner loop's setpoint; each judged as \
         `stiction diagnose loop.csv` judges it, without `--sp` (the setpoint is not in the export; the error is then PV's \
         deviation from the setpoint read off the record, or from its mean).\n\n",
    );
    md.push_str(&section(true, &sets, &mut jsonl));
    if let Some(path) = args.value("--jsonl") {
        std::fs::write(path, &jsonl)
            .unwrap_or_else(|e| args.fail(&format!("{path}: cannot write: {e}")));
    }
    args.emit(&md);
}
