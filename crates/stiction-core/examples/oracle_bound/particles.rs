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
use stiction_core::rng::{gaussian, seeded};
use stiction_core::sim::{ClosedLoop, Plan, ProcessState, ValveLag};

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

/// What a step of the loop needs besides the particle.
struct Step<'a> {
    dt: f64,
    t: usize,
    j1: usize,
    sp: &'a [f64],
    dist: &'a [f64],
    load: &'a [f64],
    pv0: f64,
    kc: f64,
    ki: f64,
    nd: usize,
    x0: f64,
    flow0: f64,
    setup: &'a ClosedLoop,
    model: &'a Model,
}

/// The sum of the process outputs from step `t` to the step before `j1`, the particle run on
/// with every measurement noise `noise`.
fn predicted_outputs(p: &Particle, s: &Step, noise: f64) -> f64 {
    let mut q = p.clone();
    let mut sum = 0.0;
    for k in s.t..s.j1 {
        let y = q.process.output();
        sum += y;
        let e = s.sp[k] - (s.pv0 + y + s.dist[k] + noise);
        if k > 0 {
            q.op = (q.op + s.kc * (e - q.e) + s.ki * e).clamp(0.0, 100.0);
            q.stem = s.model.step(&mut q.valve, q.op);
        }
        q.e = e;
        let mv = if k == 0 { s.x0 } else { q.lag.step(q.stem) };
        q.ring.rotate_right(1);
        q.ring[0] = mv;
        let position = if k >= s.nd { q.ring[s.nd] } else { s.x0 };
        q.process
            .advance(s.setup.characteristic.flow(position) - s.flow0 + s.load[k] + q.level);
        q.level += q.slope * s.dt;
    }
    sum
}

const LN_2PI: f64 = 1.837_877_066_409_345_4;

fn ln_normal(x: f64, var: f64) -> f64 {
    -0.5 * (LN_2PI + var.ln() + x * x / var)
}

/// A record's increment of the log-likelihood under which the filter has lost track: every
/// particle about 10 noise standard deviations from the recorded PV.
const LOST: f64 = -50.0;

/// The filter's estimate.
pub struct Filtered {
    pub log_likelihood: f64,
    /// The share of records at which every particle had lost track of PV ([`LOST`]): the
    /// estimate is then not to be trusted (a limit cycle with little noise, whose slips no
    /// particle follows).
    pub lost: f64,
}

/// The log-likelihood of the record (`op`, `pv` at the plan's recorded steps) under the valve
/// `model`, by a particle filter of `n` particles; `None` where the plant is stepped more than
/// once per controller execution, the loop is a cascade's inner loop or the noise is zero.
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
    let steps = plan.steps;
    let dt = plan.dt;
    let sp = setup.setpoint.generate(dt, steps);
    let dist = setup
        .disturbance
        .as_ref()
        .map(|d| d.generate(dt, steps))
        .unwrap_or_else(|| vec![0.0; steps]);
    let mut load = setup
        .load
        .as_ref()
        .map(|d| d.generate(dt, steps))
        .unwrap_or_else(|| vec![0.0; steps]);
    // a drift's model instead of its path: each particle carries a level and a slope
    let drift = match &setup.load {
        Some(stiction_core::sim::Signal::IntegratedRandomWalk {
            slope_std, offset, ..
        }) if !load_known => {
            load.iter_mut().for_each(|v| *v = 0.0);
            Some((*offset, slope_std * dt.sqrt()))
        }
        _ => None,
    };
    let nd = (setup.process.delay() / dt).round() as usize;
    let pv0 = sp.first().copied().unwrap_or(0.0);
    let (valve, x0) = model.start(setup.op0);
    let flow0 = setup.characteristic.flow(x0);
    let (kc, ki) = (setup.pi.kc, setup.pi.kc * plan.h / setup.pi.ti);
    let var = setup.noise * setup.noise;
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
    // suffix sums of the known part of the error, `sp - pv0 - dist`
    let mut known = vec![0.0; steps + 1];
    for t in (0..steps).rev() {
        known[t] = known[t + 1] + sp[t] - pv0 - dist[t];
    }
    let start = Particle {
        process: setup.process.discretise(dt),
        valve,
        lag: ValveLag::new(setup.valve_lag, dt, x0),
        op: setup.op0,
        e: 0.0,
        stem: x0,
        ring: vec![x0; nd + 1],
        esum: 0.0,
        level: 0.0,
        slope: 0.0,
    };
    let mut start = start;
    if let Some((offset, _)) = drift {
        start.level = offset;
    }
    let mut ps = vec![start; n];
    let mut logw = vec![0.0; n];
    let mut rng = seeded(seed);
    let mut total = 0.0;
    let mut lost = 0usize;
    // the errors' sum between the last record and the next (set at each record)
    let mut target_sum = f64::NAN;
    let mut last_record: Option<usize> = None;
    for t in 0..steps {
        let rec = rec_at[t];
        let j1 = next[t];
        let bridged = rec.is_none() && last_record.is_some() && j1 != usize::MAX;
        for (p, w) in ps.iter_mut().zip(logw.iter_mut()) {
            let y = p.process.output();
            let noise = if let Some(j) = rec {
                let v = pv[j] - (pv0 + y + dist[t]);
                *w += ln_normal(v, var);
                v
            } else if bridged {
                let r = j1 - t;
                let remaining = target_sum - p.esum;
                // sum of the noises still to come so that the errors sum to the target: the
                // process output predicted by running the particle on to the next record with
                // each noise at the sum's share (from the output held at y), then its last
                // noise closes the sum exactly
                let held = (known[t] - known[j1]) - r as f64 * y - remaining;
                let total_noise = if r > 1 {
                    let ys = predicted_outputs(
                        p,
                        &Step {
                            dt,
                            t,
                            j1,
                            sp: &sp,
                            dist: &dist,
                            load: &load,
                            pv0,
                            kc,
                            ki,
                            nd,
                            x0,
                            flow0,
                            setup,
                            model,
                        },
                        held / r as f64,
                    );
                    (known[t] - known[j1]) - ys - remaining
                } else {
                    held
                };
                if r > 1 {
                    let mean = total_noise / r as f64;
                    let pvar = var * (1.0 - 1.0 / r as f64);
                    let v = mean + pvar.sqrt() * gaussian(&mut rng);
                    *w += ln_normal(v, var) - ln_normal(v - mean, pvar);
                    v
                } else {
                    *w += ln_normal(total_noise, var);
                    total_noise
                }
            } else {
                setup.noise * gaussian(&mut rng)
            };
            let e = sp[t] - (pv0 + y + dist[t] + noise);
            if t > 0 {
                p.op = (p.op + kc * (e - p.e) + ki * e).clamp(0.0, 100.0);
                p.stem = model.step(&mut p.valve, p.op);
            }
            p.e = e;
            if bridged {
                p.esum += e;
            }
            if let Some(j) = rec {
                // the bridge lands OP on the record unless OP was clamped on the way
                let miss = p.op - op[j];
                if miss.abs() > 1e-6 {
                    *w += ln_normal(miss, 0.05 * 0.05) - ln_normal(0.0, 0.05 * 0.05);
                }
                p.op = op[j];
                p.esum = 0.0;
            }
            let mv = if t == 0 { x0 } else { p.lag.step(p.stem) };
            p.ring.rotate_right(1);
            p.ring[0] = mv;
            let position = if t >= nd { p.ring[nd] } else { x0 };
            p.process
                .advance(setup.characteristic.flow(position) - flow0 + load[t] + p.level);
            if let Some((_, kick)) = drift {
                p.level += p.slope * dt;
                p.slope += kick * gaussian(&mut rng);
            }
        }
        if let Some(j) = rec {
            let top = logw.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if !top.is_finite() {
                return None;
            }
            let sum: f64 = logw.iter().map(|w| (w - top).exp()).sum();
            let increment = top + (sum / n as f64).ln();
            total += increment;
            // every particle 10 noise standard deviations or more away from the record
            lost += usize::from(increment < LOST);
            // systematic resampling
            let weights: Vec<f64> = logw.iter().map(|w| (w - top).exp() / sum).collect();
            let u0: f64 = rng.random::<f64>() / n as f64;
            let mut out = Vec::with_capacity(n);
            let (mut c, mut i) = (weights[0], 0);
            for k in 0..n {
                let u = u0 + k as f64 / n as f64;
                while u > c && i + 1 < n {
                    i += 1;
                    c += weights[i];
                }
                out.push(ps[i].clone());
            }
            ps = out;
            logw.iter_mut().for_each(|w| *w = 0.0);
            // the errors between this record and the next must sum to C
            if let Some(&j2) = plan.recorded.get(j + 1) {
                let e0 = sp[t] - pv[j];
                let e1 = sp[j2] - pv[j + 1];
                target_sum = (op[j + 1] - op[j] - kc * (e1 - e0)) / ki - e1;
            }
            last_record = Some(t);
        }
    }
    Some(Filtered {
        log_likelihood: total,
        lost: lost as f64 / plan.recorded.len().max(1) as f64,
    })
}
