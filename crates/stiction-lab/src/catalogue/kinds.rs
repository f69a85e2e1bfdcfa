//! The catalogue's vocabulary: classes, truths, loop kinds, noise levels, excitations, tunings,
//! and the benchmark loop itself.

use super::{Set, Suite};
use serde::{Deserialize, Serialize};
use std::fmt;
use stiction_core::sim::{ClosedLoop, LoopData};

/// What is wrong (or not) with the loop, as the benchmark tables group it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopClass {
    /// Sticky valve, Stenman's model (band `d`).
    StenmanValve,
    /// Sticky valve, Kano et al.'s model (`S`, `J > 0`).
    KanoValve,
    /// Sticky valve, He et al.'s model (`fs`, `fd`).
    HeValve,
    /// A dead band without slip jump (Kano, `J = 0`): outside the goals.
    BacklashValve,
    /// Healthy valve, nothing special.
    Healthy,
    /// Healthy valve with an equal-percentage characteristic (the loop gain moves with OP).
    EqualPercentage,
    /// PV rounded to a resolution (at the sensor or in the historian).
    QuantisedPv,
    /// PV (and sometimes OP) stored by deadband or swinging-door compression.
    CompressedPv,
    /// A slow process with a long dead time (temperature, analyser).
    SlowLongDelay,
    /// A tight tuning with little margin: lightly damped responses.
    AggressiveTuning,
    /// An external oscillation (sine or narrow-band noise) entering as load or on PV.
    ExternalOscillation,
    /// Tuning at the stability limit: the linear loop grows or drifts in amplitude.
    NearUnstable,
    /// OP held at 0 or 100 % for part of the record.
    SaturatedOp,
    /// The inner loop of a cascade: its setpoint moves with the outer loop.
    CascadeInner,
    /// Healthy valve with a load that changes in steps OP does not explain (a feed rate or an
    /// upstream pressure that jumps): PV kicks at each step while OP answers it.
    LoadSteps,
    /// Healthy valve whose controller adds a feed-forward of a measured load that jumps in
    /// steps: OP moves with the load while PV, the load compensated, hardly does.
    FeedForward,
}

impl LoopClass {
    /// Every class, in catalogue order.
    pub const ALL: [LoopClass; 16] = [
        Self::StenmanValve,
        Self::KanoValve,
        Self::HeValve,
        Self::BacklashValve,
        Self::Healthy,
        Self::EqualPercentage,
        Self::QuantisedPv,
        Self::CompressedPv,
        Self::SlowLongDelay,
        Self::AggressiveTuning,
        Self::ExternalOscillation,
        Self::NearUnstable,
        Self::SaturatedOp,
        Self::CascadeInner,
        Self::LoadSteps,
        Self::FeedForward,
    ];

    /// The truth a verdict on this class is judged against.
    pub fn truth(self) -> Truth {
        match self {
            Self::StenmanValve | Self::KanoValve | Self::HeValve => Truth::Sticky,
            Self::BacklashValve => Truth::BacklashOnly,
            _ => Truth::NotSticky,
        }
    }

    /// The name used in tables, ids and on command lines (as serialised).
    pub fn name(self) -> &'static str {
        match self {
            Self::StenmanValve => "stenman_valve",
            Self::KanoValve => "kano_valve",
            Self::HeValve => "he_valve",
            Self::BacklashValve => "backlash_valve",
            Self::Healthy => "healthy",
            Self::EqualPercentage => "equal_percentage",
            Self::QuantisedPv => "quantised_pv",
            Self::CompressedPv => "compressed_pv",
            Self::SlowLongDelay => "slow_long_delay",
            Self::AggressiveTuning => "aggressive_tuning",
            Self::ExternalOscillation => "external_oscillation",
            Self::NearUnstable => "near_unstable",
            Self::SaturatedOp => "saturated_op",
            Self::CascadeInner => "cascade_inner",
            Self::LoadSteps => "load_steps",
            Self::FeedForward => "feed_forward",
        }
    }
}

impl fmt::Display for LoopClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for LoopClass {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|c| c.name()).collect();
                format!(
                    "unknown loop class '{s}'; the classes are {}",
                    names.join(", ")
                )
            })
    }
}

/// The truth a verdict is judged against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Truth {
    /// A sticky valve: the verdict should be `stiction`.
    Sticky,
    /// No sticky valve: a `stiction` verdict is a false alarm.
    NotSticky,
    /// A dead band without slip jump: neither goal applies.
    BacklashOnly,
}

impl Truth {
    /// The name used in tables (as serialised).
    pub fn name(self) -> &'static str {
        match self {
            Self::Sticky => "sticky",
            Self::NotSticky => "not_sticky",
            Self::BacklashOnly => "backlash_only",
        }
    }
}

/// The plant loop the simulation stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LoopKind {
    /// A flow loop.
    Flow,
    /// A pressure loop.
    Pressure,
    /// A level (integrating process).
    Level,
    /// A temperature loop.
    Temperature,
    /// An analyser loop.
    Analyser,
    /// A cooling-water loop.
    CoolingWater,
}

impl LoopKind {
    /// The name used in tables (as serialised).
    pub fn name(self) -> &'static str {
        match self {
            Self::Flow => "flow",
            Self::Pressure => "pressure",
            Self::Level => "level",
            Self::Temperature => "temperature",
            Self::Analyser => "analyser",
            Self::CoolingWater => "cooling_water",
        }
    }
}

/// Standard deviation of the PV's measurement noise, % of span.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseLevel {
    /// 0.03 %.
    Low,
    /// 0.1 %.
    Medium,
    /// 0.3 %.
    High,
}

impl NoiseLevel {
    /// Every level, low to high.
    pub const ALL: [NoiseLevel; 3] = [Self::Low, Self::Medium, Self::High];

    /// The PV noise's standard deviation, % of span.
    pub fn std(self) -> f64 {
        match self {
            Self::Low => 0.03,
            Self::Medium => 0.1,
            Self::High => 0.3,
        }
    }
}

/// What keeps the loop moving during the record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Excitation {
    /// Setpoint step sequences at random levels and times.
    SetpointSteps,
    /// A slow load drift (integrated random walk).
    LoadDrift,
    /// A load ramp.
    LoadRamp,
    /// Setpoint steps and a load drift.
    StepsAndDrift,
    /// Regulation at a setpoint with rare small steps and a little load drift (fast loops).
    Regulation,
    /// Load steps in place of the drawn load, at a constant setpoint (the look-alikes with load
    /// steps, and with them fed forward).
    LoadSteps,
    /// Setpoint steps, and load steps in place of the drawn load.
    StepsAndLoadSteps,
}

impl Excitation {
    /// The excitation once load steps replace the drawn load: the setpoint's part stays.
    pub fn with_load_steps(self) -> Self {
        match self {
            Self::SetpointSteps | Self::StepsAndDrift | Self::StepsAndLoadSteps => {
                Self::StepsAndLoadSteps
            }
            Self::LoadDrift | Self::LoadRamp | Self::LoadSteps => Self::LoadSteps,
            Self::Regulation => Self::Regulation,
        }
    }
}

/// How the controller was tuned.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case")]
pub enum Tuning {
    /// SIMC (Skogestad 2003) for closed-loop time constant `lambda` seconds.
    Simc {
        /// The closed-loop time constant, seconds.
        lambda: f64,
    },
    /// `Kc = fraction * Ku` at the chosen integral time; `ku`, `pu` of the linear loop.
    Ultimate {
        /// Kc over the ultimate gain.
        fraction: f64,
        /// The ultimate gain: the Kc at which the linear loop reaches its stability limit.
        ku: f64,
        /// The ultimate period: the period it then oscillates with, seconds.
        pu: f64,
    },
}

/// One benchmark loop: what it is, how it was made, and its record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BenchmarkLoop {
    /// `routine-b-0042` (suite, b = benchmark or c = calibration, index), or `issue14`.
    pub id: String,
    /// Which suite the loop belongs to.
    pub suite: Suite,
    /// Benchmark or calibration seeds.
    pub set: Set,
    /// What is wrong (or not) with the loop.
    pub class: LoopClass,
    /// The truth its verdict is judged against.
    pub truth: Truth,
    /// The plant loop it stands for.
    pub kind: LoopKind,
    /// The parameters in words.
    pub description: String,
    /// The process is integrating (for `diagnose`'s `integrating`).
    pub integrating: bool,
    /// The PV's measurement noise.
    pub noise_level: NoiseLevel,
    /// What keeps the loop moving.
    pub excitation: Excitation,
    /// How the controller was tuned.
    pub tuning: Tuning,
    /// Everything the simulation used: valve model and parameters (% of span), process, PI,
    /// noise, signals, plant features. `setup.run()` gives `data` again.
    pub setup: ClosedLoop,
    /// Times the valve broke away within the record.
    pub slips: usize,
    /// Share of the record's controller executions with OP at 0 or 100 %.
    pub saturated: f64,
    /// Draws made before a sticky valve showed what its suite asks (1 for other loops).
    pub attempts: u64,
    /// The cycle the same loop keeps without measurement noise, if any.
    pub cycle: Option<Cycle>,
    /// A sticky valve's slip visibility: how far its slips move PV, in the recorded PV's noise
    /// standard deviations (`plant::slip_visibility`); `None` for other valves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visibility: Option<f64>,
    /// The record: t, sp, op, mv, pv.
    pub data: LoopData,
}

impl BenchmarkLoop {
    /// The record's sampling time, seconds.
    pub fn ts(&self) -> f64 {
        self.setup.ts
    }
}

/// A cycle of the control error (see `cycle_of` in the catalogue's sources).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cycle {
    /// Mean period, seconds.
    pub period: f64,
    /// Standard deviation of the periods over their mean (0 for a perfectly regular cycle).
    pub spread: f64,
    /// Half the 5-95 percentile range of the control error, % of span.
    pub amplitude: f64,
}
