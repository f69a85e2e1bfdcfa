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
//!     cargo run --release -p stiction-core --example oracle_bound -- [--benchmark] [--out FILE]
//!
//! The calibration set by default (`--benchmark`: the benchmark seeds).

#[path = "common/study_args.rs"]
mod study_args;

use rayon::prelude::*;
use std::fmt::Write as _;
use stiction_core::models::{He, Kano, Model, Stenman};
use stiction_core::sim::catalogue::{self, BenchmarkLoop, LoopClass, Suite, Truth};
use stiction_core::sim::{ClosedLoop, Plan, Process, Signal, ValveLag};
use study_args::StudyArgs;

/// The full-rate run of a loop: every plant step from the start of the warm-up.
struct FullRun {
    op: Vec<f64>,
    pv: Vec<f64>,
    /// The plant step of the record's first sample.
    warm: usize,
    /// The plant steps the historian recorded.
    recorded: Vec<usize>,
    dt: f64,
    /// Plant steps per controller execution.
    m: usize,
}

fn full_run(setup: &ClosedLoop) -> FullRun {
    let plan = Plan::new(setup);
    let mut full = setup.clone();
    full.ts = plan.dt;
    full.controller_period = Some(plan.h);
    full.samples = plan.steps;
    full.warmup = 0.0;
    let data = full.run().expect("a catalogue loop runs");
    FullRun {
        op: data.op,
        pv: data.pv,
        warm: plan.recorded.first().copied().unwrap_or(0),
        recorded: plan.recorded,
        dt: plan.dt,
        m: plan.substeps,
    }
}

/// PV without load and noise if `model` were the valve, driven by the run's OP.
fn replay(setup: &ClosedLoop, model: &Model, run: &FullRun) -> Vec<f64> {
    let n = run.op.len();
    let dist = setup
        .disturbance
        .as_ref()
        .map(|d| d.generate(run.dt, n))
        .unwrap_or_else(|| vec![0.0; n]);
    let pv0 = setup.setpoint.generate(run.dt, 1)[0];
    let (mut state, x0) = model.start(setup.op0);
    let mut lag = ValveLag::new(setup.valve_lag, run.dt, x0);
    let flow0 = setup.characteristic.flow(x0);
    let mut process = setup.process.discretise(run.dt);
    let nd = (setup.process.delay() / run.dt).round() as usize;
    let mut stem = x0;
    let mut mv = Vec::with_capacity(n);
    let mut out = Vec::with_capacity(n);
    for t in 0..n {
        out.push(pv0 + process.output() + dist[t]);
        if t % run.m == 0 && t > 0 {
            stem = model.step(&mut state, run.op[t]);
        }
        mv.push(if t == 0 { x0 } else { lag.step(stem) });
        let position = if t >= nd { mv[t - nd] } else { x0 };
        process.advance(setup.characteristic.flow(position) - flow0);
    }
    out
}

/// The process's response to `u` (from rest).
fn response(p: &Process, dt: f64, u: &[f64]) -> Vec<f64> {
    let mut s = p.discretise(dt);
    u.iter()
        .map(|&x| {
            let y = s.output();
            s.advance(x);
            y
        })
        .collect()
}

const NS: usize = 4;
type Mat = [[f64; NS]; NS];

/// The linear model of the load's effect on PV: state `[x1, x2, level, slope]` (the process's
/// states, the load's level and slope), `x' = A x + w` with `w` on the slope only, PV's share
/// `c x`.
struct LoadStateSpace {
    a: Mat,
    c: [f64; NS],
    q: f64,
}

fn state_space(p: &Process, dt: f64, kick: f64) -> LoadStateSpace {
    let mut a = [[0.0; NS]; NS];
    let mut c = [0.0; NS];
    // process input u = level (the load is not delayed)
    match p.discretise(dt) {
        stiction_core::sim::ProcessState::Lag { k, a: pole, .. } => {
            a[0][0] = pole;
            a[0][2] = k * (1.0 - pole);
            c[0] = 1.0;
        }
        stiction_core::sim::ProcessState::Integrator { k, h, .. } => {
            a[0][0] = 1.0;
            a[0][2] = k * h;
            c[0] = 1.0;
        }
        stiction_core::sim::ProcessState::TwoLags { k, a1, a2, phi, .. } => {
            // x2' = a2 x2 + phi x1 + (1 - a2 - phi) u; x1' = a1 x1 + (1 - a1) u; y = k x2
            a[1][1] = a2;
            a[1][0] = phi;
            a[1][2] = 1.0 - a2 - phi;
            a[0][0] = a1;
            a[0][2] = 1.0 - a1;
            c[1] = k;
        }
    }
    a[2][2] = 1.0;
    a[2][3] = dt;
    a[3][3] = 1.0;
    LoadStateSpace {
        a,
        c,
        q: kick * kick,
    }
}

/// The log-likelihood ratio of the residuals `r1` (sticky hypothesis) against `r0` (healthy),
/// both `G load + noise` under their hypothesis, with PV seen at the steps where `seen`; the load
/// starts at rest (level and slope 0, as the simulator's). Innovation variances do not depend on
/// the data, so they are shared.
fn kalman_llr(ss: &LoadStateSpace, sigma: f64, r1: &[f64], r0: &[f64], seen: &[bool]) -> f64 {
    let mut x1 = [0.0; NS];
    let mut x0 = [0.0; NS];
    let mut p = [[0.0; NS]; NS];
    let r = sigma * sigma;
    let mut llr = 0.0;
    for t in 0..r1.len() {
        if seen[t] {
            // innovation variance s = c P c' + r; gain k = P c' / s
            let pc: [f64; NS] = std::array::from_fn(|i| (0..NS).map(|j| p[i][j] * ss.c[j]).sum());
            let s = (0..NS).map(|i| ss.c[i] * pc[i]).sum::<f64>() + r;
            let k: [f64; NS] = std::array::from_fn(|i| pc[i] / s);
            let nu1 = r1[t] - (0..NS).map(|i| ss.c[i] * x1[i]).sum::<f64>();
            let nu0 = r0[t] - (0..NS).map(|i| ss.c[i] * x0[i]).sum::<f64>();
            llr += (nu0 * nu0 - nu1 * nu1) / (2.0 * s);
            for i in 0..NS {
                x1[i] += k[i] * nu1;
                x0[i] += k[i] * nu0;
            }
            let mut np = p;
            for i in 0..NS {
                for j in 0..NS {
                    np[i][j] -= k[i] * pc[j];
                }
            }
            p = np;
        }
        // predict: x = A x; P = A P A' + Q
        let step = |x: &[f64; NS]| -> [f64; NS] {
            std::array::from_fn(|i| (0..NS).map(|j| ss.a[i][j] * x[j]).sum())
        };
        x1 = step(&x1);
        x0 = step(&x0);
        let ap: Mat = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..NS).map(|l| ss.a[i][l] * p[l][j]).sum())
        });
        let mut np: Mat = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..NS).map(|l| ap[i][l] * ss.a[j][l]).sum())
        });
        np[3][3] += ss.q;
        p = np;
    }
    llr
}

/// The three oracles' log-likelihood ratios (sticky against healthy) on one run.
#[derive(Clone, Copy)]
struct Llr {
    known_load: f64,
    every_step: f64,
    recorded: f64,
}

fn llrs(setup: &ClosedLoop, sticky: &Model, run: &FullRun) -> Llr {
    let healthy = Model::Stenman(Stenman { d: 0.0 });
    let n = run.op.len();
    let residual = |model: &Model| -> Vec<f64> {
        let pred = replay(setup, model, run);
        run.pv.iter().zip(&pred).map(|(y, p)| y - p).collect()
    };
    let (r1, r0) = (residual(sticky), residual(&healthy));
    let sigma = setup.noise;
    // the load's response, sample by sample (the first oracle subtracts it)
    let load = setup
        .load
        .as_ref()
        .map_or_else(|| vec![0.0; n], |l| l.generate(run.dt, n));
    let g = response(&setup.process, run.dt, &load);
    let known_load = (run.warm..n)
        .map(|t| {
            let (a, b) = (r0[t] - g[t], r1[t] - g[t]);
            (a * a - b * b) / (2.0 * sigma * sigma)
        })
        .sum::<f64>();
    let in_record: Vec<bool> = (0..n).map(|t| t >= run.warm).collect();
    let mut at_samples = vec![false; n];
    for &j in &run.recorded {
        at_samples[j] = true;
    }
    // the other two know a drift's model only; a ramp (or no load) they know exactly
    let (r1, r0, kick) = match &setup.load {
        Some(Signal::IntegratedRandomWalk { slope_std, .. }) => (r1, r0, slope_std * run.dt.sqrt()),
        _ => {
            let minus = |r: &[f64]| -> Vec<f64> { r.iter().zip(&g).map(|(a, b)| a - b).collect() };
            (minus(&r1), minus(&r0), 0.0)
        }
    };
    // the filter runs from the warm-up's start (the load starts at rest); only the record counts
    let ss = state_space(&setup.process, run.dt, kick);
    Llr {
        known_load,
        every_step: kalman_llr(&ss, sigma, &r1, &r0, &in_record),
        recorded: kalman_llr(&ss, sigma, &r1, &r0, &at_samples),
    }
}

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
    fine: bool,
    sticky: Llr,
    twin: Llr,
}

fn judge(l: &BenchmarkLoop) -> Row {
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
    Row {
        class: l.class,
        fine: l.setup.ts < 5.0,
        sticky,
        twin,
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
        let ba = 0.5 * (hit.0 as f64 / hit.1.max(1) as f64 + twin.0 as f64 / twin.1.max(1) as f64);
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
    let rows: Vec<Row> = sticky.par_iter().map(|l| judge(l)).collect();
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
        "# An oracle's bound on the routine suite ({} set)\n\nGenerated by `cargo run --release -p stiction-core --example oracle_bound -- {}--out FILE`. \
         The likelihood-ratio test of an oracle that knows each loop's process, actuator lag, controller, noise, setpoint, load model and, \
         for the sticky hypothesis, the very valve; it sees OP at every controller execution (on the records of 1 s, the record's own OP). For each sticky loop and its healthy twin \
         no test has a smaller sum of the two errors, so no method that sees less can have a higher balanced accuracy on these loops \
         (up to the sampling error of a finite set); what it does not bound is the look-alikes, which are not twins. Sticky loops: the suite's Stenman, Kano and He \
         valves. Twins: each sticky loop with a healthy valve (same process, seeds and signals), judged against the sticky valve it would \
         have had. `healthy` class: judged against a valve drawn from the suite's ranges. See the example's documentation.\n",
        if set == catalogue::Set::Benchmark { "benchmark" } else { "calibration" },
        if set == catalogue::Set::Benchmark { "--benchmark " } else { "" },
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
    args.emit(&md);
}
