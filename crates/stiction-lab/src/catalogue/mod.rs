//! The catalogue of benchmark loops: simulated plant loops of many kinds, each with its truth
//! (sticky valve, healthy valve, backlash only), to calibrate and check `diagnose`.
//!
//! Three suites, after the benchmark parts of issues 10, 14 and 69:
//! - [`Suite::Routine`] (540 loops): routine plant historian windows, 750 samples every 10 s or
//!   2,000 every 1 s, of flow, pressure, level (integrating) and temperature or analyser loops
//!   under SIMC (lambda) tuning, excited by setpoint step sequences, slow load drifts and load
//!   ramps. 240 have a sticky valve (Stenman `d`, Kano `S`/`J`, He `fs`/`fd`, bands 0.5 to 5 % of
//!   span, log-uniform); the others are healthy look-alikes (equal-percentage valve, quantised PV,
//!   compressed PV, slow process with long delay, aggressive tuning, external oscillation, load steps, load steps fed forward to OP, plain),
//!   plus a backlash-only valve (Kano with `J = 0`, see [`stiction_core::sim::backlash`]) reported apart.
//! - [`Suite::Fast`] (240 loops): fast loops that limit-cycle (flow, pressure, cooling water), PI
//!   every 1-3 s, samples every 1-5 s, actuator lag, bands 0.5-5 %; look-alikes: an external
//!   oscillation at the loop's own period, tuning at the stability limit, OP saturating at 0 or
//!   100 %, a cascade's inner loop; and the example of issue 14 ([`issue14_example`]).
//! - [`Suite::Plant`] (430 loops): plant historian windows shaped after the real plant records
//!   (`../shared/data/plant-dev`): 750 values 10 s apart, each the mean of a 1-s loop's values;
//!   flow, level and pressure loops (and slow temperature or analyser look-alikes) under detuned
//!   PI (integral times many time constants: a stuck valve's OP winds for tens of minutes);
//!   operator setpoint steps and staircases; bands 0.3-4 %; look-alikes: levels and flows near
//!   their stability limit, external oscillations, load steps, load steps fed forward. A sticky
//!   valve needs one slip, and carries its visibility (how far its slips move PV, in noise
//!   standard deviations: `BenchmarkLoop::visibility`).
//!
//! Each suite has two sets drawn from the same ranges: [`Set::Benchmark`] with fixed seeds (the
//! figures we report) and [`Set::Calibration`] with other seeds, for setting thresholds, so the
//! benchmark is never the training set. Where 30 loops of a class cannot settle a decision (a
//! share of false alarms near a goal moves by 3 % a loop), [`Set::Extra`] draws the same plan
//! again from further seeds: more calibration data, never the benchmark. Everything is deterministic: a loop's parameters come from
//! its own seed, `mix(set seed + index)`; generation runs in parallel and keeps the order.
//!
//! Every sticky valve must stick and slip at least [`MIN_SLIPS`] times within its record, and in
//! the fast suite the loop must visibly limit-cycle (without noise, its control error cycles
//! regularly, period spread under 40 %, at least 6 samples per period, amplitude at least twice
//! the noise's standard deviation): a loop that does not is drawn again from the next seed (up to
//! [`MAX_ATTEMPTS`] times; the attempts are recorded).

mod day;
mod draw;
mod fast;
mod kinds;
mod plant;
mod routine;
mod tuning;
mod windows;

pub use day::{day_class, plant_day};
pub use fast::issue14_example;
pub use kinds::{BenchmarkLoop, Cycle, Excitation, LoopClass, LoopKind, NoiseLevel, Truth, Tuning};
pub use tuning::LinearLoop;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Fewest slips a sticky loop must show in its record.
pub const MIN_SLIPS: usize = 4;
/// Draws tried per sticky loop before the one with the most slips is kept.
pub const MAX_ATTEMPTS: u64 = 12;

/// Which benchmark: routine historian windows (issue 10) or fast limit-cycling loops (issue 14).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Suite {
    /// Routine historian windows (issue 10).
    Routine,
    /// Fast limit-cycling loops (issue 14).
    Fast,
    /// Plant historian windows as the real plant records are (`windows`): 10-s averages of a
    /// 1-s loop, detuned PI, operator setpoint steps, levels near their stability limit.
    Plant,
}

/// Which seeds: the reported benchmark or the calibration set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Set {
    /// The seeds the benchmark reports.
    Benchmark,
    /// Other seeds, for setting thresholds.
    Calibration,
    /// Further calibration draws (1, 2, ...): the same plan from other seeds again, to check a
    /// threshold chosen on the calibration set on more loops of each class.
    Extra(u8),
}

/// How many loops of each class a suite holds, in catalogue order.
pub fn plan(suite: Suite) -> &'static [(LoopClass, usize)] {
    use LoopClass::*;
    match suite {
        Suite::Routine => &[
            (StenmanValve, 80),
            (KanoValve, 80),
            (HeValve, 80),
            (BacklashValve, 30),
            (Healthy, 30),
            (EqualPercentage, 30),
            (QuantisedPv, 30),
            (CompressedPv, 30),
            (SlowLongDelay, 30),
            (AggressiveTuning, 30),
            (ExternalOscillation, 30),
            (LoadSteps, 30),
            (FeedForward, 30),
        ],
        Suite::Fast => &[
            (StenmanValve, 30),
            (KanoValve, 30),
            (HeValve, 30),
            (Healthy, 30),
            (ExternalOscillation, 30),
            (NearUnstable, 30),
            (SaturatedOp, 30),
            (CascadeInner, 30),
        ],
        Suite::Plant => &[
            (StenmanValve, 60),
            (KanoValve, 60),
            (HeValve, 60),
            (Healthy, 80),
            (NearUnstable, 40),
            (ExternalOscillation, 30),
            (LoadSteps, 30),
            (FeedForward, 20),
            (SlowLongDelay, 30),
        ],
    }
}

/// The seed a set's loops are derived from.
pub fn set_seed(suite: Suite, set: Set) -> u64 {
    match (suite, set) {
        (Suite::Routine, Set::Benchmark) => 20_261_110,
        (Suite::Fast, Set::Benchmark) => 20_261_114,
        (Suite::Routine, Set::Calibration) => 90_261_110,
        (Suite::Fast, Set::Calibration) => 90_261_114,
        (Suite::Routine, Set::Extra(n)) => 40_261_110 + 100_000 * u64::from(n),
        (Suite::Fast, Set::Extra(n)) => 40_261_114 + 100_000 * u64::from(n),
        (Suite::Plant, Set::Benchmark) => 20_261_202,
        (Suite::Plant, Set::Calibration) => 90_261_202,
        (Suite::Plant, Set::Extra(n)) => 40_261_202 + 100_000 * u64::from(n),
    }
}

fn class_at(suite: Suite, index: usize) -> Option<LoopClass> {
    let mut start = 0;
    for &(class, count) in plan(suite) {
        if index < start + count {
            return Some(class);
        }
        start += count;
    }
    None
}

/// Number of loops in a suite.
pub fn size(suite: Suite) -> usize {
    plan(suite).iter().map(|p| p.1).sum()
}

/// The id of a catalogue loop.
pub fn loop_id(suite: Suite, set: Set, index: usize) -> String {
    let s = match suite {
        Suite::Routine => "routine",
        Suite::Fast => "fast",
        Suite::Plant => "plant",
    };
    match set {
        Set::Benchmark => format!("{s}-b-{index:04}"),
        Set::Calibration => format!("{s}-c-{index:04}"),
        Set::Extra(n) => format!("{s}-x{n}-{index:04}"),
    }
}

/// Generate one loop of a suite; `None` past the suite's end.
pub fn generate(suite: Suite, set: Set, index: usize) -> Option<BenchmarkLoop> {
    let class = class_at(suite, index)?;
    let seed = draw::mix(set_seed(suite, set).wrapping_add(index as u64));
    let id = loop_id(suite, set, index);
    let mut l = match suite {
        Suite::Routine => plant::with_slips(class, seed, plant::Accept::Slips, routine::build),
        Suite::Fast => plant::with_slips(class, seed, plant::Accept::SlipsAndCycle, fast::build),
        Suite::Plant => plant::with_slips(class, seed, plant::Accept::AnySlip, windows::build),
    };
    l.id = id;
    l.suite = suite;
    l.set = set;
    Some(l)
}

/// All loops of a suite and set, in catalogue order (generated in parallel; the result does not
/// depend on the thread count).
pub fn catalogue(suite: Suite, set: Set) -> Vec<BenchmarkLoop> {
    (0..size(suite))
        .into_par_iter()
        .map(|i| generate(suite, set, i).expect("index within the suite"))
        .collect()
}

/// A loop by its id (`routine-b-0042`, `fast-c-0007`, `routine-x2-0100`, `issue14`).
pub fn find(id: &str) -> Option<BenchmarkLoop> {
    if id == "issue14" {
        return Some(issue14_example());
    }
    let mut parts = id.split('-');
    let suite = match parts.next()? {
        "routine" => Suite::Routine,
        "fast" => Suite::Fast,
        "plant" => Suite::Plant,
        _ => return None,
    };
    let set = match parts.next()? {
        "b" => Set::Benchmark,
        "c" => Set::Calibration,
        x => Set::Extra(x.strip_prefix('x')?.parse().ok()?),
    };
    let index: usize = parts.next()?.parse().ok()?;
    if parts.next().is_some() {
        return None;
    }
    generate(suite, set, index)
}
