//! The families' statistics read together: gradient-boosted trees, trained on simulated loops
//! of many kinds (the catalogue's calibration draws, routine and fast; never the ISDB), give the
//! probability of a sticky valve from the 45 statistics the families report
//! (`features::NAMES`). The verdict's rules read each family's vote and a few of its figures;
//! the trees also read how the figures go together (a closed-loop fit's test ratio between its
//! thresholds while the stick-slip episodes and the oscillation's amplitude say more), which
//! finds sticky valves the rules leave `no_stiction` or `undetermined`.
//!
//! The trees only ever add a `stiction` verdict, and only from a probability calibrated to add few
//! look-alikes: out of fold on their training loops, under one healthy loop in 200. They never take
//! one away, never decide where the valve position is recorded, and never decide against stiction:
//! a learned combination does not hold where the catalogue does not teach it
//! (stiction-lab/journal/accuracy-history.md, "A learned combination of the families' statistics":
//! as the whole verdict it lost ISDB loops whose statistics the catalogue has no example of), so
//! its low probabilities are no evidence. Where it decides, the verdict names the statistics that
//! weighed most.

pub mod features;
mod forest;

pub use forest::forest;

use super::evidence::{Family, FamilyEvidence};
use super::result::{Verdict, Vote};
use serde::{Deserialize, Serialize};

/// One statistic as the trees read it, and how much it moved their log-odds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Statistic {
    /// Its name (`features::NAMES`).
    pub name: String,
    /// Its value as the trees read it (log-scaled ones on their log scale).
    pub value: f64,
    /// Its share of the trees' log-odds (Saabas' path contributions; positive: towards a sticky
    /// valve).
    pub contribution: f64,
}

/// What the trees found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CombinedEvidence {
    /// The trees' probability of a sticky valve.
    pub probability: f64,
    /// From this probability the rules' verdict becomes `stiction` (the trees' threshold for it:
    /// lower where the rules are `undetermined` than where they say `no_stiction`).
    pub threshold: f64,
    /// Whether the trees turned the verdict to `stiction`.
    pub decided: bool,
    /// The rules' verdict, when the trees turned it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub before: Option<Verdict>,
    /// Every statistic read, in the trees' order.
    pub statistics: Vec<Statistic>,
    /// How the trees and the threshold were set.
    pub calibration: String,
}

/// How many statistics the verdict's reason names.
const NAMED: usize = 3;

impl CombinedEvidence {
    /// The trees' reading of one judged stretch; `None` without trained trees.
    pub fn of(stretch: &features::Stretch) -> Option<Self> {
        let forest = forest()?;
        let x = features::of(stretch);
        let reading = forest.read(&x)?;
        Some(Self {
            probability: reading.probability,
            threshold: forest.threshold,
            decided: false,
            before: None,
            statistics: features::NAMES
                .iter()
                .zip(x)
                .zip(reading.contributions)
                .map(|((&(name, ..), value), contribution)| Statistic {
                    name: name.into(),
                    value,
                    contribution,
                })
                .collect(),
            calibration: forest.calibration.clone(),
        })
    }

    /// Hold the trees to their threshold for the rules' `verdict` (the forest's `threshold_for`).
    pub fn for_verdict(&mut self, verdict: Verdict) {
        if let Some(f) = forest() {
            self.threshold = f.threshold_for(verdict);
        }
    }

    /// Whether the trees turn `verdict` to `stiction`: their probability reaches the threshold,
    /// the rules did not already say `stiction` or find nothing to judge, no recorded valve
    /// position decided, and OP drives PV (where no valve, sticky or not, lets OP explain PV's
    /// variation, it enters the loop elsewhere: the trees never saw such a loop called sticky).
    pub fn decides(&self, verdict: Verdict, families: &[FamilyEvidence]) -> bool {
        let valve_voted = families
            .iter()
            .any(|f| f.family == Family::Valve && f.vote != Vote::Undetermined);
        self.probability >= self.threshold
            && matches!(verdict, Verdict::NoStiction | Verdict::Undetermined)
            && !valve_voted
            && !super::verdict::op_does_not_drive(families)
    }

    /// The verdict's reason when the trees decide.
    pub fn reason(&self, before: Verdict) -> String {
        format!(
            "the families' statistics read together call the valve sticky: trees trained on simulated loops give a sticky valve a \
             probability of {:.2} (stiction from {:.2}), most of all from {}; the rules alone said {}",
            self.probability,
            self.threshold,
            self.leading(),
            before.as_str()
        )
    }

    /// The statistics that weighed most towards a sticky valve, in words with their values.
    pub fn leading(&self) -> String {
        let mut order: Vec<&Statistic> = self.statistics.iter().collect();
        order.sort_by(|a, b| b.contribution.total_cmp(&a.contribution));
        let words: Vec<String> = order
            .iter()
            .take(NAMED)
            .filter(|s| s.contribution > 0.0)
            .map(|s| match features::NAMES.iter().find(|n| n.0 == s.name) {
                Some(&(_, words, scale)) => format!("{words} ({})", shown(s, scale)),
                None => format!("{} ({})", s.name, Sig3(s.value)),
            })
            .collect();
        match words.as_slice() {
            [] => "no single statistic".into(),
            [one] => one.clone(),
            [init @ .., last] => format!("{} and {last}", init.join(", ")),
        }
    }

    /// The trees' vote: stiction from the threshold, else none (they never vote against).
    pub fn vote(&self) -> Vote {
        if self.probability >= self.threshold {
            Vote::Stiction
        } else {
            Vote::Undetermined
        }
    }

    /// What the trees did to the verdict, in words.
    pub fn role(&self) -> &'static str {
        match (self.decided, self.vote()) {
            (true, _) => "the trees decided the verdict",
            (false, Vote::Stiction) => "the rules had already decided",
            _ => "the trees only ever add a stiction verdict",
        }
    }

    /// One line for the evidence list.
    pub fn line(&self) -> String {
        format!(
            "statistics combined: {} (probability of a sticky valve {:.2}; stiction from {:.2}; {})",
            match self.vote() {
                Vote::Stiction => "stiction",
                _ => "no vote",
            },
            self.probability,
            self.threshold,
            self.role()
        )
    }
}

/// A statistic's value as a person reads it: votes as words, the others on their own scale.
fn shown(s: &Statistic, scale: features::Scale) -> String {
    if scale == features::Scale::Vote {
        return match s.value {
            v if v > 0.5 => "stiction".into(),
            v if v < -0.5 => "none".into(),
            _ => "undetermined".into(),
        };
    }
    if scale == features::Scale::Index && s.value <= features::NOT_COMPUTED {
        return "not computed".into();
    }
    format!("{}", Sig3(scale.undo(s.value)))
}

/// Three significant figures.
struct Sig3(f64);

impl std::fmt::Display for Sig3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v == 0.0 || !v.is_finite() {
            return write!(f, "{v}");
        }
        let digits = (2 - v.abs().log10().floor() as i32).max(0) as usize;
        write!(f, "{v:.digits$}")
    }
}

#[cfg(test)]
mod tests;
