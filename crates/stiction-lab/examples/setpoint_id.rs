//! How close to the truth is the process a closed-loop record gives? The closed-loop fit's
//! (`quantify::compare_fits`, what the model family judges by) against a two-stage
//! identification from the setpoint (Van den Hof and Schrama 1993): OP's part driven by the
//! setpoint is found first (a least-squares step response of OP to SP's steps, beside a level and
//! a slope), and the process is fitted from that part alone. It carries none of PV's noise or of
//! the load the controller answered, so, unlike OP, it is a fair input in closed loop.
//!
//!     cargo run --release -p stiction-lab --example setpoint_id -- [--benchmark] [--out FILE]
//!
//! Routine suite, loops whose setpoint steps. The truth: the catalogue's process, the actuator lag
//! added to its time constant. Both identifications as a first-order process with dead time (an
//! integrator for levels).
//!
//! Then what each process is worth to a test: `oracle_bound`'s "recorded" oracle (the load's
//! model, the noise and the valve known; PV at the recorded samples; a Kalman filter over the
//! load gives the exact likelihoods) on each sticky loop and its healthy twin, under the true
//! process, under each identification's, under the setpoint's identified again with the sticky
//! valve between OP and the process for the sticky hypothesis (a generalised likelihood ratio),
//! and with the process profiled 0.25-4 times around each identification's (`profile::WIDE`),
//! with the band known and, on the Stenman loops, free. `--pairs FILE` writes each pair's ratios.

use stiction_lab::oracle::{kalman, profile};
use stiction_lab::setpoint;
use stiction_lab::study_args;

use rayon::prelude::*;
use setpoint::{op_from_setpoint, process_from, Foptd};
use std::fmt::Write as _;
use stiction_core::models::{Model, Stenman};
use stiction_core::quantify::{compare_fits, CompareRequest};
use stiction_core::sim::{ClosedLoop, LoopData, Process};
use stiction_lab::catalogue::{self, BenchmarkLoop, Excitation, Suite};
use study_args::StudyArgs;

/// The truth: gain, the lags summed (actuator lag included), dead time.
fn truth(l: &BenchmarkLoop) -> Foptd {
    let lag = l.setup.valve_lag;
    match l.setup.process {
        Process::Foptd { k, tau, delay } => Foptd {
            k,
            tau: tau + lag,
            delay,
        },
        Process::Integrating { k, delay } => Foptd { k, tau: lag, delay },
        Process::Soptd {
            k,
            tau1,
            tau2,
            delay,
        } => Foptd {
            k,
            tau: tau1 + tau2 + lag,
            delay,
        },
    }
}

fn by_fit(l: &BenchmarkLoop, d: &LoopData) -> Option<Foptd> {
    let f = compare_fits(
        &d.op,
        &d.pv,
        &CompareRequest {
            ts: l.setup.ts,
            integrating: Some(l.integrating),
            ..CompareRequest::default()
        },
    )?;
    Some(Foptd {
        k: f.gain?,
        tau: f.time_constant.unwrap_or(0.0),
        delay: f.dead_time,
    })
}

/// The process from the setpoint with a valve `model` between OP and the process: the valve run
/// on the recorded OP, its setpoint-driven part the input.
fn by_setpoint_under(l: &BenchmarkLoop, d: &LoopData, model: &Model) -> Option<Foptd> {
    let n = d.op.len();
    let mv = model.simulate_from(&d.op, None);
    let u = op_from_setpoint(&d.sp, &mv, n / 8)?;
    process_from(&u, &d.pv, l.setup.ts, l.integrating)
}

fn by_setpoint(l: &BenchmarkLoop, d: &LoopData) -> Option<Foptd> {
    let n = d.op.len();
    let u = op_from_setpoint(&d.sp, &d.op, n / 8)?;
    process_from(&u, &d.pv, l.setup.ts, l.integrating)
}

/// A record's process as each identification gives it.
#[derive(Clone, Copy)]
struct Ids {
    fit: Option<Foptd>,
    setpoint: Option<Foptd>,
}

/// A group of rows for the first table: its name's rule.
type Group = Box<dyn Fn(&Row) -> bool>;

struct Row {
    class: String,
    kind: String,
    ts: f64,
    integrating: bool,
    truth: Foptd,
    fit: Option<Foptd>,
    setpoint: Option<Foptd>,
    /// The oracle's ratio on the sticky loop and its twin, process: truth, fit's, setpoint's.
    oracle: Option<[(f64, f64); 9]>,
}

/// `setup` with its process as identified (the actuator lag left to it).
fn with_process(l: &BenchmarkLoop, setup: &ClosedLoop, p: Foptd) -> ClosedLoop {
    let mut s = setup.clone();
    s.process = if l.integrating {
        Process::Integrating {
            k: p.k,
            delay: p.delay,
        }
    } else {
        Process::Foptd {
            k: p.k,
            tau: p.tau.max(0.1),
            delay: p.delay,
        }
    };
    s.valve_lag = 0.0;
    s
}

/// The "recorded" oracle (load's model known, PV at the recorded samples; band known but in the last three rows) on a sticky
/// loop and its twin under the true process, the fit's and the setpoint's.
fn oracle(l: &BenchmarkLoop, ids: Ids) -> Option<[(f64, f64); 9]> {
    if !matches!(l.truth, catalogue::Truth::Sticky) {
        return None;
    }
    let run = kalman::full_run(&l.setup);
    let mut twin = l.setup.clone();
    twin.model = Model::Stenman(Stenman { d: 0.0 });
    let twin_run = kalman::full_run(&twin);
    let twin_data = twin.run().ok()?;
    let llr = |s: &ClosedLoop, r: &kalman::FullRun| kalman::llrs(s, &l.setup.model, r).recorded;
    let truth = (llr(&l.setup, &run), llr(&twin, &twin_run));
    // each identification once, of the loop's record and of its twin's
    let fit = (ids.fit?, by_fit(l, &twin_data)?);
    let setpoint = (ids.setpoint?, by_setpoint(l, &twin_data)?);
    let under = |(p1, p0): (Foptd, Foptd)| -> Option<(f64, f64)> {
        Some((
            llr(&with_process(l, &l.setup, p1), &run),
            llr(&with_process(l, &twin, p0), &twin_run),
        ))
    };
    // each hypothesis its own process, from the setpoint: a generalised likelihood ratio
    let healthy = Model::Stenman(Stenman { d: 0.0 });
    let glr = |d: &LoopData, setup: &ClosedLoop, r: &kalman::FullRun, p0: Foptd| -> Option<f64> {
        let p1 = by_setpoint_under(l, d, &l.setup.model)?;
        Some(
            profile::recorded_log_likelihood(&with_process(l, setup, p1), &l.setup.model, r)
                - profile::recorded_log_likelihood(&with_process(l, setup, p0), &healthy, r),
        )
    };
    let each = (
        glr(&l.data, &l.setup, &run, setpoint.0)?,
        glr(&twin_data, &twin, &twin_run, setpoint.1)?,
    );
    // the wide profile (band known) centred on each identification's process
    let centred = |(p1, p0): (Foptd, Foptd)| -> Option<(f64, f64)> {
        let s1 = with_process(l, &l.setup, p1);
        let s0 = with_process(l, &twin, p0);
        Some((
            profile::profiled_llr(&s1, &l.setup.model, &run, &profile::WIDE),
            profile::profiled_llr(&s0, &l.setup.model, &twin_run, &profile::WIDE),
        ))
    };
    // with the band free too (16 Stenman bands at every point), on the Stenman loops; and with
    // the noise as the record shows it
    let free = |(p1, p0): (Foptd, Foptd), read: bool| -> Option<(f64, f64)> {
        if l.class != catalogue::LoopClass::StenmanValve {
            return Some((f64::NAN, f64::NAN));
        }
        let mut s1 = with_process(l, &l.setup, p1);
        let mut s0 = with_process(l, &twin, p0);
        if read {
            s1.noise = stiction_core::detect::measurement_noise(&l.data.pv).max(1e-3);
            s0.noise = stiction_core::detect::measurement_noise(&twin_data.pv).max(1e-3);
        }
        Some((
            profile::profiled_band_free_llr(&s1, &run, &profile::WIDE),
            profile::profiled_band_free_llr(&s0, &twin_run, &profile::WIDE),
        ))
    };
    Some([
        truth,
        under(fit)?,
        under(setpoint)?,
        each,
        centred(fit)?,
        centred(setpoint)?,
        free(fit, false)?,
        free(setpoint, false)?,
        free(setpoint, true)?,
    ])
}

/// |log(est / truth)|, or infinity when missing or of the wrong sign.
fn err(est: Option<f64>, truth: f64) -> f64 {
    match est {
        Some(e) if e > 0.0 && truth > 0.0 => (e / truth).ln().abs(),
        _ => f64::INFINITY,
    }
}

fn share_within(v: &[f64], tol: f64) -> String {
    let n = v.iter().filter(|&&e| e <= tol).count();
    format!("{:.0} %", 100.0 * n as f64 / v.len().max(1) as f64)
}

fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

/// The balanced accuracy at the threshold that does best on the pairs' column `i` themselves.
fn best_threshold(part: &[&[(f64, f64); 9]], i: usize) -> f64 {
    let n = part.len().max(1) as f64;
    part.iter()
        .flat_map(|p| [p[i].0, p[i].1])
        .map(|th| {
            let hit = part.iter().filter(|p| p[i].0 >= th).count() as f64 / n;
            let ok = part.iter().filter(|p| p[i].1 < th).count() as f64 / n;
            (hit + ok) / 2.0
        })
        .fold(0.0, f64::max)
}

/// The area under the ROC curve of column `i`: the share of (sticky loop, twin) pairs, over all
/// loops, in which the sticky loop's ratio is the higher (ties a half).
fn auc(part: &[&[(f64, f64); 9]], i: usize) -> f64 {
    let mut wins = 0.0;
    for a in part {
        for b in part {
            wins += match a[i].0.total_cmp(&b[i].1) {
                std::cmp::Ordering::Greater => 1.0,
                std::cmp::Ordering::Equal => 0.5,
                std::cmp::Ordering::Less => 0.0,
            };
        }
    }
    wins / (part.len() * part.len()).max(1) as f64
}

fn main() {
    let args = StudyArgs::from_env("setpoint_id");
    let set = args.set();
    let loops: Vec<BenchmarkLoop> = catalogue::catalogue(Suite::Routine, set)
        .into_iter()
        .filter(|l| {
            matches!(
                l.excitation,
                Excitation::SetpointSteps
                    | Excitation::StepsAndDrift
                    | Excitation::StepsAndLoadSteps
            )
        })
        .collect();
    let rows: Vec<Row> = loops
        .par_iter()
        .map(|l| {
            let ids = Ids {
                fit: by_fit(l, &l.data),
                setpoint: by_setpoint(l, &l.data),
            };
            Row {
                class: l.class.to_string(),
                kind: format!("{:?}", l.kind),
                ts: l.setup.ts,
                integrating: l.integrating,
                truth: truth(l),
                fit: ids.fit,
                setpoint: ids.setpoint,
                oracle: oracle(l, ids),
            }
        })
        .collect();
    let mut md = process_table(&rows, set);
    md += &oracle_table(&rows, args.value("--pairs"));
    args.emit(&md);
}

/// The first table: each identification's process against the truth, by group.
fn process_table(rows: &[Row], set: catalogue::Set) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# The process a closed-loop record gives (routine suite, loops with setpoint steps)\n\n\
         Generated by `cargo run --release -p stiction-lab --example setpoint_id{}`. Errors as |log(estimate / truth)|: 0.18 is 20 % off. \
         The gain for every loop; the response time (time constant and dead time, the actuator lag counted in the time constant) for self-regulating ones.\n",
        if set == catalogue::Set::Benchmark { " -- --benchmark" } else { "" }
    );
    let _ = writeln!(
        md,
        "| group | loops | gain within 20 %: fit / setpoint | gain, median error: fit / setpoint | response time within 30 %: fit / setpoint | median error: fit / setpoint |\n|---|---|---|---|---|---|"
    );
    let mut groups: Vec<(String, Group)> = vec![("all".into(), Box::new(|_| true))];
    for c in ["stenman_valve", "kano_valve", "he_valve", "healthy"] {
        let c2 = c.to_string();
        groups.push((c.into(), Box::new(move |r: &Row| r.class == c2)));
    }
    groups.push(("1 s".into(), Box::new(|r: &Row| r.ts < 5.0)));
    groups.push(("10 s".into(), Box::new(|r: &Row| r.ts >= 5.0)));
    for k in ["Flow", "Pressure", "Level", "Temperature"] {
        let k2 = k.to_string();
        groups.push((k.into(), Box::new(move |r: &Row| r.kind == k2)));
    }
    for (name, pick) in &groups {
        let part: Vec<&Row> = rows.iter().filter(|r| pick(r)).collect();
        if part.is_empty() {
            continue;
        }
        let gain = |f: fn(&Row) -> Option<Foptd>| -> Vec<f64> {
            part.iter()
                .map(|r| err(f(r).map(|p| p.k.abs()), r.truth.k.abs()))
                .collect()
        };
        let resp = |f: fn(&Row) -> Option<Foptd>| -> Vec<f64> {
            part.iter()
                .filter(|r| !r.integrating)
                .map(|r| err(f(r).map(|p| p.tau + p.delay), r.truth.tau + r.truth.delay))
                .collect()
        };
        let (gf, gs) = (gain(|r| r.fit), gain(|r| r.setpoint));
        let (rf, rs) = (resp(|r| r.fit), resp(|r| r.setpoint));
        let _ = writeln!(
            md,
            "| {name} | {} | {} / {} | {:.2} / {:.2} | {} / {} | {:.2} / {:.2} |",
            part.len(),
            share_within(&gf, 0.18),
            share_within(&gs, 0.18),
            median(&gf),
            median(&gs),
            share_within(&rf, 0.26),
            share_within(&rs, 0.26),
            median(&rf),
            median(&rs)
        );
    }
    md
}

/// The second table: the oracle's test under each process; each pair's ratios to `pairs_file`.
fn oracle_table(rows: &[Row], pairs_file: Option<&str>) -> String {
    let mut md = String::new();
    let pairs: Vec<[(f64, f64); 9]> = rows.iter().filter_map(|r| r.oracle).collect();
    let _ = writeln!(
        md,
        "\n## The oracle's test under each process (sticky loops with setpoint steps and their twins; load's model known, PV at the recorded samples; band known but in the last three rows)\n\n\
         Each test is \"stiction when the log-likelihood ratio exceeds 0\"; the last two columns rank instead: the balanced accuracy at the threshold that does best on these pairs themselves (in-sample), and the area under the ROC curve (sticky loops over twins).\n\n\
         | process | pairs | sticky called stiction | twins called healthy | balanced accuracy | at the best threshold (in-sample) | area under the ROC curve |\n|---|---|---|---|---|---|---|"
    );
    if let Some(path) = pairs_file {
        let lines: Vec<String> = pairs
            .iter()
            .map(|p| {
                let v: Vec<String> = p.iter().map(|(a, b)| format!("[{a},{b}]")).collect();
                format!("[{}]", v.join(",")).replace("NaN", "null")
            })
            .collect();
        let _ = std::fs::write(path, lines.join("\n"));
    }
    for (i, name) in [
        "the truth",
        "the closed-loop fit's",
        "from the setpoint (two stages)",
        "from the setpoint under each hypothesis",
        "profiled 0.25-4 times around the fit's",
        "profiled 0.25-4 times around the setpoint's",
        "Stenman loops, band free too: around the fit's",
        "Stenman loops, band free too: around the setpoint's",
        "the same, the noise as the record shows it",
    ]
    .iter()
    .enumerate()
    {
        let part: Vec<&[(f64, f64); 9]> = pairs.iter().filter(|p| !p[i].0.is_nan()).collect();
        let n = part.len().max(1) as f64;
        let hit = part.iter().filter(|p| p[i].0 > 0.0).count() as f64 / n;
        let ok = part.iter().filter(|p| p[i].1 <= 0.0).count() as f64 / n;
        let _ = writeln!(
            md,
            "| {name} | {} | {:.1} % | {:.1} % | {:.3} | {:.3} | {:.3} |",
            part.len(),
            100.0 * hit,
            100.0 * ok,
            (hit + ok) / 2.0,
            best_threshold(&part, i),
            auc(&part, i)
        );
    }
    md
}
