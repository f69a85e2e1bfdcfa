//! What both suites share: valves by class, the slip check, the description in words, the period
//! of a cycle.

use super::draw::{mix, Draw};
use super::{
    BenchmarkLoop, Cycle, Excitation, LoopClass, LoopKind, NoiseLevel, Set, Suite, Truth, Tuning,
    MAX_ATTEMPTS, MIN_SLIPS,
};
use std::fmt::Write as _;
use stiction_core::models::{He, Kano, Model, Stenman};
use stiction_core::sim::{backlash, Characteristic, ClosedLoop, LoopData, Process, Signal};

/// A loop drawn but not yet run.
pub struct Built {
    pub setup: ClosedLoop,
    pub kind: LoopKind,
    pub noise_level: NoiseLevel,
    pub excitation: Excitation,
    pub tuning: Tuning,
    /// Class-specific settings in words.
    pub notes: Vec<String>,
}

/// What a sticky loop of a suite must show to be kept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Accept {
    /// At least [`MIN_SLIPS`] slips in the record.
    Slips,
    /// That, and a visible limit cycle ([`limit_cycles`]).
    SlipsAndCycle,
    /// At least one slip (a plant window's valve may stick through most of it, as real ones do).
    AnySlip,
}

/// Build and run a loop; a sticky valve that does not show what `accept` asks is drawn again from
/// the next seed, and after [`MAX_ATTEMPTS`] the draw with the most slips is kept.
pub fn with_slips(
    class: LoopClass,
    seed: u64,
    accept: Accept,
    build: fn(LoopClass, &mut Draw) -> Built,
) -> BenchmarkLoop {
    let mut best: Option<BenchmarkLoop> = None;
    for attempt in 0..MAX_ATTEMPTS {
        let mut draw = Draw::new(mix(seed ^ attempt.wrapping_mul(0x5851_F42D_4C95_7F2D)));
        let built = build(class, &mut draw);
        let l = finish(class, built, attempt + 1);
        let enough = class.truth() != Truth::Sticky
            || (accept == Accept::AnySlip && l.slips >= 1)
            || (l.slips >= MIN_SLIPS && (accept == Accept::Slips || limit_cycles(&l)));
        if best.as_ref().is_none_or(|b| l.slips > b.slips) || enough {
            best = Some(l);
        }
        if enough {
            break;
        }
    }
    best.expect("at least one attempt")
}

/// Run a built loop into a catalogue entry (id, suite and set are filled in by the caller).
pub fn finish(class: LoopClass, b: Built, attempts: u64) -> BenchmarkLoop {
    let run = b
        .setup
        .simulate()
        .expect("catalogue loops are drawn from valid ranges");
    let quiet = without_noise(&b.setup);
    let cycle = quiet.as_ref().and_then(|q| cycle_of(q, &b.setup));
    let visibility = quiet
        .as_ref()
        .filter(|_| class.truth() == Truth::Sticky)
        .and_then(|q| slip_visibility(q, &run.data, &b.setup));
    BenchmarkLoop {
        id: String::new(),
        suite: Suite::Routine,
        set: Set::Benchmark,
        class,
        truth: class.truth(),
        kind: b.kind,
        description: describe(&b),
        integrating: b.setup.process.is_integrating(),
        noise_level: b.noise_level,
        excitation: b.excitation,
        tuning: b.tuning,
        slips: run.slips,
        saturated: run.saturated as f64 / run.steps.max(1) as f64,
        attempts,
        cycle,
        visibility,
        setup: b.setup,
        data: run.data,
    }
}

/// The valve a class has: a sticky model with a band log-uniform in 0.5..5 % of span, a
/// backlash, or a healthy valve (Stenman with `d = 0`).
pub fn valve(class: LoopClass, d: &mut Draw) -> Model {
    let band = d.log_uniform(0.5, 5.0);
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
        LoopClass::BacklashValve => backlash(band),
        _ => Model::Stenman(Stenman { d: 0.0 }),
    }
}

pub fn noise(d: &mut Draw) -> NoiseLevel {
    d.pick(&NoiseLevel::ALL)
}

fn process_words(p: &Process) -> String {
    match *p {
        Process::Foptd { k, tau, delay } => {
            format!("FOPTD K={k:.3} tau={tau:.1} s delay={delay:.1} s")
        }
        Process::Integrating { k, delay } => {
            format!("integrating K={k:.5} /s delay={delay:.1} s")
        }
        Process::Soptd {
            k,
            tau1,
            tau2,
            delay,
        } => format!("SOPTD K={k:.3} tau1={tau1:.1} s tau2={tau2:.1} s delay={delay:.1} s"),
    }
}

fn valve_words(m: &Model) -> String {
    match *m {
        Model::Stenman(v) if v.d == 0.0 => "healthy".into(),
        Model::Stenman(v) => format!("Stenman d={:.2} %", v.d),
        Model::Kano(v) if v.j == 0.0 => format!("backlash (Kano S={:.2} %, J=0)", v.s),
        Model::Kano(v) => format!("Kano S={:.2} % J={:.2} %", v.s, v.j),
        Model::He(v) => format!("He fs={:.2} % fd={:.2} %", v.fs, v.fd),
        Model::Choudhury(v) => format!("Choudhury S={:.2} % J={:.2} %", v.s, v.j),
    }
}

fn excitation_words(e: Excitation, cl: &ClosedLoop) -> String {
    let sp = match &cl.setpoint {
        Signal::RandomSteps {
            amplitude,
            min_hold,
            max_hold,
            ..
        } => format!(
            "setpoint steps within ±{amplitude:.1} % held {:.0}-{:.0} min",
            min_hold / 60.0,
            max_hold / 60.0
        ),
        Signal::Step { from, to, at } => format!("a setpoint step {from} to {to} at {at} s"),
        _ => "constant setpoint".into(),
    };
    match e {
        Excitation::SetpointSteps => sp,
        Excitation::LoadDrift => format!("{sp}, slow load drift"),
        Excitation::LoadRamp => format!("{sp}, load ramp"),
        Excitation::StepsAndDrift => format!("{sp} and a slow load drift"),
        Excitation::Regulation => format!("regulation: {sp}, slight load drift"),
        // the class's own words name the load steps
        Excitation::LoadSteps | Excitation::StepsAndLoadSteps => sp,
    }
}

/// The loop's parameters in one line.
pub fn describe(b: &Built) -> String {
    let cl = &b.setup;
    let mut s = format!(
        "{}; {}; PI Kc={:.3} Ti={:.1} s",
        b.kind.name(),
        process_words(&cl.process),
        cl.pi.kc,
        cl.pi.ti
    );
    match b.tuning {
        Tuning::Simc { lambda } => {
            let _ = write!(s, " (SIMC lambda={lambda:.1} s)");
        }
        Tuning::Ultimate { fraction, ku, pu } => {
            let _ = write!(s, " ({fraction:.3} of Ku={ku:.3}, Pu={pu:.0} s)");
        }
    }
    let _ = write!(s, "; valve {}", valve_words(&cl.model));
    if cl.valve_lag > 0.0 {
        let _ = write!(s, ", lag {:.1} s", cl.valve_lag);
    }
    if let Characteristic::EqualPercentage { rangeability } = cl.characteristic {
        let _ = write!(s, ", equal-percentage R={rangeability:.0}");
    }
    let _ = write!(
        s,
        ", OP0={:.0} %; noise {:.2} ({}); {}",
        cl.op0,
        cl.noise,
        format!("{:?}", b.noise_level).to_lowercase(),
        excitation_words(b.excitation, cl)
    );
    for n in &b.notes {
        let _ = write!(s, "; {n}");
    }
    let _ = write!(
        s,
        "; {} samples every {} s, controller every {} s",
        cl.samples,
        cl.ts,
        cl.controller_period.unwrap_or(cl.ts)
    );
    if cl.warmup > 0.0 {
        let _ = write!(
            s,
            "; {:.0} s of warm-up before the record (signal times count from its start)",
            cl.warmup
        );
    }
    s
}

/// The same loop run without measurement noise.
fn without_noise(setup: &ClosedLoop) -> Option<LoopData> {
    let mut quiet = setup.clone();
    quiet.noise = 0.0;
    if let Some(c) = quiet.cascade.as_mut() {
        c.noise = 0.0;
    }
    quiet.run().ok()
}

/// The cycle the loop keeps without measurement noise (`d`: its noise-free record): measured on
/// the control error `sp - pv` over the record's second half, when it crosses its mean at least
/// five times.
fn cycle_of(d: &LoopData, setup: &ClosedLoop) -> Option<Cycle> {
    let half = d.pv.len() / 2;
    let e: Vec<f64> = d.sp[half..]
        .iter()
        .zip(&d.pv[half..])
        .map(|(s, p)| s - p)
        .collect();
    let mut sorted = e.clone();
    sorted.sort_by(f64::total_cmp);
    let q = |p: f64| sorted[((sorted.len() - 1) as f64 * p).round() as usize];
    let amplitude = (q(0.95) - q(0.05)) / 2.0;
    if amplitude <= 1e-9 {
        return None;
    }
    let m = e.iter().sum::<f64>() / e.len() as f64;
    let ups: Vec<usize> = (1..e.len())
        .filter(|&k| e[k - 1] < m && e[k] >= m)
        .collect();
    if ups.len() < 6 {
        return None;
    }
    let gaps: Vec<f64> = ups.windows(2).map(|w| (w[1] - w[0]) as f64).collect();
    let mean = gaps.iter().sum::<f64>() / gaps.len() as f64;
    let sd = (gaps.iter().map(|g| (g - mean).powi(2)).sum::<f64>() / gaps.len() as f64).sqrt();
    Some(Cycle {
        period: mean * setup.ts,
        spread: sd / mean,
        amplitude,
    })
}

/// A visible limit cycle: the loop without noise cycles regularly (period spread under 40 %),
/// with at least 6 samples per period and an amplitude of the control error at least twice the
/// noise's standard deviation.
pub fn limit_cycles(l: &BenchmarkLoop) -> bool {
    l.cycle.is_some_and(|c| {
        c.spread < 0.4 && c.period >= 6.0 * l.setup.ts && c.amplitude >= 2.0 * l.setup.noise
    })
}

/// The mean period of a cycle in `x` (mean distance between upward crossings of its mean over
/// the second half), when it crosses at least four times.
pub fn cycle_period(x: &[f64], ts: f64) -> Option<f64> {
    let x = &x[x.len() / 2..];
    let m = x.iter().sum::<f64>() / x.len().max(1) as f64;
    let ups: Vec<usize> = (1..x.len())
        .filter(|&k| x[k - 1] < m && x[k] >= m)
        .collect();
    if ups.len() < 4 {
        return None;
    }
    Some((ups[ups.len() - 1] - ups[0]) as f64 * ts / (ups.len() - 1) as f64)
}

/// A slow load drift whose spread over `seconds` is about `spread` % (an integrated random walk
/// has standard deviation `slope_std sqrt(T^3 / 3)` at time T).
pub fn load_drift(spread: f64, seconds: f64, seed: u64) -> Signal {
    Signal::IntegratedRandomWalk {
        slope_std: spread / (seconds.powi(3) / 3.0).sqrt(),
        offset: 0.0,
        seed,
    }
}

/// How far a sticky valve's slips move PV, in the recorded PV's noise standard deviations (as a
/// diagnosis measures it): the median over the slips of the noise-free record `quiet` of PV's
/// change from the sample before a slip to the process's response time after it. A valve whose
/// slips move PV less than its noise shows its stiction to no one; labels on real records come
/// from what engineers could see.
pub fn slip_visibility(quiet: &LoopData, recorded: &LoopData, setup: &ClosedLoop) -> Option<f64> {
    let band = setup.model.values().first().copied().filter(|b| *b > 0.0)?;
    let noise = stiction_core::detect::measurement_noise(&recorded.pv);
    let (mv, pv) = (&quiet.mv, &quiet.pv);
    let tau = match setup.process {
        Process::Foptd { tau, .. } => tau,
        Process::Soptd { tau1, tau2, .. } => tau1.max(tau2),
        Process::Integrating { .. } => 3.0 * setup.ts,
    };
    let horizon = (((setup.process.delay() + 2.0 * tau) / setup.ts).ceil() as usize).clamp(1, 30);
    let mut moves = Vec::new();
    let mut k = 1;
    while k < mv.len() {
        if (mv[k] - mv[k - 1]).abs() > 0.25 * band {
            // a slip spread over consecutive samples (averages) counts once
            let start = k;
            while k + 1 < mv.len() && (mv[k + 1] - mv[k]).abs() > 0.05 * band {
                k += 1;
            }
            let end = (k + horizon).min(pv.len() - 1);
            moves.push((pv[end] - pv[start - 1]).abs());
        }
        k += 1;
    }
    if moves.is_empty() || noise <= 0.0 {
        return Some(0.0);
    }
    moves.sort_by(f64::total_cmp);
    Some(moves[moves.len() / 2] / noise)
}
