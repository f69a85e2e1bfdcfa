//! The routine suite (issue 10): historian windows of loops in ordinary operation.
//!
//! Ranges (uniform unless said): record 750 samples every 10 s or 2,000 every 1 s (even odds);
//! warm-up a quarter of the window (at least 10 min). Kinds: flow 30 %, pressure 25 %, level 25 %,
//! temperature 20 %:
//! - flow: FOPTD K 0.7-1.5, tau 2-8 s, delay 0.5-2 s, controller 1 s, actuator lag 0.3-1.5 s;
//! - pressure: FOPTD K 0.5-2, tau 10-40 s, delay 1-5 s, controller 1 s, lag 0.5-2 s;
//! - level: integrating K 0.002-0.02 %/s per %, delay 0-5 s, controller 1 s, lag 0.5-3 s;
//! - temperature: SOPTD K 0.5-2, tau1 60-300 s, tau2 10-40 s, delay 10-60 s (10 s records) or
//!   tau1 30-120 s, tau2 5-20 s, delay 5-20 s (1 s records), controller 2 s, lag 1-4 s;
//! - slow with long delay (temperature or analyser): SOPTD tau1 600-1500 s, tau2 60-200 s, delay
//!   120-400 s (10 s records) or tau1 150-400 s, tau2 20-60 s, delay 40-120 s (1 s records).
//!
//! Tuning SIMC with lambda 1-3 effective delays (level: 1-4 % of the window, at least two
//! effective delays); aggressive tuning: Ti half to one SIMC Ti, Kc 0.55-0.8 of the ultimate gain.
//! Excitation: setpoint steps within ±1-5 % held 5-12 % of the window and up to three times
//! that (30 %), a load drift spreading 2-6 % (25 %), a load ramp of 2-8 % over the window (20 %),
//! steps and drift (25 %). OP0 25-75 %. Load steps (a look-alike): the load, in place of any
//! drift or ramp, steps within ±2-8 % and holds 5-12 % of the window and up to three times that.

use super::draw::Draw;
use super::plant::{load_drift, noise, valve, Built};
use super::tuning::LinearLoop;
use super::{Excitation, LoopClass, LoopKind, Tuning};
use stiction_core::sim::{
    Characteristic, ClosedLoop, Compression, CompressionMethod, Process, Quantisation, QuantiseAt,
    Reconstruction, Signal,
};

/// Process, controller period and actuator lag of a loop kind.
fn process(kind: LoopKind, slow: bool, fine: bool, d: &mut Draw) -> (Process, f64, f64) {
    let soptd = |d: &mut Draw, t1: (f64, f64), t2: (f64, f64), th: (f64, f64)| Process::Soptd {
        k: d.uniform(0.5, 2.0),
        tau1: d.uniform(t1.0, t1.1),
        tau2: d.uniform(t2.0, t2.1),
        delay: d.uniform(th.0, th.1),
    };
    match kind {
        _ if slow => {
            let p = if fine {
                soptd(d, (150.0, 400.0), (20.0, 60.0), (40.0, 120.0))
            } else {
                soptd(d, (600.0, 1500.0), (60.0, 200.0), (120.0, 400.0))
            };
            (p, 2.0, d.uniform(1.0, 4.0))
        }
        LoopKind::Flow => {
            let p = Process::Foptd {
                k: d.uniform(0.7, 1.5),
                tau: d.uniform(2.0, 8.0),
                delay: d.uniform(0.5, 2.0),
            };
            (p, 1.0, d.uniform(0.3, 1.5))
        }
        LoopKind::Pressure => {
            let p = Process::Foptd {
                k: d.uniform(0.5, 2.0),
                tau: d.uniform(10.0, 40.0),
                delay: d.uniform(1.0, 5.0),
            };
            (p, 1.0, d.uniform(0.5, 2.0))
        }
        LoopKind::Level => {
            let p = Process::Integrating {
                k: d.log_uniform(0.002, 0.02),
                delay: d.uniform(0.0, 5.0),
            };
            (p, 1.0, d.uniform(0.5, 3.0))
        }
        _ => {
            let p = if fine {
                soptd(d, (30.0, 120.0), (5.0, 20.0), (5.0, 20.0))
            } else {
                soptd(d, (60.0, 300.0), (10.0, 40.0), (10.0, 60.0))
            };
            (p, 2.0, d.uniform(1.0, 4.0))
        }
    }
}

fn tune(
    class: LoopClass,
    lin: &LinearLoop,
    window: f64,
    d: &mut Draw,
) -> (stiction_core::sim::Pi, Tuning) {
    let theta = lin.effective_delay();
    if class == LoopClass::AggressiveTuning {
        let ti = lin.simc(theta).ti * d.uniform(0.5, 1.0);
        if let Some((ku, pu)) = lin.ultimate(ti) {
            let fraction = d.uniform(0.55, 0.8);
            let pi = stiction_core::sim::Pi {
                kc: fraction * ku,
                ti,
            };
            return (pi, Tuning::Ultimate { fraction, ku, pu });
        }
    }
    let lambda = if lin.process.is_integrating() {
        (window * d.uniform(0.01, 0.04)).max(2.0 * theta)
    } else {
        theta * d.uniform(1.0, 3.0)
    };
    (lin.simc(lambda), Tuning::Simc { lambda })
}

/// Setpoint and load signals; the loop's signals start at the warm-up's beginning.
fn excite(cl: &mut ClosedLoop, window: f64, d: &mut Draw) -> Excitation {
    use Excitation::*;
    let e = d.weighted(&[
        (SetpointSteps, 0.3),
        (LoadDrift, 0.25),
        (LoadRamp, 0.2),
        (StepsAndDrift, 0.25),
    ]);
    let total = cl.warmup + window;
    if matches!(e, SetpointSteps | StepsAndDrift) {
        let min_hold = window * d.uniform(0.05, 0.12);
        cl.setpoint = Signal::RandomSteps {
            amplitude: d.uniform(1.0, 5.0),
            min_hold,
            max_hold: min_hold * d.uniform(1.5, 3.0),
            offset: 50.0,
            seed: d.seed(),
        };
    } else {
        cl.setpoint = Signal::Constant { value: 50.0 };
    }
    cl.load = match e {
        LoadDrift | StepsAndDrift => Some(load_drift(d.uniform(2.0, 6.0), total, d.seed())),
        LoadRamp => {
            let sign = if d.chance(0.5) { 1.0 } else { -1.0 };
            Some(Signal::Ramp {
                slope: sign * d.uniform(2.0, 8.0) / window,
                start: cl.warmup + window * d.uniform(0.0, 0.3),
                offset: 0.0,
            })
        }
        _ => None,
    };
    e
}

/// The look-alikes' own settings; returns them in words.
fn look_alike(class: LoopClass, cl: &mut ClosedLoop, window: f64, d: &mut Draw) -> Vec<String> {
    let mut notes = Vec::new();
    match class {
        LoopClass::QuantisedPv => {
            let step = d.uniform(0.1, 0.5).max(cl.noise * d.uniform(1.0, 2.0));
            let at = if d.chance(0.5) {
                QuantiseAt::Sensor
            } else {
                QuantiseAt::Historian
            };
            cl.quantisation = Some(Quantisation { step, at });
            notes.push(format!("PV quantised to {step:.2} % ({at:?})").to_lowercase());
        }
        LoopClass::CompressedPv => {
            let method = d.pick(&[CompressionMethod::SwingingDoor, CompressionMethod::Deadband]);
            let reconstruction = if d.chance(0.7) {
                Reconstruction::Linear
            } else {
                Reconstruction::Hold
            };
            let deviation = d.uniform(0.1, 0.5).max(cl.noise * d.uniform(2.0, 4.0));
            cl.historian.pv = Some(Compression {
                method,
                deviation,
                reconstruction,
            });
            let mut note =
                format!("PV {method:?} compression {deviation:.2} %, {reconstruction:?}");
            if d.chance(0.3) {
                let deviation = d.uniform(0.2, 1.0);
                cl.historian.op = Some(Compression {
                    method,
                    deviation,
                    reconstruction,
                });
                note.push_str(&format!(", OP too ({deviation:.2} %)"));
            }
            notes.push(note.to_lowercase());
        }
        LoopClass::LoadSteps => notes.push(load_steps(cl, window, d)),
        LoopClass::FeedForward => {
            let steps = load_steps(cl, window, d);
            let gain = d.uniform(0.7, 1.1);
            cl.feed_forward = Some(gain);
            notes.push(format!(
                "{steps}, {:.0} % of them fed forward to OP",
                100.0 * gain
            ));
        }
        LoopClass::ExternalOscillation => {
            let lo = (8.0 * cl.ts).max(30.0);
            let period = d.log_uniform(lo, window / 6.0);
            notes.push(oscillation(cl, period, d));
        }
        _ => {}
    }
    notes
}

/// A load that jumps in steps OP does not explain (held 5-12 % of the `window`, seconds, each
/// hold up to 1.5-3 times the shortest), in place of any other load; returns it in words.
fn load_steps(cl: &mut ClosedLoop, window: f64, d: &mut Draw) -> String {
    let amplitude = d.uniform(2.0, 8.0);
    let min_hold = window * d.uniform(0.05, 0.12);
    cl.load = Some(Signal::RandomSteps {
        amplitude,
        min_hold,
        max_hold: min_hold * d.uniform(1.5, 3.0),
        offset: 0.0,
        seed: d.seed(),
    });
    format!(
        "load steps within ±{amplitude:.1} % held {:.0}-{:.0} min, in place of any other load",
        min_hold / 60.0,
        min_hold * 3.0 / 60.0
    )
}

/// An external oscillation of `period` seconds as a sine or narrow-band noise, entering as a load
/// or on PV; returns it in words.
pub fn oscillation(cl: &mut ClosedLoop, period: f64, d: &mut Draw) -> String {
    let as_load = d.chance(0.5);
    let amplitude = if as_load {
        d.uniform(1.0, 4.0)
    } else {
        d.uniform(0.5, 3.0)
    };
    let (signal, shape) = if d.chance(0.5) {
        let s = Signal::Sine {
            amplitude,
            period,
            offset: 0.0,
        };
        (s, "sine".to_string())
    } else {
        let damping = d.uniform(0.03, 0.1);
        let s = Signal::NarrowBand {
            amplitude,
            period,
            damping,
            seed: d.seed(),
        };
        (s, format!("narrow-band (damping {damping:.2})"))
    };
    let place = if as_load {
        cl.load = Some(match cl.load.take() {
            Some(l) => Signal::Sum {
                parts: vec![l, signal],
            },
            None => signal,
        });
        "load"
    } else {
        cl.disturbance = Some(signal);
        "PV"
    };
    format!("external {shape} oscillation on the {place}, amplitude {amplitude:.2} %, period {period:.0} s")
}

/// A routine loop of `class`.
pub fn build(class: LoopClass, d: &mut Draw) -> Built {
    let fine = d.chance(0.5);
    let (samples, ts) = if fine { (2000, 1.0) } else { (750, 10.0) };
    let window = samples as f64 * ts;
    let slow = class == LoopClass::SlowLongDelay;
    let kind = if slow {
        d.pick(&[LoopKind::Temperature, LoopKind::Analyser])
    } else {
        d.weighted(&[
            (LoopKind::Flow, 0.3),
            (LoopKind::Pressure, 0.25),
            (LoopKind::Level, 0.25),
            (LoopKind::Temperature, 0.2),
        ])
    };
    let (process, h, lag) = process(kind, slow, fine, d);
    let noise_level = noise(d);
    let mut cl = ClosedLoop::new(valve(class, d));
    cl.process = process;
    cl.ts = ts;
    cl.samples = samples;
    cl.controller_period = Some(h);
    // the plant moves every second between controller executions
    cl.substeps = Some(h.round().max(1.0) as usize);
    cl.valve_lag = lag;
    cl.noise = noise_level.std();
    cl.seed = d.seed();
    cl.op0 = d.uniform(25.0, 75.0);
    cl.warmup = (window / 4.0).max(600.0);
    if class == LoopClass::EqualPercentage {
        cl.characteristic = Characteristic::EqualPercentage {
            rangeability: d.uniform(20.0, 50.0),
        };
        cl.op0 = d.uniform(20.0, 80.0);
    }
    let lin = LinearLoop {
        process,
        valve_lag: lag,
        h,
        valve_gain: cl.characteristic.gain(cl.op0),
    };
    let (pi, tuning) = tune(class, &lin, window, d);
    cl.pi = pi;
    let mut excitation = excite(&mut cl, window, d);
    let notes = look_alike(class, &mut cl, window, d);
    if matches!(class, LoopClass::LoadSteps | LoopClass::FeedForward) {
        excitation = excitation.with_load_steps();
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
