//! The diagnosis of one loop, shared by every front end (CLI, report, batch, Python).

use super::evidence::FamilyEvidence;
use crate::detect::{IaeCount, Regularity};
use crate::quality::Finding;
use crate::quantify::Quantification;
use serde::{Deserialize, Serialize};

pub use crate::detect::Vote;

/// The answer for a loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Verdict {
    /// The valve sticks: the families that decided agree on stiction.
    Stiction,
    /// The valve does not stick: the record shows no stiction (healthy, or another cause of the
    /// oscillation).
    NoStiction,
    /// The record was judged but the evidence is too weak or conflicting to decide.
    Undetermined,
    /// The record cannot be judged: too short, or too little usable data (see the reason).
    InsufficientData,
}

impl Verdict {
    /// The name used in files (`no_stiction`), as serde writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Stiction => "stiction",
            Verdict::NoStiction => "no_stiction",
            Verdict::Undetermined => "undetermined",
            Verdict::InsufficientData => "insufficient_data",
        }
    }
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One stiction index of the shape family: its value, the threshold it is held to, and its vote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Index {
    /// Short name: "cross_correlation", "ddpv_histogram", "bicoherence", "curve_fitting",
    /// "harmonics", "shape".
    pub name: String,
    /// Where the method and its threshold come from.
    pub reference: String,
    /// The index's value (`None` when it could not be computed).
    pub value: Option<f64>,
    /// The rule, in words, e.g. "stiction above 0.667, none below 0.333".
    pub threshold: String,
    /// Its vote.
    pub vote: Vote,
    /// Its weight in the shape family's vote.
    pub weight: f64,
    /// Set for an index that can vote only one way (the shape index confirms stiction, the
    /// harmonics index confirms a linear oscillation): when it does not cast that vote it is
    /// silent by design and is left out of the family's total weight, so its silence does not
    /// dilute the other indices.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub only_votes: Option<Vote>,
    /// Why it voted as it did, or why it could not vote.
    pub note: String,
}

/// Is there an oscillation, and of what period?
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Oscillation {
    /// Whether the control error oscillates: a regular period (with at least 4 IAE exceedances) or
    /// Hägglund's count, with an amplitude that stands out of the noise.
    pub oscillating: bool,
    /// Seconds.
    pub period: Option<f64>,
    /// Stretch length over the period.
    pub periods_in_record: Option<f64>,
    /// Thornhill's regularity of the control error.
    pub regularity: Regularity,
    /// Hägglund's IAE count on the control error.
    pub iae: IaeCount,
    /// Standard deviation of the noise on the control error (robust, from first differences).
    pub noise_std: f64,
    /// Half the peak-to-peak amplitude of the control error (5th to 95th percentile).
    pub amplitude: f64,
    /// The samples `[start, end)` the oscillation was judged on: the longest stretch with a
    /// constant setpoint, or the whole stretch across the setpoint's steps
    /// (`across_setpoint_steps`).
    pub stretch: [usize; 2],
    /// The oscillation was judged across the setpoint's steps: the longest constant-setpoint
    /// stretch showed none, while the whole stretch cycles, with at least 30 % of the error's
    /// variance in the cycle, and the setpoint moves in steps no more often than once a period.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub across_setpoint_steps: bool,
    /// A weak cycle: regular, but its half periods' areas clear 1.5 noise standard deviations
    /// only (not Hägglund's 3), and its period wanders as a limit cycle's does beside the noise
    /// (regularity under 100: one that kept time like a clock would be an input's).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub weak_cycle: bool,
    /// Share of the control error's variance in its cycle (from the autocorrelation at the period
    /// and half of it), when a period was found.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle_share: Option<f64>,
    /// The period was read with the autocorrelation's zero crossings taken through its noise
    /// band (one standard error either side of zero): read plainly, the estimate's scatter near
    /// zero broke a wandering cycle's periods up.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub through_noise_band: bool,
}

impl Oscillation {
    /// How the period was read, in words, for an oscillation found through the noise band
    /// ([`Oscillation::through_noise_band`]); `None` otherwise.
    pub fn reading_words(&self) -> Option<&'static str> {
        (self.oscillating && self.through_noise_band).then_some(
            "its period wanders: read with the autocorrelation's zero crossings taken through its noise band",
        )
    }
}

/// Where the band in the verdict comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BandSource {
    /// Estimated from OP and the recorded valve position (the paper's problem, exact).
    Valve,
    /// The closed-loop Hammerstein estimate (Stenman, exact) from OP and PV.
    ClosedLoop,
    /// The closed-loop fit's scan of the Stenman band (not the exact search).
    FitScan,
    /// The band `S` of the closed-loop fit's slip-jump valve (Kano's, its jump `J` free).
    SlipJumpFit,
    /// The median OP travel per stick of the stick-slip episodes.
    StickSlip,
    /// The band whose describing function closes the harmonic balance of the identified loop at
    /// the observed cycle (the loop family).
    DescribingFunction,
    /// The best valve of the model family's levels test (`thorough`): every Stenman valve, then
    /// He's near it, scored on PV's levels.
    Levels,
    /// The width of the PV-OP ellipse of the oscillation (along OP), where the fits resolve no
    /// band.
    Ellipse,
    /// The hidden-valve family's best band (a grid of 10 bands, 0.3-8 % of span).
    HiddenValve,
}

impl BandSource {
    /// Where the band comes from, in words.
    pub fn words(self) -> &'static str {
        match self {
            BandSource::Valve => "from the recorded valve position",
            BandSource::ClosedLoop => "the closed-loop estimate (Stenman, exact)",
            BandSource::FitScan => "the closed-loop fit's scan of the Stenman band",
            BandSource::SlipJumpFit => "the closed-loop fit's slip-jump valve (Kano's S)",
            BandSource::StickSlip => "the median OP travel per stick",
            BandSource::DescribingFunction => "the describing function of the loop's limit cycle",
            BandSource::Levels => "the levels test's best valve",
            BandSource::Ellipse => "the width of the oscillation's PV-OP ellipse",
            BandSource::HiddenValve => {
                "the hidden-valve test's band (the best of 10 from 0.3 to 8 % of span)"
            }
        }
    }
}

impl BandSource {
    /// The name used in files (`closed_loop`), as serde writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            BandSource::Valve => "valve",
            BandSource::ClosedLoop => "closed_loop",
            BandSource::FitScan => "fit_scan",
            BandSource::SlipJumpFit => "slip_jump_fit",
            BandSource::StickSlip => "stick_slip",
            BandSource::DescribingFunction => "describing_function",
            BandSource::Levels => "levels",
            BandSource::Ellipse => "ellipse",
            BandSource::HiddenValve => "hidden_valve",
        }
    }
}

/// The stiction band the verdict reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Band {
    /// In % of valve span (OP mapped through the request's `op_range`).
    pub band_percent_of_span: f64,
    /// In OP units.
    pub op_units: f64,
    /// The values that fit equally well, % of span, where the source knows them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub interval_percent_of_span: Option<[f64; 2]>,
    /// Where the band comes from.
    pub source: BandSource,
    /// The other estimates, % of span, for comparison.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub others: Vec<(BandSource, f64)>,
    /// The width along OP of the ellipse fitted to the filtered PV-OP plot of an oscillation
    /// (Choudhury et al. 2008), % of span.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ellipse_percent_of_span: Option<f64>,
}

/// The verdict for one window of the record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowVerdict {
    /// Sample range `[start, end)` in the whole record.
    pub start: usize,
    /// End of the sample range (exclusive).
    pub end: usize,
    /// Time of the first and last sample, seconds.
    pub t_start: f64,
    /// Time of the last sample, seconds.
    pub t_end: f64,
    /// The window's verdict.
    pub verdict: Verdict,
    /// The probability of a sticky valve (as [`Diagnosis::probability`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
    /// Why (as [`Diagnosis::reasons`]).
    pub reasons: Vec<super::Reason>,
    /// The oscillation period, seconds, when the window oscillates.
    pub period: Option<f64>,
    /// Each family's vote.
    pub votes: Vec<(super::evidence::Family, Vote)>,
}

/// The setpoint read off a record without SP: PV's settled level between the setpoint's steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetpointReadOff {
    /// The samples of the record at which it steps, in order.
    pub steps: Vec<usize>,
    /// Its level from the analysed stretch's start to the first step, then after each step (one
    /// more than `steps`).
    pub levels: Vec<f64>,
}

impl SetpointReadOff {
    /// The setpoint at every sample of `[start, end)` of the record.
    pub fn over(&self, [start, end]: [usize; 2]) -> Vec<f64> {
        (start..end)
            .map(|k| self.levels[self.steps.partition_point(|&s| s <= k)])
            .collect()
    }
}

/// The diagnosis of one loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The answer for the loop.
    pub verdict: Verdict,
    /// The probability of a sticky valve from the verdict's model (`None` where the record could
    /// not be judged).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
    /// Why: the one or two findings that decided the verdict (for `insufficient_data`, why the
    /// record cannot be judged; for `undetermined`, the probability between the thresholds).
    pub reasons: Vec<super::Reason>,
    /// What to do next.
    pub next_step: super::NextStep,
    /// The verdict's model's reading: each statistic's value and its share of the log-odds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub statistics: Option<super::Reading>,
    /// Samples in the record.
    pub samples: usize,
    /// The analysed stretch `[start, end)`: the longest stretch in automatic with usable data
    /// (setpoint changes are kept: they excite the loop).
    pub analysed: [usize; 2],
    /// Every usable stretch, the analysed one among them.
    pub stretches: Vec<[usize; 2]>,
    /// Sampling time, seconds.
    pub ts: f64,
    /// The data-quality gates' findings.
    pub quality: Vec<Finding>,
    /// The oscillation on the analysed stretch (absent when the record is too short to judge).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub oscillation: Option<Oscillation>,
    /// The families of evidence, each with what it measured and its vote (its statistics'
    /// share of the model's log-odds).
    pub families: Vec<FamilyEvidence>,
    /// The shape family's indices (on an oscillating stretch).
    pub indices: Vec<Index>,
    /// The bands a record like this one shows and hides, from OP's noise (on every judged
    /// record; what a `no_stiction` verdict speaks for).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reach: Option<super::Reach>,
    /// The stiction band, when the verdict is `stiction`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band: Option<Band>,
    /// The closed-loop estimate (`quantify`, Stenman exact) behind the band.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quantification: Option<Quantification>,
    /// The samples `[start, end)` the closed-loop estimate used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub quantified: Option<[usize; 2]>,
    /// What of a long record was judged and at what resolution (absent where every sample of
    /// the analysed stretch was): the families' figures in samples are then in means of it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub judged_on: Option<super::averaging::JudgedOn>,
    /// A verdict per window, when the request asks for windows.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub windows: Vec<WindowVerdict>,
    /// Without a recorded setpoint, the setpoint read off OP and PV over the analysed stretch
    /// (`diagnose::setpoint`): where it stepped and the levels between.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub setpoint_read_off: Option<SetpointReadOff>,
    /// The loop's kind (integrating or self-regulating) and where it was read.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_kind: Option<super::loop_kind::LoopKind>,
    /// What the diagnosis had to assume (e.g. no setpoint recorded).
    pub warnings: Vec<String>,
    /// Time the diagnosis took, seconds.
    pub seconds: f64,
}
