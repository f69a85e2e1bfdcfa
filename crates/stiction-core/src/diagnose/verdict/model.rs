//! The verdict's model: the probability of a sticky valve from a few statistics the families
//! measure, one logistic model with monotone effects. Each statistic is read through a few hinges
//! (`max(0, x - knot)`) whose weights are at or above zero, so a larger value never points away
//! from a sticky valve, and the effect can bend (grow, or level off) without a rule. The weights
//! live in `model.json` beside how they were trained: the lab's `verdict` program fits them to
//! simulated records of many kinds together with real plant records and writes the file; the core
//! embeds it and checks it once.

use serde::{Deserialize, Serialize};
use std::sync::OnceLock;

/// A statistic the model reads, each a family's measurement with a physical meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Statistic {
    /// The share of PV's steps that end a stick: OP wound over a level PV, then PV stepped OP's
    /// way (the stick-slip family).
    StickShare,
    /// The sticks found, read as `ln(1 + n)`.
    Sticks,
    /// OP's longest travel, % of span, while PV held off the setpoint without moving towards it
    /// (a valve that does not move at all), read as `ln(1 + x)`.
    Stuck,
    /// The closed-loop fit's improvement with a sticky valve: the share of PV's variance above
    /// its noise that the band adds (the closed-loop fit family).
    FitGain,
    /// The band the closed-loop fit finds, over OP's noise standard deviation, `ln(1 + x)`.
    FitBand,
    /// The closed-loop fit's test ratio (the improvement held against the stiction fit's
    /// residual per independent change), `ln(1 + x)`.
    FitTest,
    /// The oscillation's shape score, -1 (sinusoidal, a linear cause) to 1 (a sticky valve's
    /// triangles and squares); 0 without a cycle.
    CycleShape,
    /// The phase lag, degrees, a valve must add for the identified linear loop to sustain the
    /// observed cycle, where a sticky valve's describing function gives it (at most 90°, the
    /// balance closed); 0 where no valve gives it (the linear-loop family).
    LoopLag,
}

impl Statistic {
    /// The family that measures it.
    pub fn family(self) -> crate::diagnose::Family {
        use crate::diagnose::Family;
        match self {
            Statistic::StickShare | Statistic::Sticks | Statistic::Stuck => Family::StickSlip,
            Statistic::FitGain | Statistic::FitBand | Statistic::FitTest => Family::Model,
            Statistic::CycleShape => Family::Shape,
            Statistic::LoopLag => Family::Loop,
        }
    }

    /// Every statistic, in the model file's order.
    pub const ALL: [Statistic; 8] = [
        Statistic::StickShare,
        Statistic::Sticks,
        Statistic::Stuck,
        Statistic::FitGain,
        Statistic::FitBand,
        Statistic::FitTest,
        Statistic::CycleShape,
        Statistic::LoopLag,
    ];
}

/// One statistic as the model reads it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Input {
    /// Which statistic.
    pub statistic: Statistic,
    /// The value is clipped to this range (the training records' own) before it is read.
    pub range: [f64; 2],
    /// The hinges' knots, ascending.
    pub knots: Vec<f64>,
    /// One weight per knot, each at or above zero (log-odds per unit above the knot).
    pub weights: Vec<f64>,
    /// The value the contributions are measured from (the healthy training records' median); a
    /// statistic not measured reads this, so it moves nothing.
    pub reference: f64,
}

impl Input {
    /// The statistic's effect on the log-odds at `x` (clipped to the range): the hinges' sum.
    pub fn effect(&self, x: f64) -> f64 {
        let x = x.clamp(self.range[0], self.range[1]);
        self.knots
            .iter()
            .zip(&self.weights)
            .map(|(k, w)| w * (x - k).max(0.0))
            .sum()
    }

    /// This statistic's share of the log-odds: its effect at `x` over its effect at the
    /// reference.
    pub fn contribution(&self, x: Option<f64>) -> f64 {
        x.map_or(0.0, |x| self.effect(x) - self.effect(self.reference))
    }
}

/// How the model was trained (written by the lab beside the weights).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Training {
    /// The command that trains it.
    pub command: String,
    /// The training records, in words.
    pub records: String,
    /// The weight of each real record against one simulated record.
    pub real_weight: f64,
    /// The ridge penalty on the weights (inputs scaled to unit spread).
    pub ridge: f64,
    /// Out of fold on the real records (leave-one-loop-out) and in the simulations, in words.
    pub checked: String,
}

/// The verdict's model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VerdictModel {
    /// The log-odds of a record whose statistics all sit at their references.
    pub intercept: f64,
    /// The statistics read, each once.
    pub inputs: Vec<Input>,
    /// From this probability the verdict is `stiction`.
    pub stiction_from: f64,
    /// Under this probability the verdict is `no_stiction`; between the two, `undetermined`.
    pub no_stiction_below: f64,
    /// How it was trained.
    pub training: Training,
}

/// A model file that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A statistic read twice.
    #[error("the verdict's model reads {0:?} twice")]
    Repeated(Statistic),
    /// Knots and weights of different lengths.
    #[error("the verdict's model has {knots} knots but {weights} weights for {statistic:?}")]
    Shape {
        /// The statistic.
        statistic: Statistic,
        /// Its knots.
        knots: usize,
        /// Its weights.
        weights: usize,
    },
    /// A weight below zero (the effects are monotone) or not finite.
    #[error("the verdict's model has a weight below zero or not finite for {0:?}")]
    Weight(Statistic),
    /// Knots out of order, not finite, or a range upside down.
    #[error("the verdict's model has knots out of order or a range upside down for {0:?}")]
    Knots(Statistic),
    /// Thresholds out of order.
    #[error("the verdict's thresholds must satisfy 0 < no_stiction_below <= stiction_from < 1")]
    Thresholds,
    /// The file does not parse.
    #[error("the verdict's model file does not parse: {0}")]
    Parse(String),
}

impl VerdictModel {
    /// Parse and check a model file.
    pub fn from_json(text: &str) -> Result<Self, ModelError> {
        let m: VerdictModel =
            serde_json::from_str(text).map_err(|e| ModelError::Parse(e.to_string()))?;
        m.check()?;
        Ok(m)
    }

    /// The model embedded in the library (`model.json`), checked once.
    pub fn embedded() -> &'static VerdictModel {
        static MODEL: OnceLock<VerdictModel> = OnceLock::new();
        MODEL.get_or_init(|| {
            VerdictModel::from_json(include_str!("model.json"))
                .expect("the embedded verdict model is checked by the tests")
        })
    }

    /// An error naming what is wrong, if anything.
    pub fn check(&self) -> Result<(), ModelError> {
        for (i, input) in self.inputs.iter().enumerate() {
            let s = input.statistic;
            if self.inputs[..i].iter().any(|o| o.statistic == s) {
                return Err(ModelError::Repeated(s));
            }
            if input.knots.len() != input.weights.len() {
                return Err(ModelError::Shape {
                    statistic: s,
                    knots: input.knots.len(),
                    weights: input.weights.len(),
                });
            }
            if input.weights.iter().any(|w| !(w.is_finite() && *w >= 0.0)) {
                return Err(ModelError::Weight(s));
            }
            let ordered = input.knots.windows(2).all(|k| k[0] <= k[1])
                && input.knots.iter().all(|k| k.is_finite())
                && input.range[0] <= input.range[1]
                && input.reference.is_finite();
            if !ordered {
                return Err(ModelError::Knots(s));
            }
        }
        let (lo, hi) = (self.no_stiction_below, self.stiction_from);
        if !(lo > 0.0 && lo <= hi && hi < 1.0 && self.intercept.is_finite()) {
            return Err(ModelError::Thresholds);
        }
        Ok(())
    }

    /// The probability of a sticky valve from the statistics (`value(s)`: `None` where a
    /// statistic was not measured), and every statistic's contribution to the log-odds (0 for one
    /// the model does not read).
    pub fn read(&self, value: impl Fn(Statistic) -> Option<f64>) -> Reading {
        let contributions: Vec<Contribution> = Statistic::ALL
            .into_iter()
            .map(|statistic| {
                let v = value(statistic);
                let input = self.inputs.iter().find(|i| i.statistic == statistic);
                Contribution {
                    statistic,
                    value: v,
                    contribution: input.map_or(0.0, |i| i.contribution(v)),
                }
            })
            .collect();
        let z = self.intercept + contributions.iter().map(|c| c.contribution).sum::<f64>();
        Reading {
            probability: 1.0 / (1.0 + (-z).exp()),
            contributions,
        }
    }
}

/// One statistic's part in a reading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Contribution {
    /// Which statistic.
    pub statistic: Statistic,
    /// Its value as the model reads it (`None`: not measured on this record).
    pub value: Option<f64>,
    /// Its share of the log-odds, from its reference (positive: towards a sticky valve).
    pub contribution: f64,
}

/// The model's reading of one record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reading {
    /// The probability of a sticky valve.
    pub probability: f64,
    /// Every statistic's part, in [`Statistic::ALL`]'s order.
    pub contributions: Vec<Contribution>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_embedded_model_parses_and_reads_every_statistic_once() {
        let m = VerdictModel::embedded();
        assert!(m.check().is_ok());
        for s in Statistic::ALL {
            assert!(m.inputs.iter().filter(|i| i.statistic == s).count() <= 1);
        }
    }

    #[test]
    fn a_larger_statistic_never_lowers_the_probability() {
        let m = VerdictModel::embedded();
        for s in Statistic::ALL {
            let mut last = 0.0;
            for k in 0..50 {
                let x = -2.0 + k as f64 * 0.5;
                let p = m.read(|t| (t == s).then_some(x).or(Some(0.0))).probability;
                assert!(p >= last - 1e-12, "{s:?} at {x}: {p} < {last}");
                last = p;
            }
        }
    }

    #[test]
    fn a_bad_file_names_what_is_wrong() {
        let mut m = VerdictModel::embedded().clone();
        if let Some(i) = m.inputs.first_mut() {
            i.weights[0] = -1.0;
            assert!(matches!(m.check(), Err(ModelError::Weight(_))));
        }
        let mut m = VerdictModel::embedded().clone();
        m.stiction_from = 0.2;
        m.no_stiction_below = 0.5;
        assert_eq!(m.check(), Err(ModelError::Thresholds));
        assert!(matches!(
            VerdictModel::from_json("{"),
            Err(ModelError::Parse(_))
        ));
    }
}
