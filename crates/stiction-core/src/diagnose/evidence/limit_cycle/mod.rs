//! The loop family: a limit cycle that no linear loop can sustain. A stable linear loop does not
//! oscillate on its own; a sustained cycle in it needs an external input oscillating at that
//! period or a non-linearity in the loop, most often the valve. The family identifies the loop
//! (the process from OP to PV as the closed-loop fit with a sticky valve sees it, the controller as
//! a PI from the control error to OP), measures the observed cycle cycle by cycle, and asks what
//! the valve must do for the harmonic balance `L(jω) N = -1` to hold at the observed frequency:
//! `N = -1 / L`, a gain and a phase lag. A linear loop at its stability limit needs nothing
//! (N = 1); a sticky valve gives a lag that grows as the cycle's amplitude shrinks towards the
//! band. Where a valve's describing function (Stenman's band, Kano's S and J) gives that N, its
//! amplitude over band turns the observed OP amplitude into a band, with no single stick to
//! resolve; its harmonic balance with the identified loop predicts the period (Gelb and Vander
//! Velde 1968; Choudhury, Thornhill and Shah 2005, "Modelling valve stiction", Control Engineering
//! Practice 13, 641-658). Notes: detection.md, "A limit cycle that no linear loop can sustain".
//!
//! The look-alikes and how they are told apart:
//! - an external input at the cycle's period: the closed-loop fit absorbs a dominant sinusoid
//!   (its process then makes the loop marginal, N = 1), and a valve lag without harmonics is no
//!   valve (a lag of 25 degrees needs jumps that distort the cycle); otherwise PV moves at the
//!   cycle's frequency that OP does not explain (the process residual);
//! - saturation: OP reaching a limit of its range in the cycle;
//! - aggressive tuning: N = 1 at the cycle (the identified loop is at its stability limit),
//!   often with an amplitude that grows, decays or wanders from cycle to cycle; the family then
//!   leaves the verdict to the others (a valve whose band is small beside its cycle looks the
//!   same: the loop must sit near its limit for such a cycle, see the benchmark);
//! - a cascade's inner loop, its setpoint moving unrecorded: the PI of the recorded error does not
//!   explain OP's cycle; without a setpoint the vote is weakened.
//!
//! Thresholds: set on simulated fast loops (`stiction-lab/examples/loop_benchmark.rs`,
//! `stiction-lab/results/loop-benchmark.md`: sticky valves of Stenman, Kano and He; healthy valves
//! with the look-alikes above), keeping the look-alikes' stiction votes at or under 3 % per class;
//! never on the ISDB.

mod measure;
mod vote;

use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::loop_analysis::{AmplitudeTrend, Margins, PiFit};
use crate::models::ModelKind;
use serde::{Deserialize, Serialize};

/// The loop family.
pub struct LimitCycle;

/// Below this R² of the (low-passed) OP increments the controller is not a PI of the error.
const MIN_PI_R2: f64 = 0.5;
/// Above this share of OP's cycle unexplained by the PI, the recorded error does not drive OP.
const MAX_CONTROLLER_RESIDUAL: f64 = 0.3;
/// The valve lag the loop needs, degrees: stiction from `MIN_LAG` to `MAX_LAG` (a describing
/// function of a valve lags by at most 90 degrees), full strength at `FULL_LAG`; below
/// `LINEAR_LAG` the linear loop sustains the cycle by itself.
const MIN_LAG: f64 = 25.0;
/// The largest valve lag that counts as stiction, degrees (a valve's describing function lags by at
/// most 90).
const MAX_LAG: f64 = 90.0;
/// The valve lag at which the stiction vote reaches full strength, degrees.
const FULL_LAG: f64 = 50.0;
/// Below this valve lag, degrees (and within `LINEAR_GAIN` of a gain of 1), the linear loop
/// sustains the cycle by itself.
const LINEAR_LAG: f64 = 10.0;
/// ... and within this of a gain of 1.
const LINEAR_GAIN: f64 = 0.15;
/// Largest distance between the needed describing function and a valve's.
const MAX_DISTANCE: f64 = 0.2;
/// Largest share of the PV's cycle that OP may leave unexplained through the fitted process.
const MAX_RESIDUAL: f64 = 0.35;
/// The PV's measurement noise is taken off the unexplained share on cycles of at least this many
/// samples (on shorter ones the cycle itself swells the noise estimate from PV's differences: at
/// 12 samples a noise-free sinusoid passes for noise worth 0.07 of its cycle, at 8 samples 0.22).
const NOISE_FREE_CYCLE: f64 = 12.0;
/// The identified linear loop's gain margin must exceed this. A little under 1 is allowed: a sticky
/// valve's describing function has a gain under 1, so a loop unstable with a valve that follows OP
/// can hold a cycle with a sticky one, and the closed-loop fit puts some of the valve's lag into
/// the process. Set on the loop benchmark: at 0.8 no look-alike gains a loop vote there or in the
/// plant benchmark's calibration sets, and the family votes stiction on 69 of the 240 sticky loops
/// instead of 56 at 1.0.
const MIN_MARGIN: f64 = 0.8;
/// OP within this share of its range from either end counts as at a limit ...
const LIMIT_NEAR: f64 = 0.01;
/// ... when this share of the cycles reach it.
pub(crate) const LIMIT_CYCLES: f64 = 0.25;
/// Strength of the vote against stiction when OP reaches a limit in [`LIMIT_CYCLES`] of the cycles.
pub(crate) const SATURATION_STRENGTH: f64 = 0.6;
/// An amplitude that changes by this much over the record, or scatters this much from cycle to
/// cycle (standard deviation of its logarithm), is reported as a linear loop's (not a vote: on
/// plant data stick-slip cycles wander too).
const UNSTEADY_CHANGE: f64 = 0.5;
/// The scatter of the cycle amplitudes (standard deviation of their logarithm) at which the
/// amplitude is reported as unsteady.
const UNSTEADY_SCATTER: f64 = 0.25;
/// A cycle sustains itself when its amplitude scatters less than this from cycle to cycle
/// (standard deviation of its logarithm), changes by less than [`UNSTEADY_CHANGE`] over the record,
/// and its phase wanders more than [`FREE_RUNNING`]. Set on the plant benchmark's calibration
/// sets: no look-alike there holds its amplitude this well while its phase runs free.
const STEADY_SCATTER: f64 = 0.15;
/// Over at least [`STEADY_CYCLES`] cycles a steady amplitude may scatter up to this. The scatter of
/// a cycle that noise drives through a linear loop (its envelope Rayleigh-like: 0.64 in the long
/// run) cannot come out this low by chance over so many cycles, and an envelope that swells slowly
/// shows its swell. On the pooled calibration draws the look-alikes' scatters start above it (but
/// for 3 near-unstable loops), while sticky valves that were not called sticky lie between
/// [`STEADY_SCATTER`] and it.
const STEADY_SCATTER_LONG: f64 = 0.25;
/// The cycles over which [`STEADY_SCATTER_LONG`] applies.
const STEADY_CYCLES: usize = 30;
/// The phase wander (`Cycles::phase_wander`) above which the cycle keeps no outside clock: a cycle
/// forced by an input of fixed period stays under 2 in 99 of 100 records of 6 to 60 cycles (under
/// 2.6 in 999 of 1,000). On the plant benchmark's steady cycles (both sets, both suites) no
/// look-alike exceeds 1.5, and 42 of 53 sticky fast loops exceed 2.
const FREE_RUNNING: f64 = 2.0;
/// The strength of a stiction vote from a self-sustained cycle (with a setpoint recorded; without
/// one the family does not vote on it: an outer loop's cycle moving the setpoint looks the same).
const SELF_SUSTAINED: f64 = 0.6;
/// A predicted period within this factor of the observed one matches it.
const PERIOD_MATCH: f64 = 1.25;
/// The harmonics are measured up to the 5th, or as many as lie below the Nyquist frequency; under
/// this many (the 3rd, where a symmetric valve cycle puts most of its distortion) they are not
/// measured and not asked for.
pub(super) const MIN_HARMONICS: usize = 3;
/// The controller is identified below this many times the cycle's frequency.
const PI_CUTOFF: f64 = 4.0;
/// Without a setpoint the stiction vote's strength is multiplied by this (a cascade's moving
/// setpoint cannot be ruled out).
const NO_SETPOINT: f64 = 0.6;

/// How the thresholds were set, reported with every result.
const CALIBRATION: &str = "thresholds set on simulated fast loops (sticky valves of Stenman, Kano and He bands; healthy valves with \
an external sinusoid or narrow-band disturbance, aggressive tuning, saturation, a cascade's moving setpoint; \
examples/loop_benchmark.rs, docs/loop-benchmark.md), not on the data judged";

/// Which process model the loop is built from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProcessSource {
    /// The linear part of the closed-loop fit with a sticky valve (the process behind the valve).
    StictionFit,
    /// The fit of a valve that follows OP.
    LinearFit,
}

/// What a stiction vote of the family rests on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StictionBasis {
    /// A sticky valve's lag closes the harmonic balance of the identified loop: its describing
    /// function's band fits the cycle.
    ValveLag,
    /// The cycle sustains itself (amplitude steady, phase free) while the identified loop needs
    /// no valve lag: the describing function does not pin the band down.
    SelfSustained,
}

/// The valve whose describing function closes the harmonic balance of the identified loop at the
/// observed cycle, and the band that makes the observed amplitude.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DescribingBand {
    /// The valve: Stenman's band, or Kano's S with slip ratio J / S.
    pub model: ModelKind,
    /// Kano's slip ratio J / S (1 for Stenman).
    pub slip_ratio: f64,
    /// The band (Stenman's d, Kano's S), OP units and % of span.
    pub band: f64,
    /// The band, % of valve span.
    pub band_percent_of_span: f64,
    /// The OP amplitude over the band.
    pub amplitude_over_band: f64,
    /// How far the valve's describing function is from the one the loop needs (complex gain).
    pub distance: f64,
    /// The period the harmonic balance of this valve with the identified loop predicts, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub predicted_period: Option<f64>,
    /// Whether it is within the match factor of the observed period.
    pub period_matches: bool,
}

/// What the loop family found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoopEvidence {
    /// The identified PI.
    pub controller: PiFit,
    /// Whether a setpoint was recorded (without it the error is the PV's deviation from its mean).
    pub setpoint_recorded: bool,
    /// Which fit the process model comes from.
    pub process: ProcessSource,
    /// The identified linear loop's margins.
    pub margins: Margins,
    /// The observed cycle: mean period (s), mean amplitudes of the fundamental of OP and PV per
    /// cycle.
    pub period: f64,
    /// Mean amplitude of OP's fundamental per cycle, OP units.
    pub op_amplitude: f64,
    /// Mean amplitude of PV's fundamental per cycle, PV units.
    pub pv_amplitude: f64,
    /// Harmonic distortion of the cycle (the larger of OP's and PV's; harmonics 2 to
    /// `harmonic_count` over the fundamental's power). `None` when fewer than `MIN_HARMONICS`
    /// lie below the Nyquist frequency: a cycle of under 7 samples cannot show a valve's jumps, and
    /// the family then does not ask for them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub harmonics: Option<f64>,
    /// Samples per cycle (the period over the sampling interval).
    #[serde(default)]
    pub samples_per_cycle: f64,
    /// The highest harmonic measured (5, or fewer for a cycle of under 11 samples; 0 when none was).
    #[serde(default)]
    pub harmonic_count: usize,
    /// Share of the PV's cycle (RMS over the cycles of its fundamental) that OP does not explain
    /// through the fitted process, above what PV's measurement noise puts there (on cycles of at
    /// least `NOISE_FREE_CYCLE` samples).
    pub residual_share: f64,
    /// Share of OP's cycle that the identified PI does not explain from the error's cycle (a
    /// setpoint moving unrecorded, or a controller that is not a PI).
    pub controller_residual_share: f64,
    /// Share of the cycles whose OP reaches within 1 % of its range from a limit.
    pub op_at_limit: f64,
    /// The amplitude of each cycle of OP.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<AmplitudeTrend>,
    /// How freely the cycle's phase runs (`Cycles::phase_wander` of OP's cycles):
    /// near 1 for a cycle that keeps time with an input of fixed period, growing with the cycles
    /// for a self-sustained one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase_wander: Option<f64>,
    /// What the valve must do for the identified loop to sustain the observed cycle: the
    /// describing function `N = -1 / L` at the cycle's frequency, as its gain and its phase lag
    /// (degrees). A linear loop at its stability limit needs nothing (gain 1, lag 0); a sticky
    /// valve gives a lag.
    pub needed_gain: f64,
    /// The needed describing function's phase lag, degrees.
    pub needed_lag_degrees: f64,
    /// The valve and band that give it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub describing: Option<DescribingBand>,
    /// What the family's stiction vote rests on (none without one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiction_basis: Option<StictionBasis>,
    /// Caveats (a missing setpoint, a cascade).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub caveat: Option<String>,
    /// How the thresholds were set (`CALIBRATION`).
    pub calibration: String,
}

impl LoopEvidence {
    /// Whether the identified linear loop sustains the cycle by itself: it needs no valve lag
    /// (under `LINEAR_LAG`) and a gain within `LINEAR_GAIN` of 1, i.e. it sits at its
    /// stability limit at the cycle's period (aggressive tuning, or a band small beside the cycle).
    pub fn linear_loop_sustains(&self) -> bool {
        self.needed_lag_degrees.abs() < LINEAR_LAG && (self.needed_gain - 1.0).abs() < LINEAR_GAIN
    }
}

impl EvidenceFamily for LimitCycle {
    fn family(&self) -> Family {
        Family::Loop
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let statistic = "the phase lag (degrees) a valve must add for the identified linear loop to sustain the observed cycle";
        let threshold = format!(
            "stiction when the lag is {MIN_LAG} to {MAX_LAG} degrees and a sticky valve's describing function gives it (within {MAX_DISTANCE}), \
             the cycle has harmonics (at least {} of the fundamental's power, when the 3rd lies below the Nyquist frequency), OP explains all but {:.0} % of the PV's cycle, \
             the identified loop's gain margin exceeds {MIN_MARGIN} and OP stays off its limits; or, with a setpoint recorded, when the cycle sustains itself \
             (its amplitude scatters under {:.0} % from cycle to cycle, under {:.0} % over {STEADY_CYCLES} cycles or more, and changes under {:.0} % over the record while its phase wanders over {FREE_RUNNING}); \
             none when OP reaches a limit of its range in the cycle (a loop that needs no valve, lag under {LINEAR_LAG} degrees, is otherwise left undetermined)",
            crate::diagnose::evidence::shape::SINUSOIDAL_HARMONICS,
            100.0 * MAX_RESIDUAL,
            100.0 * STEADY_SCATTER,
            100.0 * STEADY_SCATTER_LONG,
            100.0 * UNSTEADY_CHANGE,
        );
        match measure::measure(ctx) {
            Err(why) => FamilyEvidence::abstains(Family::Loop, statistic, threshold, why),
            Ok(e) => vote::vote(e, statistic, threshold),
        }
    }
}

#[cfg(test)]
mod tests;
