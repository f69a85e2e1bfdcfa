//! The verdict from the families: families that agree give `stiction` or `no_stiction` with a
//! confidence; families that conflict give `undetermined`, naming the conflict. The valve family
//! (the recorded valve position) outweighs the indirect ones, then the hidden valve's stiction
//! vote (with `thorough`). Against the loop family's evidence
//! of a non-linearity, the shape, fit and stick-slip votes against stiction count only weakly.
//! A family whose statistic lies between its thresholds casts no vote but says which way it
//! leans: with no vote cast, such a record is `undetermined` (judged, too weak to decide), not
//! `insufficient_data` (nothing could be judged).

use super::evidence::{Family, FamilyEvidence};
use super::result::{Verdict, Vote};

mod next_step;
use next_step::next_step;
pub(super) use next_step::op_does_not_drive;

/// What the families decide.
pub(super) struct Decision {
    pub verdict: Verdict,
    pub confidence: Option<f64>,
    pub reason: Option<String>,
    pub evidence: Vec<String>,
    pub next_step: String,
}

/// A side of a conflict wins when its total strength is at least this many times the other's and
/// no single vote against it is stronger than `WEAK_DISSENT`.
const DOMINANCE: f64 = 1.0;
pub(super) const WEAK_DISSENT: f64 = 0.5;
/// A stiction verdict needs at least one vote this strong.
const DECIDES: f64 = 0.5;

/// Against the loop family's evidence of a non-linearity that sustains the cycle, a vote against
/// stiction that reads the cycle's shape or a fit (shape, model, stick-slip) counts at most this:
/// a fast loop's valve can stick for less than a sample, which leaves the cycle near-sinusoidal,
/// the fits with and without a band alike and no stick-slip episode to find (detection.md, "A
/// limit cycle that no linear loop can sustain").
const BLIND_AGAINST_LOOP: f64 = 0.15;

/// A vote's strength in the verdict: its own, unless it is one of the votes against stiction
/// that held loop evidence for it (`loop_holds`: a stiction vote of strength 0.5 or more)
/// outweighs. Weaker loop evidence (no setpoint recorded) only keeps them from deciding.
fn weight(f: &FamilyEvidence, loop_holds: bool) -> f64 {
    let blind = matches!(f.family, Family::Shape | Family::Model | Family::StickSlip);
    if loop_holds && blind && f.vote == Vote::NoStiction {
        f.strength.min(BLIND_AGAINST_LOOP)
    } else {
        f.strength
    }
}

/// Independent evidence: the chance that every supporting family is wrong, taken as the product.
fn combined(strengths: impl Iterator<Item = f64>) -> f64 {
    1.0 - strengths.fold(1.0, |p, s| p * (1.0 - s.clamp(0.0, 0.99)))
}

fn names(fams: &[&FamilyEvidence]) -> String {
    let words: Vec<&str> = fams.iter().map(|f| f.family.words()).collect();
    match words.as_slice() {
        [] => String::new(),
        [one] => one.to_string(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// One line per family: its name, vote and note.
fn evidence_lines(families: &[FamilyEvidence]) -> Vec<String> {
    families
        .iter()
        .map(|f| {
            format!(
                "{}: {} ({})",
                f.family.words(),
                match f.vote {
                    Vote::Stiction => "stiction",
                    Vote::NoStiction => "no stiction",
                    Vote::Undetermined => "undetermined",
                },
                f.note
            )
        })
        .collect()
}

/// The recorded valve position decides when its family votes: the verdict, and a confidence
/// from 0.8 (every other voting family against) to 1 (all agree).
fn by_valve(families: &[FamilyEvidence]) -> Option<(Verdict, f64)> {
    let valve = families
        .iter()
        .find(|f| f.family == Family::Valve && f.vote != Vote::Undetermined)?;
    let others: Vec<&FamilyEvidence> = families
        .iter()
        .filter(|f| f.family != Family::Valve && f.vote != Vote::Undetermined)
        .collect();
    let agree = others.iter().filter(|f| f.vote == valve.vote).count();
    let share = if others.is_empty() {
        1.0
    } else {
        agree as f64 / others.len() as f64
    };
    let verdict = if valve.vote == Vote::Stiction {
        Verdict::Stiction
    } else {
        Verdict::NoStiction
    };
    Some((verdict, 0.8 + 0.2 * share))
}

/// The hidden-valve family's stiction vote decides (its threshold lies above every look-alike of
/// the calibration sets, and the families it overrules read the recorded OP as the valve's input,
/// which is what it shows to be wrong): the confidence, from 0.6 (every other voting family
/// against) to 0.9 (all agree).
fn by_hidden_valve(families: &[FamilyEvidence]) -> Option<f64> {
    families
        .iter()
        .find(|f| f.family == Family::HiddenValve && f.vote == Vote::Stiction)?;
    let others: Vec<&FamilyEvidence> = families
        .iter()
        .filter(|f| f.family != Family::HiddenValve && f.vote != Vote::Undetermined)
        .collect();
    let agree = others.iter().filter(|f| f.vote == Vote::Stiction).count();
    let share = if others.is_empty() {
        1.0
    } else {
        agree as f64 / others.len() as f64
    };
    Some(0.6 + 0.3 * share)
}

/// What the oscillation tells a verdict that no family could judge.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Motion {
    /// The loop oscillates, so a record no family could judge is not short of excitation.
    pub oscillating: bool,
    /// A regular cycle too short in samples for any family (its period, s, and samples per
    /// period): the control error's autocorrelation shows it, but at a few samples a cycle it
    /// passes for measurement noise.
    pub unresolved_cycle: Option<(f64, f64)>,
    /// The setpoint is recorded and holds over the whole stretch: nothing but the load and the
    /// noise moves the loop, and the fits must tell the process from the load in closed loop
    /// (on the plant benchmark a sticky valve is called `stiction` in 26-50 % of such windows,
    /// 61-76 % of those with setpoint steps).
    pub setpoint_steady: bool,
    /// The share of PV samples that look not recorded (historian compression or a frozen
    /// transmitter), when over the quality gate's limit ([`crate::quality::Limits`]'s
    /// `repeated_share`): compression hides a sticky valve's sticks, which the next step says.
    pub pv_not_recorded: Option<f64>,
}

/// Thornhill's regularity from which a cycle of under [`UNRESOLVED_SAMPLES`] samples a period is
/// named in an `insufficient_data` reason. On the plant benchmark such cycles (regularity 5 to
/// 40) are sticky valves' limit cycles recorded every 10 s and loops tuned at their stability
/// limit, which the record is sampled too slowly to tell apart.
const UNRESOLVED_REGULARITY: f64 = 5.0;
/// A cycle of fewer samples than this a period is not resolved.
const UNRESOLVED_SAMPLES: f64 = 4.0;

impl Motion {
    /// From the oscillation of the analysed stretch, sampled every `ts` seconds, and its
    /// setpoint when recorded.
    pub fn of(osc: &super::Oscillation, ts: f64, sp: Option<&[f64]>) -> Self {
        Self {
            oscillating: osc.oscillating,
            unresolved_cycle: unresolved_cycle(osc, ts),
            setpoint_steady: sp.is_some_and(|sp| sp.windows(2).all(|w| w[1] == w[0])),
            pv_not_recorded: None,
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

/// Decide from the families' votes and what the oscillation shows (`motion`).
pub(super) fn decide(families: &[FamilyEvidence], motion: &Motion) -> Decision {
    let evidence = evidence_lines(families);
    let of =
        |v: Vote| -> Vec<&FamilyEvidence> { families.iter().filter(|f| f.vote == v).collect() };
    let (pro, con) = (of(Vote::Stiction), of(Vote::NoStiction));
    if let Some((verdict, confidence)) = by_valve(families) {
        return Decision {
            verdict,
            confidence: Some(confidence),
            reason: None,
            next_step: next_step(verdict, Some(confidence), families, motion),
            evidence,
        };
    }
    if let Some(confidence) = by_hidden_valve(families) {
        return Decision {
            verdict: Verdict::Stiction,
            confidence: Some(confidence),
            reason: None,
            next_step: next_step(Verdict::Stiction, Some(confidence), families, motion),
            evidence,
        };
    }
    let loop_pro = pro.iter().any(|f| f.family == Family::Loop);
    let loop_holds = pro
        .iter()
        .any(|f| f.family == Family::Loop && f.strength >= 0.5);
    let w = |f: &&FamilyEvidence| weight(f, loop_holds);
    let total = |fs: &[&FamilyEvidence]| fs.iter().map(w).sum::<f64>();
    let strongest = |fs: &[&FamilyEvidence]| fs.iter().map(w).fold(0.0, f64::max);
    let leaning: Vec<&FamilyEvidence> = families
        .iter()
        .filter(|f| f.vote == Vote::Undetermined && f.leans.is_some())
        .collect();
    let (verdict, confidence, reason) = match (pro.is_empty(), con.is_empty()) {
        (true, true) => {
            let (verdict, reason) = without_votes(families, &leaning, motion);
            (verdict, None, Some(reason))
        }
        (false, true) if strongest(&pro) < DECIDES => (
            Verdict::Undetermined,
            None,
            Some(format!(
                "only weak evidence points to stiction ({}), nothing against it",
                names(&pro)
            )),
        ),
        (false, true) => (Verdict::Stiction, Some(combined(pro.iter().map(w))), None),
        (true, false) => (Verdict::NoStiction, Some(combined(con.iter().map(w))), None),
        (false, false) => {
            let (p, c) = (total(&pro), total(&con));
            if p >= DOMINANCE * c && strongest(&con) <= WEAK_DISSENT && strongest(&pro) >= DECIDES {
                (
                    Verdict::Stiction,
                    Some(combined(pro.iter().map(w)) * (1.0 - c / (p + c))),
                    None,
                )
            } else if c >= DOMINANCE * p && strongest(&pro) <= WEAK_DISSENT && !loop_pro {
                (
                    Verdict::NoStiction,
                    Some(combined(con.iter().map(w)) * (1.0 - p / (p + c))),
                    None,
                )
            } else {
                (
                    Verdict::Undetermined,
                    None,
                    Some(format!(
                        "the families disagree: {} point to stiction, {} do not",
                        names(&pro),
                        names(&con)
                    )),
                )
            }
        }
    };
    Decision {
        verdict,
        confidence,
        reason,
        next_step: next_step(verdict, confidence, families, motion),
        evidence,
    }
}

/// The rules' decision turned to `stiction` by the families' statistics read together.
pub(super) fn decided_by_combination(
    before: Decision,
    combined: &super::combined::CombinedEvidence,
    families: &[FamilyEvidence],
    motion: &Motion,
) -> Decision {
    let confidence = Some(combined.probability);
    Decision {
        verdict: Verdict::Stiction,
        confidence,
        reason: Some(combined.reason(before.verdict)),
        next_step: next_step(Verdict::Stiction, confidence, families, motion),
        evidence: before.evidence,
    }
}

/// The verdict and reason when no family votes: leaning evidence, a withdrawn fit, an
/// oscillation nobody explains, or a record nobody could judge.
fn without_votes(
    families: &[FamilyEvidence],
    leaning: &[&FamilyEvidence],
    motion: &Motion,
) -> (Verdict, String) {
    if !leaning.is_empty() {
        return (Verdict::Undetermined, leaning_reason(leaning));
    }
    if model_flag(families, |m| m.op_moved_elsewhere) {
        return (
            Verdict::Undetermined,
            "the loop moves, but only the closed-loop fit could judge it, and OP steps while the control error stays at rest (an input the record does not hold: a feed-forward, an override, an operator): PV need not follow those steps, so the fit's band is no vote, and no other family votes"
                .to_string(),
        );
    }
    if model_flag(families, |m| {
        m.cycle_shape.as_ref().is_some_and(|c| c.foreign())
    }) {
        return (
            Verdict::Undetermined,
            "the loop moves, but only the closed-loop fit could judge it, and the valve it fits would give PV's regular cycle a shape PV does not have (steps' harmonics in a sinusoidal cycle): a cycle OP does not drive, as a sine added to PV, gives that; no other family votes"
                .to_string(),
        );
    }
    if model_flag(families, |m| m.fit_mirrors_controller) {
        return (
            Verdict::Undetermined,
            "the loop moves, but only the closed-loop fit could judge it, and it explains PV through the controller's own law (a load OP does not explain moves the loop, not the setpoint): its gain with a band is no vote, and no other family votes"
                .to_string(),
        );
    }
    if motion.oscillating {
        return (
            Verdict::Undetermined,
            "the loop oscillates but no family of evidence names the cause: the cycle is regular and near-sinusoidal, the fits with and without stiction alike, and the linear loop could sustain it by itself"
                .to_string(),
        );
    }
    let reason = match motion.unresolved_cycle {
        Some((period, samples)) => format!(
            "no family of evidence could judge this record: the control error cycles regularly every {period:.0} s, only {samples:.1} samples a cycle, \
             which passes for measurement noise here; a sticky valve's cycle and a loop at its stability limit look alike at this sampling"
        ),
        None => "no family of evidence could judge this record: the loop is not excited enough (OP and PV hardly move above their noise, no oscillation)"
            .to_string(),
    };
    (Verdict::InsufficientData, reason)
}

/// Whether the closed-loop fit's evidence carries `flag` (why its stiction vote was withdrawn).
fn model_flag(
    families: &[FamilyEvidence],
    flag: impl Fn(&super::evidence::ModelEvidence) -> bool,
) -> bool {
    families
        .iter()
        .any(|f| f.family == Family::Model && f.model.as_ref().is_some_and(&flag))
}

/// Why a record whose families measured something but none voted is undetermined: which lean
/// which way, between their thresholds (their notes say by how much).
fn leaning_reason(leaning: &[&FamilyEvidence]) -> String {
    let side = |v: Vote| -> Vec<&FamilyEvidence> {
        leaning
            .iter()
            .copied()
            .filter(|f| f.leans == Some(v))
            .collect()
    };
    let mut parts = Vec::new();
    for (v, words) in [
        (Vote::Stiction, "towards stiction"),
        (Vote::NoStiction, "against stiction"),
    ] {
        let fams = side(v);
        if !fams.is_empty() {
            parts.push(format!("{words} ({})", names(&fams)));
        }
    }
    format!(
        "the evidence leans {} but lies between the thresholds, and no family votes: too weak to decide",
        parts.join(" and ")
    )
}

#[cfg(test)]
mod tests;
