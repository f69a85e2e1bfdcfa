//! Accuracy benchmark of closed-loop quantification (`stiction quantify`) on simulated loops.
//!
//!     cargo run --release -p stiction-lab --example quantify_accuracy -- [--quick] [--full] [--only MODEL] [--out crates/stiction-lab/results/quantify-accuracy.md]
//!
//! Loops: Stenman d in {0.5, 1, 2, 4} % and Kano (S, J) in {(2, 0.5), (4, 1), (4, 4), (6, 2)} %;
//! processes K e^{-θs}/(τs+1) with (K, τ, θ) in {(3, 10, 10), (1, 30, 5), (2, 5, 2)} and an
//! integrating process; a PI tuning per process that gives a stiction limit cycle; noise-to-signal
//! 0, 5 and 15 % (noise standard deviation over the standard deviation of the noise-free PV);
//! 5 seeds per case (the seed sets the noise, the setpoint step and the operating point).
//! Stenman is estimated with the exact method, Kano with ACO_R. Writes a Markdown table.

use std::fmt::Write as _;
use std::time::Instant;
use stiction_core::estimate::Method;
use stiction_core::models::{Kano, Model, ModelKind, Stenman};
use stiction_core::quantify::{quantify, LinearFamily, QuantifyRequest};
use stiction_core::rng::seeded;
use stiction_core::sim::{ClosedLoop, Pi, Process, Signal};

use rand::RngExt;

struct Plant {
    name: &'static str,
    process: Process,
    pi: Pi,
}

fn plants() -> Vec<Plant> {
    vec![
        Plant {
            name: "FOPTD K=3 τ=10 θ=10",
            process: Process::Foptd {
                k: 3.0,
                tau: 10.0,
                delay: 10.0,
            },
            pi: Pi { kc: 0.2, ti: 10.0 },
        },
        Plant {
            name: "FOPTD K=1 τ=30 θ=5",
            process: Process::Foptd {
                k: 1.0,
                tau: 30.0,
                delay: 5.0,
            },
            pi: Pi { kc: 1.5, ti: 30.0 },
        },
        Plant {
            name: "FOPTD K=2 τ=5 θ=2",
            process: Process::Foptd {
                k: 2.0,
                tau: 5.0,
                delay: 2.0,
            },
            pi: Pi { kc: 0.5, ti: 5.0 },
        },
        Plant {
            name: "integrating K=0.02/s θ=2",
            process: Process::Integrating {
                k: 0.02,
                delay: 2.0,
            },
            pi: Pi { kc: 2.0, ti: 50.0 },
        },
    ]
}

fn std_dev(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
}

struct Row {
    valve: String,
    plant: &'static str,
    noise: f64,
    seed: u64,
    estimate: Vec<f64>,
    rel_err: f64,
    cycling: bool,
    seconds: f64,
    structure: String,
}

/// `--full`: every cell of the whole record (the reference) instead of the staged exact search.
static FULL: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

fn run_case(valve: Model, plant: &Plant, nsr: f64, seed: u64) -> Row {
    let mut rng = seeded(1000 + seed);
    let op0 = 40.0 + 20.0 * rng.random::<f64>();
    let step = 0.5 + 1.5 * rng.random::<f64>();
    let mut cl = ClosedLoop::new(valve);
    cl.process = plant.process;
    cl.pi = plant.pi;
    cl.samples = 2000;
    cl.op0 = op0;
    cl.setpoint = Signal::Step {
        from: 50.0,
        to: 50.0 + step,
        at: 10.0,
    };
    cl.seed = seed;
    let clean = cl.run().unwrap();
    let scale = std_dev(&clean.pv[1000..]);
    let cycling = scale > 1e-3 && clean.mv[1000..].windows(2).any(|w| w[1] != w[0]);
    cl.noise = nsr * scale;
    let data = if nsr > 0.0 { cl.run().unwrap() } else { clean };
    let kind = valve.kind();
    let method = if kind == ModelKind::Stenman {
        Method::Exact
    } else {
        Method::AcoR
    };
    let mut req = QuantifyRequest::new(kind, method);
    req.seed = seed;
    req.staged = !FULL.load(std::sync::atomic::Ordering::Relaxed);
    let t = Instant::now();
    let q = quantify(&data.op, &data.pv, &req).unwrap();
    let seconds = t.elapsed().as_secs_f64();
    let truth = valve.values();
    let estimate: Vec<f64> = kind
        .param_names()
        .iter()
        .map(|n| q.params.get(*n).copied().unwrap_or(f64::NAN))
        .collect();
    let rel_err = truth
        .iter()
        .zip(&estimate)
        .map(|(t, e)| ((e - t) / t).abs())
        .fold(0.0, f64::max);
    let structure = q
        .linear_model
        .as_ref()
        .map(|l| {
            format!(
                "{}{}{}/{}",
                if l.family == LinearFamily::Integrating {
                    "I"
                } else {
                    ""
                },
                l.na,
                l.nb,
                l.nk
            )
        })
        .unwrap_or_else(|| q.reason.clone().unwrap_or_default());
    Row {
        valve: format!(
            "{kind} {}",
            kind.param_names()
                .iter()
                .zip(&truth)
                .map(|(n, v)| format!("{n}={v}"))
                .collect::<Vec<_>>()
                .join(",")
        ),
        plant: plant.name,
        noise: nsr,
        seed,
        estimate,
        rel_err: if rel_err.is_nan() {
            f64::INFINITY
        } else {
            rel_err
        },
        cycling,
        seconds,
        structure,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    FULL.store(
        args.iter().any(|a| a == "--full"),
        std::sync::atomic::Ordering::Relaxed,
    );
    let only = args
        .iter()
        .position(|a| a == "--only")
        .map(|i| args[i + 1].clone());
    let out = args
        .iter()
        .position(|a| a == "--out")
        .map(|i| args[i + 1].clone());
    let mut valves: Vec<Model> = [0.5, 1.0, 2.0, 4.0]
        .iter()
        .map(|&d| Model::Stenman(Stenman { d }))
        .collect();
    valves.extend(
        [(2.0, 0.5), (4.0, 1.0), (4.0, 4.0), (6.0, 2.0)]
            .iter()
            .map(|&(s, j)| Model::Kano(Kano { s, j })),
    );
    if let Some(o) = &only {
        valves.retain(|v| v.kind().name() == o);
    }
    let seeds: Vec<u64> = if quick { vec![1] } else { (1..=5).collect() };
    let mut rows = Vec::new();
    let started = Instant::now();
    for valve in &valves {
        for plant in &plants() {
            for &nsr in &[0.0, 0.05, 0.15] {
                for &seed in &seeds {
                    let r = run_case(*valve, plant, nsr, seed);
                    eprintln!(
                        "{:<18} {:<26} noise {:>4.0}% seed {} -> {:?} rel.err {:>6.1}% {} {:.2}s{}",
                        r.valve,
                        r.plant,
                        100.0 * r.noise,
                        r.seed,
                        r.estimate
                            .iter()
                            .map(|v| (v * 1000.0).round() / 1000.0)
                            .collect::<Vec<_>>(),
                        100.0 * r.rel_err,
                        r.structure,
                        r.seconds,
                        if r.cycling { "" } else { " (no limit cycle)" }
                    );
                    rows.push(r);
                }
            }
        }
    }
    let total = started.elapsed().as_secs_f64();
    let md = report(&rows, total, seeds.len());
    println!("{md}");
    if let Some(path) = out {
        std::fs::write(&path, md).expect("write the report");
        eprintln!("wrote {path}");
    }
}

fn report(rows: &[Row], total: f64, seeds: usize) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Closed-loop quantification accuracy (simulated loops)\n"
    );
    let _ = writeln!(
        s,
        "Generated by `cargo run --release -p stiction-lab --example quantify_accuracy -- --out crates/stiction-lab/results/quantify-accuracy.md`.\n\
         Each loop: 2000 samples at Ts = 1 s, PI control, setpoint step at 10 s; noise-to-signal is the noise standard deviation \
         over the standard deviation of the noise-free PV in the second half; {seeds} seed(s) per case (noise, setpoint step \
         0.5-2, operating point 40-60 %). Stenman by `--method exact`, Kano by `--method aco-r`. Relative error: \
         |estimate - truth| / truth, the larger of S and J for Kano. Whole run: {total:.0} s.\n"
    );
    let _ = writeln!(s, "## Share of cases within 10 % (and within 5 %)\n");
    let _ = writeln!(s, "| valve | noise 0 % | noise 5 % | noise 15 % |");
    let _ = writeln!(s, "|---|---|---|---|");
    let mut valves: Vec<&str> = Vec::new();
    for r in rows {
        if !valves.contains(&r.valve.as_str()) {
            valves.push(&r.valve);
        }
    }
    let share = |f: &dyn Fn(&&Row) -> bool, lim: f64| {
        let sel: Vec<&Row> = rows.iter().filter(f).collect();
        let ok = sel.iter().filter(|r| r.rel_err <= lim).count();
        (ok, sel.len())
    };
    for v in &valves {
        let mut line = format!("| {v} |");
        for nsr in [0.0, 0.05, 0.15] {
            let (a, n) = share(&|r: &&Row| r.valve == *v && r.noise == nsr, 0.10);
            let (b, _) = share(&|r: &&Row| r.valve == *v && r.noise == nsr, 0.05);
            let _ = write!(line, " {a}/{n} ({b}/{n}) |");
        }
        let _ = writeln!(s, "{line}");
    }
    let mut line = "| **all** |".to_string();
    for nsr in [0.0, 0.05, 0.15] {
        let (a, n) = share(&|r: &&Row| r.noise == nsr, 0.10);
        let (b, _) = share(&|r: &&Row| r.noise == nsr, 0.05);
        let _ = write!(line, " **{a}/{n}** ({b}/{n}) |");
    }
    let _ = writeln!(s, "{line}\n");
    let (clean5, nclean) = share(&|r: &&Row| r.noise == 0.0, 0.05);
    let (noisy10, nnoisy) = share(&|r: &&Row| r.noise == 0.05, 0.10);
    let _ = writeln!(
        s,
        "Goals: every noise-free case within 5 %: {clean5}/{nclean} ({}); at least 90 % of the 5 %-noise cases within 10 %: \
         {noisy10}/{nnoisy} = {:.0} % ({}).\n",
        if clean5 == nclean { "met" } else { "missed" },
        100.0 * noisy10 as f64 / nnoisy.max(1) as f64,
        if noisy10 as f64 >= 0.9 * nnoisy as f64 { "met" } else { "missed" }
    );
    let _ = writeln!(s, "## Where the goals are missed, and why\n");
    let misses: Vec<&Row> = rows
        .iter()
        .filter(|r| (r.noise == 0.0 && r.rel_err > 0.05) || (r.noise == 0.05 && r.rel_err > 0.10))
        .collect();
    let _ = writeln!(
        s,
        "Noise-free cases beyond 5 % and 5 %-noise cases beyond 10 %:\n"
    );
    let _ = writeln!(
        s,
        "| valve | process | noise | seed | estimate | rel. error | limit cycle | linear model |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
    for r in &misses {
        let _ = writeln!(s, "{} |", row(r));
    }
    let _ = writeln!(
        s,
        "\nWhy, as far as we measured it:\n\n\
         - **Kano, two parameters.** The fit error is a step function of (S, J) whose basin around the truth is \
         very narrow: in the noise-free Kano (4, 4) loop on K=3 τ=10 θ=10, S off by 2 % raises the simulation \
         error from 5e-18 to 195. The Stenman band d is exact (every trajectory is fitted), but for Kano \
         the search is ACO_R started from the Stenman answer and polished by coordinate scans; when the Stenman \
         structure or band is not close enough the search settles in another basin, often with a different \
         linear structure (e.g. delay 30 samples, the edge of the delay range). An exact partition in (S, J), \
         as we have for d, is the fix; it is not built yet.\n\
         - **Stenman.** The band d is exact over the cells searched (the staged search: every cell of the first \
         samples, at least 600 and 8 oscillation periods, then the best of them on the whole record; `--full` \
         searches every cell of the whole record). The misses with noise are loops where another linear \
         structure (delay, orders) with a different d fits the noisy PV as well or better: the criterion \
         ranks fits of the PV, and noise blurs the difference.\n\
         - **Limit cycles.** One PI tuning per process is used for every valve; the column 'limit cycle' says \
         whether the noise-free loop still oscillates in its second half. Loops that settle (no limit cycle) \
         carry little information about the band.\n"
    );
    let _ = writeln!(s, "## Every case\n");
    let _ = writeln!(s, "| valve | process | noise | seed | estimate | rel. error | limit cycle | linear model (na nb / nk) | seconds |");
    let _ = writeln!(s, "|---|---|---|---|---|---|---|---|---|");
    for r in rows {
        let _ = writeln!(s, "{} | {:.2} |", row(r), r.seconds);
    }
    s
}

/// The columns every case table shares: valve, process, noise, seed, estimate, error, limit cycle,
/// linear model (without the closing bar).
fn row(r: &Row) -> String {
    format!(
        "| {} | {} | {:.0} % | {} | {} | {:.1} % | {} | {}",
        r.valve,
        r.plant,
        100.0 * r.noise,
        r.seed,
        r.estimate
            .iter()
            .map(|v| format!("{v:.3}"))
            .collect::<Vec<_>>()
            .join(", "),
        100.0 * r.rel_err,
        if r.cycling { "yes" } else { "no" },
        r.structure
    )
}
