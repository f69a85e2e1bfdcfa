//! The oracles' likelihoods: the loop run at full rate, replayed with a valve model, and the
//! Kalman filter over the load.

use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, Plan, Process, Signal, ValveLag};

/// The full-rate run of a loop: every plant step from the start of the warm-up.
pub struct FullRun {
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
    /// The plant step of the record's first sample.
    pub warm: usize,
    /// The plant steps the historian recorded.
    pub recorded: Vec<usize>,
    pub dt: f64,
    /// Plant steps per controller execution.
    pub m: usize,
}

impl FullRun {
    /// The same run with OP replaced (as a method that sees less of it would have it).
    pub fn with_op(&self, op: Vec<f64>) -> FullRun {
        FullRun {
            op,
            pv: self.pv.clone(),
            warm: self.warm,
            recorded: self.recorded.clone(),
            dt: self.dt,
            m: self.m,
        }
    }
}

pub fn full_run(setup: &ClosedLoop) -> FullRun {
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
pub(super) fn replay(setup: &ClosedLoop, model: &Model, run: &FullRun) -> Vec<f64> {
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
pub(super) fn response(p: &Process, dt: f64, u: &[f64]) -> Vec<f64> {
    let mut s = p.discretise(dt);
    u.iter()
        .map(|&x| {
            let y = s.output();
            s.advance(x);
            y
        })
        .collect()
}

pub(super) const NS: usize = 4;
pub(super) type Mat = [[f64; NS]; NS];

/// The linear model of the load's effect on PV: state `[x1, x2, level, slope]` (the process's
/// states, the load's level and slope), `x' = A x + w` with `w` on the slope only, PV's share
/// `c x`.
pub(super) struct LoadStateSpace {
    pub a: Mat,
    pub c: [f64; NS],
    pub q: f64,
}

pub(super) fn state_space(p: &Process, dt: f64, kick: f64) -> LoadStateSpace {
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
pub struct Llr {
    pub known_load: f64,
    pub every_step: f64,
    pub recorded: f64,
}

pub fn llrs(setup: &ClosedLoop, sticky: &Model, run: &FullRun) -> Llr {
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
