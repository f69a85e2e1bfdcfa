//! The oracle that sees OP and PV only at the recorded samples and treats what happens between
//! them as hidden: a particle filter over the whole simulated loop (process, valve, actuator lag,
//! controller), driven by the measurement noise the controller saw at each execution, with
//! everything else known (process, controller, noise, setpoint, the load's path, the valve model).
//!
//! Between two records the controller's integral action ties the errors it saw to the two
//! recorded OPs: with `e = SP - PV` and the velocity PI
//! `op[k] = op[k-1] + Kc (e[k] - e[k-1]) + Ki e[k]`, the errors at the unrecorded executions sum
//! to `C = (op[j1] - op[j0] - Kc (e[j1] - e[j0])) / Ki - e[j1]`. Each particle draws its noises
//! from a Gaussian bridge towards that sum (the process outputs to come predicted by running the
//! particle on to the next record) and is weighted by the noise density over the proposal's; the last noise closes
//! the sum, so the particle's OP lands on the recorded one. At a record the noise is PV's
//! recorded value less the particle's PV. The log-likelihood is summed over the records, the
//! particles resampled at each. Loops whose plant is stepped more than once per controller
//! execution are left out (8 of the calibration set's 40 Stenman loops of 10 s, whose controller
//! runs every 2 s).

use rand::RngExt;
use stiction_core::models::{Model, ModelState};
use stiction_core::rng::{gaussian, seeded, Rng};
use stiction_core::sim::{ClosedLoop, Plan, ProcessState, Signal, ValveLag};

#[derive(Clone)]
struct Particle {
    process: ProcessState,
    valve: ModelState,
    lag: ValveLag,
    op: f64,
    e: f64,
    stem: f64,
    /// Valve positions, a ring of the last `nd + 1`.
    ring: Vec<f64>,
    /// Errors summed since the last record.
    esum: f64,
    /// The load's level and slope, where the filter knows only its model.
    level: f64,
    slope: f64,
}

/// The loop as the filter knows it: signals at every plant step and the constants of a step.
struct Loop<'a> {
    setup: &'a ClosedLoop,
    model: &'a Model,
    dt: f64,
    sp: Vec<f64>,
    dist: Vec<f64>,
    /// The load's path, or zeros where the particles carry a drift's level and slope.
    load: Vec<f64>,
    /// A drift's kick per step, where the particles carry it.
    kick: Option<f64>,
    pv0: f64,
    kc: f64,
    ki: f64,
    nd: usize,
    x0: f64,
    flow0: f64,
    var: f64,
    /// Suffix sums of the error's known part, `sp - pv0 - dist`.
    known: Vec<f64>,
}

impl<'a> Loop<'a> {
    fn new(setup: &'a ClosedLoop, model: &'a Model, plan: &Plan, load_known: bool) -> Self {
        let (steps, dt) = (plan.steps, plan.dt);
        let path = |s: &Option<Signal>| {
            s.as_ref()
                .map(|d| d.generate(dt, steps))
                .unwrap_or_else(|| vec![0.0; steps])
        };
        let sp = setup.setpoint.generate(dt, steps);
        let dist = path(&setup.disturbance);
        let drift = match &setup.load {
            Some(Signal::IntegratedRandomWalk { slope_std, .. }) if !load_known => {
                Some(slope_std * dt.sqrt())
            }
            _ => None,
        };
        let load = if drift.is_some() {
            vec![0.0; steps]
        } else {
            path(&setup.load)
        };
        let pv0 = sp.first().copied().unwrap_or(0.0);
        let mut known = vec![0.0; steps + 1];
        for t in (0..steps).rev() {
            known[t] = known[t + 1] + sp[t] - pv0 - dist[t];
        }
        let x0 = model.start(setup.op0).1;
        Self {
            setup,
            model,
            dt,
            sp,
            dist,
            load,
            kick: drift,
            pv0,
            kc: setup.pi.kc,
            ki: setup.pi.kc * plan.h / setup.pi.ti,
            nd: (setup.process.delay() / dt).round() as usize,
            x0,
            flow0: setup.characteristic.flow(x0),
            var: setup.noise * setup.noise,
            known,
        }
    }

    fn start(&self) -> Particle {
        let (valve, x0) = self.model.start(self.setup.op0);
        Particle {
            process: self.setup.process.discretise(self.dt),
            valve,
            lag: ValveLag::new(self.setup.valve_lag, self.dt, x0),
            op: self.setup.op0,
            e: 0.0,
            stem: x0,
            ring: vec![x0; self.nd + 1],
            esum: 0.0,
            level: match &self.setup.load {
                Some(Signal::IntegratedRandomWalk { offset, .. }) if self.kick.is_some() => *offset,
                _ => 0.0,
            },
            slope: 0.0,
        }
    }

    /// The error the controller sees at step `t` with measurement noise `noise`.
    fn error(&self, p: &Particle, t: usize, noise: f64) -> f64 {
        self.sp[t] - (self.pv0 + p.process.output() + self.dist[t] + noise)
    }

    /// One plant step after the measurement: the controller acts on `e`, the valve and its lag
    /// follow, the process advances (the drift's slope is kicked by the caller).
    fn advance(&self, p: &mut Particle, t: usize, e: f64) {
        if t > 0 {
            p.op = (p.op + self.kc * (e - p.e) + self.ki * e).clamp(0.0, 100.0);
            p.stem = self.model.step(&mut p.valve, p.op);
        }
        p.e = e;
        let mv = if t == 0 { self.x0 } else { p.lag.step(p.stem) };
        p.ring.rotate_right(1);
        p.ring[0] = mv;
        let position = if t >= self.nd {
            p.ring[self.nd]
        } else {
            self.x0
        };
        let flow = self.setup.characteristic.flow(position) - self.flow0;
        p.process.advance(flow + self.load[t] + p.level);
        p.level += p.slope * self.dt;
    }

    /// The sum of the process outputs from step `t` to the step before `j1`, the particle run
    /// on with every measurement noise `noise`.
    fn predicted_outputs(&self, p: &Particle, t: usize, j1: usize, noise: f64) -> f64 {
        let mut q = p.clone();
        let mut sum = 0.0;
        for k in t..j1 {
            sum += q.process.output();
            let e = self.error(&q, k, noise);
            self.advance(&mut q, k, e);
        }
        sum
    }

    /// The noise at an unrecorded step `t` between records, drawn from the bridge towards the
    /// errors' sum `target` by the next record `j1`, and its log weight.
    fn bridge(&self, p: &Particle, t: usize, j1: usize, target: f64, rng: &mut Rng) -> (f64, f64) {
        let r = j1 - t;
        let remaining = target - p.esum;
        let known = self.known[t] - self.known[j1];
        // the noises still to come must sum to this for the errors to reach the target: the
        // process outputs predicted by running the particle on with each noise at its share
        // (from the output held), the last noise closing the sum exactly
        let held = known - r as f64 * p.process.output() - remaining;
        if r == 1 {
            return (held, ln_normal(held, self.var));
        }
        let ys = self.predicted_outputs(p, t, j1, held / r as f64);
        let mean = (known - ys - remaining) / r as f64;
        let pvar = self.var * (1.0 - 1.0 / r as f64);
        let v = mean + pvar.sqrt() * gaussian(rng);
        (v, ln_normal(v, self.var) - ln_normal(v - mean, pvar))
    }
}

const LN_2PI: f64 = 1.837_877_066_409_345_4;

fn ln_normal(x: f64, var: f64) -> f64 {
    -0.5 * (LN_2PI + var.ln() + x * x / var)
}

/// A record's increment of the log-likelihood under which the filter has lost track: every
/// particle about 10 noise standard deviations from the recorded PV.
const LOST: f64 = -50.0;
/// How far a particle's OP may miss the record (clamped at a limit between records), OP units.
const OP_MISS: f64 = 0.05;

/// The filter's estimate.
pub struct Filtered {
    pub log_likelihood: f64,
    /// The share of records at which every particle had lost track of PV ([`LOST`]): the
    /// estimate is then not to be trusted (a limit cycle with little noise, whose slips no
    /// particle follows).
    pub lost: f64,
}

/// Systematic resampling of `ps` by the log weights `logw` (reset to 0); the mean weight's log.
fn resample(ps: &mut Vec<Particle>, logw: &mut [f64], rng: &mut Rng) -> Option<f64> {
    let n = ps.len();
    let top = logw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !top.is_finite() {
        return None;
    }
    let sum: f64 = logw.iter().map(|w| (w - top).exp()).sum();
    let u0: f64 = rng.random::<f64>() / n as f64;
    let mut out = Vec::with_capacity(n);
    let (mut c, mut i) = ((logw[0] - top).exp() / sum, 0);
    for k in 0..n {
        let u = u0 + k as f64 / n as f64;
        while u > c && i + 1 < n {
            i += 1;
            c += (logw[i] - top).exp() / sum;
        }
        out.push(ps[i].clone());
    }
    *ps = out;
    logw.iter_mut().for_each(|w| *w = 0.0);
    Some(top + (sum / n as f64).ln())
}

/// The log-likelihood of the record (`op`, `pv` at the plan's recorded steps) under the valve
/// `model`, by a particle filter of `n` particles, with the load's path known or (a drift) only
/// its model; `None` where the plant is stepped more than once per controller execution, the
/// loop is a cascade's inner loop or the noise is zero.
pub fn log_likelihood(
    setup: &ClosedLoop,
    model: &Model,
    op: &[f64],
    pv: &[f64],
    n: usize,
    seed: u64,
    load_known: bool,
) -> Option<Filtered> {
    let plan = Plan::new(setup);
    if plan.substeps != 1 || setup.noise <= 0.0 || setup.cascade.is_some() {
        return None;
    }
    let lp = Loop::new(setup, model, &plan, load_known);
    let steps = plan.steps;
    // the record at each step, and the next record's step
    let mut rec_at = vec![None; steps];
    for (j, &s) in plan.recorded.iter().enumerate() {
        rec_at[s] = Some(j);
    }
    let mut next = vec![usize::MAX; steps];
    let mut upcoming = usize::MAX;
    for t in (0..steps).rev() {
        if rec_at[t].is_some() {
            upcoming = t;
        }
        next[t] = upcoming;
    }
    let mut ps = vec![lp.start(); n];
    let mut logw = vec![0.0; n];
    let mut rng = seeded(seed);
    let (mut total, mut lost) = (0.0, 0usize);
    // the errors' sum between the last record and the next (set at each record)
    let mut target = None;
    for t in 0..steps {
        let rec = rec_at[t];
        let bridged = target.filter(|_| rec.is_none() && next[t] != usize::MAX);
        for (p, w) in ps.iter_mut().zip(logw.iter_mut()) {
            let noise = match (rec, bridged) {
                (Some(j), _) => {
                    let v = pv[j] - (lp.pv0 + p.process.output() + lp.dist[t]);
                    *w += ln_normal(v, lp.var);
                    v
                }
                (None, Some(sum)) => {
                    let (v, lw) = lp.bridge(p, t, next[t], sum, &mut rng);
                    *w += lw;
                    v
                }
                (None, None) => setup.noise * gaussian(&mut rng),
            };
            let e = lp.error(p, t, noise);
            lp.advance(p, t, e);
            if bridged.is_some() {
                p.esum += e;
            }
            if let Some(j) = rec {
                // the bridge lands OP on the record unless OP was clamped on the way
                let miss = p.op - op[j];
                *w += ln_normal(miss, OP_MISS * OP_MISS) - ln_normal(0.0, OP_MISS * OP_MISS);
                p.op = op[j];
                p.esum = 0.0;
            }
            if let Some(kick) = lp.kick {
                p.slope += kick * gaussian(&mut rng);
            }
        }
        if let Some(j) = rec {
            let increment = resample(&mut ps, &mut logw, &mut rng)?;
            total += increment;
            lost += usize::from(increment < LOST);
            // the errors between this record and the next sum to C (the module's docs)
            target = plan.recorded.get(j + 1).map(|&j2| {
                let (e0, e1) = (lp.sp[t] - pv[j], lp.sp[j2] - pv[j + 1]);
                (op[j + 1] - op[j] - lp.kc * (e1 - e0)) / lp.ki - e1
            });
        }
    }
    Some(Filtered {
        log_likelihood: total,
        lost: lost as f64 / plan.recorded.len().max(1) as f64,
    })
}
