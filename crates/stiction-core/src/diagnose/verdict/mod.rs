//! The verdict: one calibrated model reads a few statistics the families measure and gives the
//! probability of a sticky valve ([`model`]); the verdict is `stiction` from the model's upper
//! threshold, `no_stiction` under its lower one, `undetermined` between. Where the valve position
//! is recorded its family decides (it measures the valve itself). Each family's vote is what its
//! statistics did to the log-odds: towards a sticky valve by at least [`VOTE`], or not. No rule
//! overrides the model, and no family reads another's result.

mod model;
mod statistics;

pub use model::{Contribution, Input, ModelError, Reading, Statistic, Training, VerdictModel};
pub(super) use statistics::Measured;

use super::evidence::{Family, FamilyEvidence};
use super::reasons::{Action, Finding, NextStep, Reason};
use super::result::{Verdict, Vote};

/// A family whose statistics move the log-odds towards a sticky valve by at least this much
/// votes stiction (a factor of about 1.6 on the odds); measured and short of it, no stiction.
pub const VOTE: f64 = 0.5;
/// At most this many findings are named as the verdict's reasons.
const NAMED: usize = 2;

/// What the verdict decides.
pub(super) struct Decision {
    pub verdict: Verdict,
    pub probability: Option<f64>,
    pub reading: Option<Reading>,
    pub reasons: Vec<Reason>,
    pub next_step: NextStep,
}

/// What the oscillation and the record tell a verdict besides the statistics.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Motion {
    /// A regular cycle too short in samples for any family (its period, s, and samples per
    /// period): at a few samples a cycle passes for measurement noise.
    pub unresolved_cycle: Option<(f64, f64)>,
    /// The setpoint is recorded and holds over the whole stretch.
    pub setpoint_steady: bool,
    /// The share of PV samples that look not recorded, when over the quality gate's limit.
    pub pv_not_recorded: Option<f64>,
    /// The oscillation's period, seconds, when the loop oscillates.
    pub period: Option<f64>,
    /// The analysed stretch, minutes.
    pub minutes: f64,
    /// Sampling time, seconds.
    pub ts: f64,
}

/// Thornhill's regularity from which a cycle of under [`UNRESOLVED_SAMPLES`] samples a period is
/// named as unresolved.
const UNRESOLVED_REGULARITY: f64 = 5.0;
/// A cycle of fewer samples than this a period is not resolved.
const UNRESOLVED_SAMPLES: f64 = 4.0;

impl Motion {
    /// From the oscillation of the analysed stretch of `samples`, sampled every `ts` seconds,
    /// and its setpoint when recorded.
    pub fn of(osc: &super::Oscillation, ts: f64, sp: Option<&[f64]>, samples: usize) -> Self {
        Self {
            unresolved_cycle: unresolved_cycle(osc, ts),
            setpoint_steady: sp.is_some_and(|sp| sp.windows(2).all(|w| w[1] == w[0])),
            pv_not_recorded: None,
            period: osc.oscillating.then_some(osc.period).flatten(),
            minutes: samples as f64 * ts / 60.0,
            ts,
        }
    }

    /// The same, with the share of PV samples not recorded when it is over `limit`.
    pub fn with_pv_not_recorded(self, share: f64, limit: f64) -> Self {
        Self {
            pv_not_recorded: (share > limit).then_some(share),
            ..self
        }
    }
}

/// A regular cycle of fewer than [`UNRESOLVED_SAMPLES`] samples a period in `osc` (sampled every
/// `ts` seconds): its period, s, and samples per period.
pub(crate) fn unresolved_cycle(osc: &super::Oscillation, ts: f64) -> Option<(f64, f64)> {
    let r = &osc.regularity;
    r.period
        .map(|p| (p, p / ts))
        .filter(|&(_, samples)| samples < UNRESOLVED_SAMPLES)
        .filter(|_| {
            r.regularity >= UNRESOLVED_REGULARITY && r.regularity < crate::detect::REGULARITY_CAP
        })
}

/// Each family's vote and strength from its statistics' share of the log-odds (the valve family
/// keeps its own: it decides; the hidden valve's is its own, read by no one).
fn set_votes(families: &mut [FamilyEvidence], reading: &Reading, read: &[Statistic]) {
    for f in families.iter_mut() {
        if matches!(f.family, Family::Valve | Family::HiddenValve) {
            continue;
        }
        let parts: Vec<&Contribution> = reading
            .contributions
            .iter()
            .filter(|c| c.statistic.family() == f.family && c.value.is_some())
            .filter(|c| read.contains(&c.statistic))
            .collect();
        if parts.is_empty() {
            (f.vote, f.strength, f.contribution) = (Vote::Undetermined, 0.0, None);
            continue;
        }
        let c: f64 = parts.iter().map(|c| c.contribution).sum();
        f.vote = if c >= VOTE {
            Vote::Stiction
        } else {
            Vote::NoStiction
        };
        f.strength = 1.0 - (-c.abs()).exp();
        f.contribution = Some(c);
    }
}

/// Decide from the families' statistics (`measured`) and what the oscillation shows.
pub(super) fn decide(
    families: &mut [FamilyEvidence],
    measured: &Measured,
    motion: &Motion,
) -> Decision {
    let model = VerdictModel::embedded();
    let reading = model.read(|s| measured.get(s));
    let read: Vec<Statistic> = model.inputs.iter().map(|i| i.statistic).collect();
    set_votes(families, &reading, &read);
    let p = reading.probability;
    let valve = families
        .iter()
        .find(|f| f.family == Family::Valve && f.vote != Vote::Undetermined);
    if let Some(v) = valve {
        let sticky = v.vote == Vote::Stiction;
        let band = v
            .valve
            .as_ref()
            .map(|e| e.d_percent_of_span)
            .filter(|_| sticky);
        return Decision {
            verdict: if sticky {
                Verdict::Stiction
            } else {
                Verdict::NoStiction
            },
            probability: Some(p),
            reasons: vec![Reason::plain(Finding::ValvePosition {
                band_percent_of_span: band,
                sticky,
            })],
            next_step: NextStep::plain(if sticky {
                Action::MaintainValve
            } else {
                Action::NoAction
            }),
            reading: Some(reading),
        };
    }
    if !measured.any() {
        let (finding, action) = match motion.unresolved_cycle {
            Some((period, samples)) => (
                Finding::UnresolvedCycle { period, samples },
                Action::SampleFaster,
            ),
            None => (Finding::NotExcited, Action::LongerRecord),
        };
        let mut next = NextStep::plain(action);
        next.sample_every = motion.unresolved_cycle.map(|(period, _)| period / 10.0);
        return Decision {
            verdict: Verdict::InsufficientData,
            probability: None,
            reading: None,
            reasons: vec![Reason::plain(finding)],
            next_step: next,
        };
    }
    let verdict = if p >= model.stiction_from {
        Verdict::Stiction
    } else if p < model.no_stiction_below {
        Verdict::NoStiction
    } else {
        Verdict::Undetermined
    };
    let reasons = reasons(verdict, &reading, families, measured, motion, model);
    let next_step = next_step(verdict, p, &reading, motion, model);
    Decision {
        verdict,
        probability: Some(p),
        reading: Some(reading),
        reasons,
        next_step,
    }
}

/// The findings a group of statistics is told by: the sticks (their share and count), the hold,
/// the fit (its gain, band or test), the cycle's shape, the loop's lag.
fn group(s: Statistic) -> u8 {
    match s {
        Statistic::StickShare | Statistic::Sticks => 0,
        Statistic::Stuck => 1,
        Statistic::FitGain | Statistic::FitBand | Statistic::FitTest => 2,
        Statistic::CycleShape => 3,
        Statistic::LoopLag => 4,
    }
}

/// The verdict's reasons: the findings that moved the log-odds most its way.
fn reasons(
    verdict: Verdict,
    reading: &Reading,
    families: &[FamilyEvidence],
    measured: &Measured,
    motion: &Motion,
    model: &VerdictModel,
) -> Vec<Reason> {
    // each group's total and its strongest statistic
    let mut groups: Vec<(f64, Statistic)> = Vec::new();
    for g in 0..5u8 {
        let parts: Vec<&Contribution> = reading
            .contributions
            .iter()
            .filter(|c| group(c.statistic) == g && c.value.is_some())
            .collect();
        if let Some(top) = parts
            .iter()
            .max_by(|a, b| a.contribution.abs().total_cmp(&b.contribution.abs()))
        {
            groups.push((parts.iter().map(|c| c.contribution).sum(), top.statistic));
        }
    }
    let toward = verdict == Verdict::Stiction || verdict == Verdict::Undetermined;
    groups.retain(|(c, _)| if toward { *c >= VOTE } else { *c <= -VOTE });
    groups.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
    let mut out: Vec<Reason> = groups
        .iter()
        .take(NAMED)
        .filter_map(|&(c, s)| {
            statistics::finding(s, families, measured, motion).map(|finding| Reason {
                finding,
                contribution: Some(c),
                text: String::new(),
            })
        })
        .collect();
    match verdict {
        Verdict::Undetermined => out.insert(
            0,
            Reason::plain(Finding::Between {
                probability: reading.probability,
                below: model.no_stiction_below,
                from: model.stiction_from,
            }),
        ),
        Verdict::NoStiction if out.is_empty() => {
            out.push(Reason::plain(Finding::NothingOfAStickyValve))
        }
        _ => {}
    }
    out
}

/// What to do next.
fn next_step(
    verdict: Verdict,
    p: f64,
    reading: &Reading,
    motion: &Motion,
    model: &VerdictModel,
) -> NextStep {
    let sinusoidal = reading
        .contributions
        .iter()
        .any(|c| c.statistic == Statistic::CycleShape && c.contribution <= -VOTE);
    let action = match verdict {
        Verdict::Stiction => Action::TravelTest,
        // a cycle of a few samples hides a valve's sticks from every family
        Verdict::NoStiction | Verdict::Undetermined if motion.unresolved_cycle.is_some() => {
            Action::SampleFaster
        }
        Verdict::NoStiction if sinusoidal => Action::CheckTuning,
        // nearer the undetermined band than to a clear healthy valve
        Verdict::NoStiction if p >= model.no_stiction_below / 2.0 => Action::NoActionWeak,
        Verdict::NoStiction => Action::NoAction,
        Verdict::Undetermined => Action::SettleIt,
        Verdict::InsufficientData => Action::LongerRecord,
    };
    let weak = matches!(action, Action::NoActionWeak | Action::SettleIt);
    NextStep {
        action,
        setpoint_steady: weak && motion.setpoint_steady,
        pv_not_recorded: motion
            .pv_not_recorded
            .filter(|_| verdict != Verdict::Stiction),
        sample_every: (action == Action::SampleFaster)
            .then(|| motion.unresolved_cycle.map(|(period, _)| period / 10.0))
            .flatten(),
        text: String::new(),
    }
}
