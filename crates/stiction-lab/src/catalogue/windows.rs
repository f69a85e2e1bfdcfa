//! The plant-window suite: routine windows as a plant historian keeps them, shaped after the real
//! plant records (../shared/data/plant-dev): 750 values 10 s apart, each the mean of the loop's
//! 1-s values over its interval; PI controllers detuned the way plant loops often are (gain a
//! fraction of SIMC's, integral time many process time constants, so a stuck valve's OP winds for
//! tens of minutes); setpoints moved by operators in occasional small steps and staircases; level
//! loops near their stability limit (healthy, cycling like a sine) beside well-damped ones.

use super::draw::Draw;
use super::plant::{load_drift, noise, valve, Built};
use super::routine::oscillation;
use super::tuning::LinearLoop;
use super::{Excitation, LoopClass, LoopKind, Tuning};
use stiction_core::models::{He, Kano, Model, Stenman};
use stiction_core::sim::{ClosedLoop, Pi, Process, Signal};

const SAMPLES: usize = 750;
const TS: f64 = 10.0;

/// How a drawn loop is recorded: its samples, their spacing, and whether each is the mean of the
/// loop's 1-s values over its interval (a historian's average) or the 1-s value itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// Samples in the record.
    pub samples: usize,
    /// Seconds between them.
    pub ts: f64,
    /// Each sample the mean over its interval.
    pub average: bool,
}

/// The plant window: 750 10-s averages.
pub const WINDOW: Shape = Shape {
    samples: SAMPLES,
    ts: TS,
    average: true,
};

fn kind_of(class: LoopClass, d: &mut Draw) -> LoopKind {
    match class {
        LoopClass::SlowLongDelay => d.pick(&[LoopKind::Temperature, LoopKind::Analyser]),
        _ => d.weighted(&[
            (LoopKind::Flow, 0.5),
            (LoopKind::Level, 0.25),
            (LoopKind::Pressure, 0.25),
        ]),
    }
}

fn process(kind: LoopKind, d: &mut Draw) -> (Process, f64) {
    match kind {
        LoopKind::Flow => (
            Process::Foptd {
                k: d.log_uniform(0.3, 2.0),
                tau: d.uniform(1.0, 10.0),
                delay: d.uniform(0.5, 4.0),
            },
            d.uniform(0.5, 3.0),
        ),
        LoopKind::Pressure => (
            Process::Foptd {
                k: d.log_uniform(0.3, 2.0),
                tau: d.uniform(10.0, 60.0),
                delay: d.uniform(1.0, 10.0),
            },
            d.uniform(0.5, 2.0),
        ),
        LoopKind::Level => (
            Process::Integrating {
                k: d.log_uniform(0.0005, 0.005),
                delay: d.uniform(0.0, 10.0),
            },
            d.uniform(0.5, 3.0),
        ),
        _ => (
            Process::Soptd {
                k: d.log_uniform(0.3, 2.0),
                tau1: d.uniform(300.0, 1200.0),
                tau2: d.uniform(30.0, 150.0),
                delay: d.uniform(60.0, 300.0),
            },
            d.uniform(1.0, 4.0),
        ),
    }
}

/// Detuned PI (the plant's usual), or near the stability limit for `NearUnstable`.
fn tune(class: LoopClass, lin: &LinearLoop, d: &mut Draw) -> (Pi, Tuning) {
    let theta = lin.effective_delay();
    let window = SAMPLES as f64 * TS;
    if class == LoopClass::NearUnstable {
        let ti = lin.simc(theta * 2.0).ti * d.uniform(0.3, 1.0);
        if let Some((ku, pu)) = lin.ultimate(ti) {
            let fraction = d.uniform(0.8, 0.97);
            let pi = Pi {
                kc: fraction * ku,
                ti,
            };
            return (pi, Tuning::Ultimate { fraction, ku, pu });
        }
    }
    let integrating = lin.process.is_integrating();
    let lambda = if integrating {
        (window * d.uniform(0.005, 0.04)).max(2.0 * theta)
    } else {
        theta * d.uniform(1.0, 3.0)
    };
    let base = lin.simc(lambda);
    let (kc_factor, ti_factor) = if integrating {
        (d.log_uniform(0.3, 1.0), d.log_uniform(1.0, 4.0))
    } else {
        (d.log_uniform(0.2, 1.0), d.log_uniform(1.0, 30.0))
    };
    let pi = Pi {
        kc: base.kc * kc_factor,
        ti: base.ti * ti_factor,
    };
    (pi, Tuning::Simc { lambda })
}

/// Operator setpoint moves: a few single steps or staircases (2-4 steps the same way, a minute
/// or a few apart) at random times, each step 0.3-8 % of the PV's scale (large steps on quiet PVs are common on a real plant).
fn operator_setpoint(total: f64, warmup: f64, d: &mut Draw) -> (Signal, usize) {
    let dt = 1.0;
    let n = (total / dt) as usize + 2;
    let mut sp = vec![50.0; n];
    // as many moves per window's length in a longer record
    let windows = ((total - warmup) / (SAMPLES as f64 * TS)).round().max(1.0) as usize;
    let moves = d.pick(&[0usize, 0, 1, 1, 2, 2, 3, 4, 5]) * windows;
    let mut steps = 0;
    for _ in 0..moves {
        let mut at = warmup + d.uniform(0.0, total - warmup);
        let sign = if d.chance(0.5) { 1.0 } else { -1.0 };
        let count = d.weighted(&[(1usize, 0.55), (2, 0.2), (3, 0.15), (4, 0.1)]);
        for _ in 0..count {
            let size = sign * d.log_uniform(0.3, 8.0);
            let from = ((at / dt) as usize).min(n);
            sp[from..].iter_mut().for_each(|v| *v += size);
            steps += 1;
            at += d.uniform(30.0, 400.0);
        }
    }
    (Signal::Recorded { dt, values: sp }, steps)
}

/// The plant window's valve: the catalogue's sticky models with bands 0.3-4 % of span; a healthy
/// valve with a band under 0.25 %.
fn plant_valve(class: LoopClass, d: &mut Draw) -> Model {
    let band = d.log_uniform(0.3, 4.0);
    match class {
        LoopClass::StenmanValve => Model::Stenman(Stenman { d: band }),
        LoopClass::KanoValve => Model::Kano(Kano {
            s: band,
            j: band * d.uniform(0.2, 0.9),
        }),
        LoopClass::HeValve => Model::He(He {
            fs: band,
            fd: band * d.uniform(0.1, 0.7),
        }),
        // a healthy plant valve is not frictionless: a band of up to a quarter per cent of span,
        // which no one calls sticky (real healthy windows' fits find 0.1-0.6 %)
        _ => match valve(class, d) {
            Model::Stenman(v) if v.d == 0.0 => Model::Stenman(Stenman {
                d: d.uniform(0.0, 0.25),
            }),
            other => other,
        },
    }
}

/// A plant window of `class`.
pub fn build(class: LoopClass, d: &mut Draw) -> Built {
    build_shaped(class, d, WINDOW)
}

/// A loop of `class` drawn as a plant window's is (the same processes, tunings and operators),
/// recorded as `shape` says: a day at 1 s is `Shape { samples: 86_400, ts: 1.0, average: false }`.
pub fn build_shaped(class: LoopClass, d: &mut Draw, shape: Shape) -> Built {
    // the draws (tuning, periods, holds) read the plant window's length, whatever the record's
    let window = SAMPLES as f64 * TS;
    let record = shape.samples as f64 * shape.ts;
    let kind = kind_of(class, d);
    let (process, lag) = process(kind, d);
    let noise_level = noise(d);
    let mut cl = ClosedLoop::new(plant_valve(class, d));
    cl.process = process;
    cl.ts = shape.ts;
    cl.samples = shape.samples;
    cl.controller_period = Some(1.0);
    cl.substeps = Some(1);
    cl.valve_lag = lag;
    // raw 1-s noise; the 10-s means carry about a third of it
    cl.noise = noise_level.std() * d.uniform(1.0, 3.0);
    cl.historian.average = shape.average;
    cl.seed = d.seed();
    cl.op0 = d.uniform(15.0, 85.0);
    cl.warmup = window / 4.0;
    let lin = LinearLoop {
        process,
        valve_lag: lag,
        h: 1.0,
        valve_gain: 1.0,
    };
    let (pi, tuning) = tune(class, &lin, d);
    cl.pi = pi;
    let total = cl.warmup + record;
    let (setpoint, steps) = operator_setpoint(total, cl.warmup, d);
    cl.setpoint = setpoint;
    // loads drift less on the real plant's healthy windows than in the routine suite: OP winds
    // there mostly where a valve sticks (OP's travel over PV held level, real vs simulated)
    let drift = d.chance(0.4);
    if drift {
        cl.load = Some(load_drift(d.uniform(0.2, 2.0), total, d.seed()));
    }
    let mut excitation = match (steps > 0, drift) {
        (true, true) => Excitation::StepsAndDrift,
        (true, false) => Excitation::SetpointSteps,
        (false, _) => Excitation::LoadDrift,
    };
    let mut notes = vec![format!(
        "operator setpoint: {steps} steps; detuned PI; 10-s averages of 1-s values"
    )];
    match class {
        LoopClass::ExternalOscillation => {
            let period = d.log_uniform(60.0, window / 6.0);
            notes.push(oscillation(&mut cl, period, d));
        }
        LoopClass::LoadSteps | LoopClass::FeedForward => {
            let amplitude = d.uniform(1.0, 6.0);
            let min_hold = window * d.uniform(0.05, 0.12);
            cl.load = Some(Signal::RandomSteps {
                amplitude,
                min_hold,
                max_hold: min_hold * d.uniform(1.5, 3.0),
                offset: 0.0,
                seed: d.seed(),
            });
            if class == LoopClass::FeedForward {
                cl.feed_forward = Some(d.uniform(0.7, 1.1));
            }
            notes.push(format!("load steps within ±{amplitude:.1} %"));
            excitation = excitation.with_load_steps();
        }
        _ => {}
    }
    Built {
        setup: cl,
        kind,
        noise_level,
        excitation,
        tuning,
        notes,
    }
}
