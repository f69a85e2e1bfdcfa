//! The fast suite (issue 14): fast loops whose sticky valve makes them limit-cycle, and the
//! look-alikes of such a cycle.
//!
//! Ranges (uniform unless said): 2,000 samples every 1, 2, 3 or 5 s; PI every 1, 2 or 3 s;
//! actuator lag 0.5-3 s; warm-up 20 min. Kinds: flow 40 % (FOPTD K 0.7-1.5, tau 2-10 s, delay
//! 0.5-3 s), pressure 30 % (K 0.5-2, tau 5-30 s, delay 1-5 s), cooling water 30 % (K 0.5-2,
//! tau 30-120 s, delay 10-40 s). OP0 25-75 %. Regulation: setpoint steps within ±0.5-2 % held
//! 20-80 % of the window, a load drift spreading 0.5-2 %.
//!
//! Tuning: SIMC with lambda 0.5-1.5 effective delays (tight: the controller pushes OP through the
//! band quickly); a third of the sticky loops are tuned as issue 14's (Ti 10-30 min, Kc 0.85-1.0
//! of the ultimate gain). Look-alikes: an external sine or narrow-band oscillation at the period
//! the same loop cycles with a sticky valve (simulated), on PV or as load; Kc 0.9-1.05 of the
//! ultimate gain (half with Ti 10-30 min); OP0 3-12 % or 88-97 % with a load oscillation 1.3-2.5
//! times the distance to the limit; a flow loop inside a cascade whose outer loop (FOPTD K
//! 0.5-1.5, tau 60-300 s, delay 10-60 s) follows setpoint steps, half of them tuned at 0.7-0.95
//! of its ultimate gain (an oscillating outer loop).

use super::draw::Draw;
use super::plant::{cycle_period, finish, load_drift, noise, valve, Built};
use super::routine::oscillation;
use super::tuning::LinearLoop;
use super::{BenchmarkLoop, Excitation, LoopClass, LoopKind, NoiseLevel, Set, Suite, Tuning};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{Cascade, ClosedLoop, Pi, Process, Signal};

const SAMPLES: usize = 2000;

fn process(kind: LoopKind, d: &mut Draw) -> Process {
    let (k, tau, delay) = match kind {
        LoopKind::Flow => ((0.7, 1.5), (2.0, 10.0), (0.5, 3.0)),
        LoopKind::Pressure => ((0.5, 2.0), (5.0, 30.0), (1.0, 5.0)),
        _ => ((0.5, 2.0), (30.0, 120.0), (10.0, 40.0)),
    };
    Process::Foptd {
        k: d.uniform(k.0, k.1),
        tau: d.uniform(tau.0, tau.1),
        delay: d.uniform(delay.0, delay.1),
    }
}

/// `Kc` a fraction of the ultimate gain at integral time `ti`.
fn at_limit(lin: &LinearLoop, ti: f64, fraction: f64) -> Option<(Pi, Tuning)> {
    let (ku, pu) = lin.ultimate(ti)?;
    Some((
        Pi {
            kc: fraction * ku,
            ti,
        },
        Tuning::Ultimate { fraction, ku, pu },
    ))
}

fn tune(class: LoopClass, lin: &LinearLoop, d: &mut Draw) -> (Pi, Tuning) {
    let theta = lin.effective_delay();
    let sticky = class.truth() == super::Truth::Sticky;
    let long_ti = d.uniform(600.0, 1800.0);
    let tuned = match class {
        LoopClass::NearUnstable => {
            let ti = if d.chance(0.5) {
                long_ti
            } else {
                lin.simc(theta).ti * d.uniform(0.5, 1.0)
            };
            at_limit(lin, ti, d.uniform(0.9, 1.05))
        }
        _ if sticky && d.chance(1.0 / 3.0) => at_limit(lin, long_ti, d.uniform(0.85, 1.0)),
        _ => None,
    };
    tuned.unwrap_or_else(|| {
        let lambda = theta * d.uniform(0.5, 1.5);
        (lin.simc(lambda), Tuning::Simc { lambda })
    })
}

/// The period the loop cycles with when its valve sticks (a Stenman band in 0.5..5 %), or 1.5
/// ultimate periods when it does not cycle.
fn sticky_period(cl: &ClosedLoop, lin: &LinearLoop, d: &mut Draw) -> f64 {
    let mut twin = cl.clone();
    twin.model = Model::Stenman(Stenman {
        d: d.log_uniform(0.5, 5.0),
    });
    let run = twin.run().expect("the twin of a valid loop is valid");
    cycle_period(&run.op, twin.ts)
        .or_else(|| lin.ultimate(cl.pi.ti).map(|u| 1.5 * u.1))
        .unwrap_or(20.0 * cl.ts)
}

fn saturate(cl: &mut ClosedLoop, window: f64, d: &mut Draw) -> String {
    let high = d.chance(0.5);
    cl.op0 = if high {
        d.uniform(88.0, 97.0)
    } else {
        d.uniform(3.0, 12.0)
    };
    let margin = if high { 100.0 - cl.op0 } else { cl.op0 };
    let amplitude = margin * d.uniform(1.3, 2.5);
    let period = d.uniform(window / 20.0, window / 5.0);
    let wave = if d.chance(0.5) {
        Signal::Sine {
            amplitude,
            period,
            offset: 0.0,
        }
    } else {
        Signal::NarrowBand {
            amplitude,
            period,
            damping: d.uniform(0.05, 0.15),
            seed: d.seed(),
        }
    };
    cl.load = Some(match cl.load.take() {
        Some(l) => Signal::Sum {
            parts: vec![l, wave],
        },
        None => wave,
    });
    format!(
        "OP near {} %, load oscillation {amplitude:.1} % over {period:.0} s",
        if high { 100 } else { 0 }
    )
}

fn cascade(cl: &mut ClosedLoop, inner_lambda: f64, window: f64, d: &mut Draw) -> String {
    let process = Process::Foptd {
        k: d.uniform(0.5, 1.5),
        tau: d.uniform(60.0, 300.0),
        delay: d.uniform(10.0, 60.0),
    };
    // the inner closed loop seen from outside: about a lag of its lambda plus its delay
    let lin = LinearLoop {
        process,
        valve_lag: inner_lambda + cl.process.delay(),
        h: cl.controller_period.unwrap_or(cl.ts),
        valve_gain: 1.0,
    };
    let theta = lin.effective_delay();
    let simc = lin.simc(theta * d.uniform(1.0, 3.0));
    let (pi, words) = match d
        .chance(0.5)
        .then(|| at_limit(&lin, simc.ti, d.uniform(0.7, 0.95)))
        .flatten()
    {
        Some((pi, Tuning::Ultimate { fraction, .. })) => {
            (pi, format!("{fraction:.2} of its ultimate gain"))
        }
        _ => (simc, "SIMC".to_string()),
    };
    let min_hold = window * d.uniform(0.1, 0.25);
    cl.cascade = Some(Cascade {
        process,
        pi,
        setpoint: Signal::RandomSteps {
            amplitude: d.uniform(1.0, 4.0),
            min_hold,
            max_hold: 2.0 * min_hold,
            offset: 50.0,
            seed: d.seed(),
        },
        noise: cl.noise / 2.0,
        disturbance: None,
    });
    format!(
        "cascade inner loop; outer FOPTD K={:.2} tau={:.0} s delay={:.0} s, PI Kc={:.3} Ti={:.0} s ({words})",
        process.gain(),
        match process {
            Process::Foptd { tau, .. } => tau,
            _ => 0.0,
        },
        process.delay(),
        pi.kc,
        pi.ti
    )
}

/// A fast loop of `class`.
pub fn build(class: LoopClass, d: &mut Draw) -> Built {
    let h = d.pick(&[1.0, 2.0, 3.0]);
    let ts = d.pick(&[1.0, 2.0, 3.0, 5.0]);
    let window = SAMPLES as f64 * ts;
    let kind = if class == LoopClass::CascadeInner {
        LoopKind::Flow
    } else {
        d.weighted(&[
            (LoopKind::Flow, 0.4),
            (LoopKind::Pressure, 0.3),
            (LoopKind::CoolingWater, 0.3),
        ])
    };
    let process = process(kind, d);
    let lag = d.uniform(0.5, 3.0);
    let noise_level = noise(d);
    let mut cl = ClosedLoop::new(valve(class, d));
    cl.process = process;
    cl.ts = ts;
    cl.samples = SAMPLES;
    cl.controller_period = Some(h);
    // the plant moves every second between controller executions
    cl.substeps = Some(h.round().max(1.0) as usize);
    cl.valve_lag = lag;
    cl.noise = noise_level.std();
    cl.seed = d.seed();
    cl.op0 = d.uniform(25.0, 75.0);
    cl.warmup = 1200.0;
    let lin = LinearLoop {
        process,
        valve_lag: lag,
        h,
        valve_gain: 1.0,
    };
    let (pi, tuning) = tune(class, &lin, d);
    cl.pi = pi;
    let min_hold = window * d.uniform(0.2, 0.4);
    cl.setpoint = Signal::RandomSteps {
        amplitude: d.uniform(0.5, 2.0),
        min_hold,
        max_hold: 2.0 * min_hold,
        offset: 50.0,
        seed: d.seed(),
    };
    cl.load = Some(load_drift(
        d.uniform(0.5, 2.0),
        cl.warmup + window,
        d.seed(),
    ));
    let mut notes = Vec::new();
    match class {
        LoopClass::ExternalOscillation => {
            let period = sticky_period(&cl, &lin, d);
            notes.push(oscillation(&mut cl, period, d));
        }
        LoopClass::SaturatedOp => notes.push(saturate(&mut cl, window, d)),
        LoopClass::CascadeInner => {
            let lambda = match tuning {
                Tuning::Simc { lambda } => lambda,
                Tuning::Ultimate { .. } => lin.effective_delay(),
            };
            cl.setpoint = Signal::Constant { value: 50.0 };
            notes.push(cascade(&mut cl, lambda, window, d));
        }
        _ => {}
    }
    Built {
        setup: cl,
        kind,
        noise_level,
        excitation: Excitation::Regulation,
        tuning,
        notes,
    }
}

/// Issue 14's example, reproduced: a cooling-water temperature under PI (every 2 s, Ti 25 min),
/// a Stenman band of 2 %, sampled every 2 s, limit-cycling with a period of about two minutes and
/// OP swinging between about 30 and 54 %.
///
/// Process `K = 1`, `tau = 80 s`, delay 30 s, actuator lag 2 s, PV noise 0.1 %; `Kc = 4.45`, which
/// is 0.996 times the linear loop's ultimate gain (4.47, ultimate period 116 s): the linear loop is
/// stable but has no margin, and the sticky valve sustains and bounds the cycle. Found by a search
/// over tau, delay, lag, controller period and Kc / Ku: with margin (Kc below about 0.95 Ku) a 2 %
/// band gives OP swings of only one to three bands (4-10 %), whatever the process; a 23 % swing
/// with a 2 % band needs the loop at its limit, and its size then depends on the noise (with
/// 0.03 % noise the same loop swings about 10 %; at Kc = 1.02 Ku and 0.1 % noise, about 50 %).
pub fn issue14_example() -> BenchmarkLoop {
    let process = Process::Foptd {
        k: 1.0,
        tau: 80.0,
        delay: 30.0,
    };
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 2.0 }));
    cl.process = process;
    cl.pi = Pi {
        kc: 4.45,
        ti: 1500.0,
    };
    cl.ts = 2.0;
    cl.samples = SAMPLES;
    cl.controller_period = Some(2.0);
    cl.valve_lag = 2.0;
    cl.op0 = 41.5;
    cl.noise = NoiseLevel::Medium.std();
    cl.seed = 1;
    cl.warmup = 1800.0;
    cl.setpoint = Signal::Step {
        from: 49.0,
        to: 50.0,
        at: 60.0,
    };
    let lin = LinearLoop {
        process,
        valve_lag: 2.0,
        h: 2.0,
        valve_gain: 1.0,
    };
    let (ku, pu) = lin
        .ultimate(1500.0)
        .expect("a FOPTD loop has an ultimate gain");
    let built = Built {
        setup: cl,
        kind: LoopKind::CoolingWater,
        noise_level: NoiseLevel::Medium,
        excitation: Excitation::Regulation,
        tuning: Tuning::Ultimate {
            fraction: 4.45 / ku,
            ku,
            pu,
        },
        notes: vec!["issue 14's example".into()],
    };
    let mut l = finish(LoopClass::StenmanValve, built, 1);
    l.id = "issue14".into();
    l.suite = Suite::Fast;
    l.set = Set::Benchmark;
    l
}
