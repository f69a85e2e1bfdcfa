//! Families of evidence: independent ways of asking "is the valve sticky?", each behind one small
//! trait so that a new family is one new file. Each returns typed evidence: its statistic, the
//! threshold it is held to (in words), its vote and how strongly it holds it.
//!
//! - [`shape`]: the shape of an oscillation (the literature's indices), on oscillating stretches;
//! - [`model`]: the closed-loop Hammerstein fit with and without stiction, on the whole record;
//! - [`stick_slip`]: episodes of OP travelling while PV stays put, ended by a PV jump;
//! - [`valve`]: the recorded valve position against OP, when MV is recorded;
//! - [`limit_cycle`]: a limit cycle that no linear loop can sustain (the identified loop, its
//!   margin and the describing function of a band);
//! - [`hidden_valve`] (with `thorough`): a sticky valve whose position the record does not hold,
//!   as a likelihood ratio, where the other families have not decided stiction.

pub mod hidden_valve;
pub mod limit_cycle;
pub mod model;
pub mod shape;
pub mod stick_slip;
pub mod valve;

use super::request::DiagnoseRequest;
use super::result::{Oscillation, Vote};
use crate::quantify::FitComparison;
use serde::{Deserialize, Serialize};

pub use hidden_valve::HiddenValveEvidence;
pub use limit_cycle::LoopEvidence;
pub use model::ModelEvidence;
pub use stick_slip::StickSlipEvidence;
pub use valve::ValveEvidence;

/// The families of evidence.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Family {
    /// The shape of the oscillation: the literature's indices on oscillating stretches.
    Shape,
    /// The closed-loop Hammerstein fits with and without stiction.
    Model,
    /// Episodes of OP travelling while PV stays put, ended by a PV jump.
    StickSlip,
    /// The recorded valve position (mv) against OP.
    Valve,
    /// The identified loop and its limit cycle.
    Loop,
    /// A sticky valve whose position the record does not hold (`thorough`).
    HiddenValve,
}

impl Family {
    /// The name used in files (`stick_slip`), as serde writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Family::Shape => "shape",
            Family::Model => "model",
            Family::StickSlip => "stick_slip",
            Family::Valve => "valve",
            Family::Loop => "loop",
            Family::HiddenValve => "hidden_valve",
        }
    }

    /// The family's name in words.
    pub fn words(self) -> &'static str {
        match self {
            Family::Shape => "shape of the oscillation",
            Family::Model => "closed-loop fit",
            Family::StickSlip => "stick-slip episodes",
            Family::Valve => "valve position",
            Family::Loop => "linear loop",
            Family::HiddenValve => "hidden valve",
        }
    }
}

/// What one family found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FamilyEvidence {
    /// Which family.
    pub family: Family,
    /// Its vote.
    pub vote: Vote,
    /// 0..1: how strongly the evidence holds the vote, `1 - exp(-|contribution|)` (for
    /// `undetermined`, 0).
    pub strength: f64,
    /// The family's statistics' share of the verdict's log-odds (positive: towards a sticky
    /// valve); `None` where the model reads none of them here.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contribution: Option<f64>,
    /// The family's statistic.
    pub value: Option<f64>,
    /// What the statistic is, in words.
    pub statistic: String,
    /// The rule it is held to, in words.
    pub threshold: String,
    /// Why it voted as it did, or why it could not vote.
    pub note: String,
    /// For an `undetermined` vote: the side the statistic falls on when it was measured but lies
    /// between the thresholds (evidence, too weak to decide); `None` when the family could not
    /// judge the record or leans nowhere.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leans: Option<Vote>,
    /// The model family's details (on its evidence only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelEvidence>,
    /// The stick-slip family's details (on its evidence only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stick_slip: Option<StickSlipEvidence>,
    /// The valve family's details (on its evidence only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valve: Option<ValveEvidence>,
    /// The loop family's details (on its evidence only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit_cycle: Option<LoopEvidence>,
    /// The hidden-valve family's details (on its evidence only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hidden_valve: Option<HiddenValveEvidence>,
}

impl FamilyEvidence {
    /// A family that cannot judge this record.
    pub fn abstains(family: Family, statistic: &str, threshold: String, note: String) -> Self {
        Self {
            family,
            vote: Vote::Undetermined,
            strength: 0.0,
            contribution: None,
            value: None,
            statistic: statistic.into(),
            threshold,
            note,
            leans: None,
            model: None,
            stick_slip: None,
            valve: None,
            limit_cycle: None,
            hidden_valve: None,
        }
    }
}

/// Everything the families read: the analysed stretch and what is computed once for all.
pub struct Context<'a> {
    /// The request's settings and limits.
    pub req: &'a DiagnoseRequest,
    /// OP over the analysed stretch, OP units.
    pub op: &'a [f64],
    /// PV over the analysed stretch.
    pub pv: &'a [f64],
    /// SP over the analysed stretch, when recorded.
    pub sp: Option<&'a [f64]>,
    /// The setpoint the control error is taken from: SP when recorded, else the setpoint read
    /// off the record ([`crate::diagnose::setpoint`]), if any.
    pub setpoint: Option<&'a [f64]>,
    /// The loop is integrating (as the request says, or as the record behaves).
    pub integrating: bool,
    /// The recorded valve position (mv) over the analysed stretch, OP units, when recorded.
    pub mv: Option<&'a [f64]>,
    /// The control error (SP - PV; without SP, PV's deviation from the setpoint read off the
    /// record, or from its mean).
    pub error: Vec<f64>,
    /// Without SP, the setpoint steps read off the record ([`crate::diagnose::setpoint`]).
    pub setpoint_steps: usize,
    /// The oscillation on the longest constant-setpoint stretch (indices relative to `op`).
    pub oscillation: Oscillation,
    /// Robust noise standard deviations of PV and OP (from first differences).
    pub pv_noise: f64,
    /// The same for OP.
    pub op_noise: f64,
    /// The PV's resolution when it is quantised.
    pub pv_quantum: Option<f64>,
    /// PV samples that look not recorded: inside runs of repeated values or of exactly straight
    /// lines (historian compression, a frozen transmitter).
    pub unrecorded: Vec<bool>,
    /// The closed-loop fits with and without stiction (`None` when no linear model fits).
    pub fits: Option<FitComparison>,
    /// The lag's bound, when the fits' lag reached it and the comparison over a third of it was
    /// kept (`model::BOUND_LAG_DIVISOR`).
    pub lag_bound: Option<usize>,
    /// The shape family's indices, once computed (they go to [`super::Diagnosis::indices`]).
    pub indices: std::cell::OnceCell<Vec<super::result::Index>>,
}

impl Context<'_> {
    /// The share of PV samples in `from..to` that look not recorded ([`Context::unrecorded`]).
    pub fn unrecorded_share(&self, from: usize, to: usize) -> f64 {
        let part = self.unrecorded.get(from..to).unwrap_or(&[]);
        part.iter().filter(|&&u| u).count() as f64 / part.len().max(1) as f64
    }
}

/// One family of evidence.
pub trait EvidenceFamily {
    /// Which family this is.
    fn family(&self) -> Family;
    /// The family's evidence on the analysed stretch.
    fn evaluate(&self, ctx: &Context) -> FamilyEvidence;
}

/// Every family, in the order they are reported.
pub fn all() -> [&'static dyn EvidenceFamily; 5] {
    [
        &valve::Valve,
        &model::Model,
        &stick_slip::StickSlip,
        &shape::Shape,
        &limit_cycle::LimitCycle,
    ]
}
