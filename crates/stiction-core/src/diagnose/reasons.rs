//! Why the verdict is what it is, and what to do next, as typed values: the core says what was
//! found, with its figures; the words are written once, in `stiction-report`'s `words`, for the
//! command line, the HTML report and Python (each front end fills the `text` beside them).

use super::verdict::Statistic;
use serde::{Deserialize, Serialize};

/// One finding behind a verdict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Finding {
    /// PV's steps ended sticks: OP wound while PV held, then PV stepped OP's way.
    Sticks {
        /// Sticks found.
        sticks: usize,
        /// PV's steps.
        steps: usize,
        /// Median OP travel per stick, % of span.
        median_travel_percent_of_span: f64,
        /// The analysed stretch, minutes.
        minutes: f64,
    },
    /// OP travelled while PV held off the setpoint without moving towards it.
    Stuck {
        /// OP's travel, % of span.
        travel_percent_of_span: f64,
        /// The hold's length, minutes.
        minutes: f64,
    },
    /// The closed-loop fit explains PV better with a sticky valve.
    FitGain {
        /// Share of PV's variance above its noise the band adds.
        improvement: f64,
        /// The band fitted, % of span.
        band_percent_of_span: f64,
    },
    /// The band the closed-loop fit finds is many times OP's noise.
    FitBand {
        /// Band over OP's noise standard deviation.
        band_over_op_noise: f64,
        /// The band, % of span.
        band_percent_of_span: f64,
    },
    /// The fit's gain with a band is far beyond chance (its test ratio).
    FitTest {
        /// The test ratio.
        ratio: f64,
    },
    /// The oscillation's shape.
    CycleShape {
        /// Shape score, -1 (sinusoidal) to 1 (a sticky valve's triangles and squares).
        score: f64,
        /// The cycle's period, seconds.
        period: Option<f64>,
    },
    /// The lag a valve must add for the identified linear loop to sustain the cycle.
    LoopLag {
        /// Degrees.
        degrees: f64,
        /// The cycle's period, seconds.
        period: Option<f64>,
    },
    /// The recorded valve position shows a band (the valve family decides).
    ValvePosition {
        /// The band fitted to MV, % of span (`None` when it shows none).
        band_percent_of_span: Option<f64>,
        /// Whether it shows stiction.
        sticky: bool,
    },
    /// No statistic points to a sticky valve.
    NothingOfAStickyValve,
    /// The probability lies between the verdict's thresholds.
    Between {
        /// The probability of a sticky valve.
        probability: f64,
        /// `no_stiction` below this.
        below: f64,
        /// `stiction` from this.
        from: f64,
    },
    /// A regular cycle of too few samples a period for any family.
    UnresolvedCycle {
        /// Its period, seconds.
        period: f64,
        /// Samples a period.
        samples: f64,
    },
    /// OP and PV hardly move above their noise: nothing to judge.
    NotExcited,
    /// The record cannot be judged (a data-quality gate; its message says why).
    Record {
        /// The gate's message.
        message: String,
    },
}

impl Finding {
    /// The statistic of the verdict's model a finding reports, if any.
    pub fn statistic(&self) -> Option<Statistic> {
        Some(match self {
            Finding::Sticks { .. } => Statistic::StickShare,
            Finding::Stuck { .. } => Statistic::Stuck,
            Finding::FitGain { .. } => Statistic::FitGain,
            Finding::FitBand { .. } => Statistic::FitBand,
            Finding::FitTest { .. } => Statistic::FitTest,
            Finding::CycleShape { .. } => Statistic::CycleShape,
            Finding::LoopLag { .. } => Statistic::LoopLag,
            _ => return None,
        })
    }
}

/// A finding with its part in the verdict and its words.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reason {
    /// What was found.
    #[serde(flatten)]
    pub finding: Finding,
    /// Its share of the model's log-odds (positive: towards a sticky valve), when it is a
    /// statistic of the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contribution: Option<f64>,
    /// In words (filled by the front end from `stiction-report`'s words; empty from the core).
    #[serde(default)]
    pub text: String,
}

impl Reason {
    /// A reason without a contribution.
    pub fn plain(finding: Finding) -> Self {
        Self {
            finding,
            contribution: None,
            text: String::new(),
        }
    }
}

/// What to do next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Action {
    /// The recorded valve position shows the band: maintain the valve.
    MaintainValve,
    /// A sticky valve without its position recorded: a valve travel test confirms it before
    /// maintenance.
    TravelTest,
    /// No stiction: no action on the valve.
    NoAction,
    /// No stiction, but a sticky valve that does not cycle can leave no more: a travel test
    /// settles it if the loop performs poorly.
    NoActionWeak,
    /// The cycle is sinusoidal: check the tuning and disturbances at its period.
    CheckTuning,
    /// Undetermined: record the valve position or run a valve travel test.
    SettleIt,
    /// A cycle too short in samples: record the loop faster.
    SampleFaster,
    /// Nothing moves: a longer record with the loop excited.
    LongerRecord,
    /// The record cannot be judged: a longer record in automatic with every signal present.
    UsableRecord,
    /// PV does not move while OP does: check the PV transmitter and its historian tag.
    CheckTransmitter,
}

/// The next step: what to do, and what qualifies it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NextStep {
    /// What to do.
    pub action: Action,
    /// The setpoint held over the whole stretch: a window with setpoint changes would tell more.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub setpoint_steady: bool,
    /// PV looks not recorded in this share of the samples (compression hides sticks).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pv_not_recorded: Option<f64>,
    /// For [`Action::SampleFaster`]: the sampling time to record at, seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_every: Option<f64>,
    /// In words (filled by the front end).
    #[serde(default)]
    pub text: String,
}

impl NextStep {
    /// A next step with nothing to qualify it.
    pub fn plain(action: Action) -> Self {
        Self {
            action,
            setpoint_steady: false,
            pv_not_recorded: None,
            sample_every: None,
            text: String::new(),
        }
    }
}
