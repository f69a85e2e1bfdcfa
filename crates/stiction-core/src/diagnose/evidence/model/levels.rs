//! The model family's second test, run when the request is `thorough`: every distinct Stenman
//! valve trajectory from OP scored on PV's *levels* against a filter bank beside a smooth drift,
//! with an AR noise model ([`crate::identify::levels`]).
//!
//! Why a second test: the closed-loop fit compares PV's changes over a lag with PV's own past among
//! its regressors, and on records sampled at every controller execution that criterion often ranks
//! the true band's valve below a small band near OP (stiction-lab/results/sampled-valve.md: on the
//! routine 1 s records it prefers the true band's valve in 10 of 40 Stenman loops; the levels test
//! in 36). The levels test has no PV past among its regressors and cannot be biased towards OP by
//! the controller's feedback of PV's noise.
//!
//! Its threshold, [`LEVELS_STICTION`], is about the 98th percentile of the test's ratio on the
//! healthy routine loops of the catalogue's calibration set with PV recorded (other seeds than the
//! benchmark's); lower, it calls externally oscillating loops sticky. A PV that is not recorded
//! over [`MAX_UNRECORDED`] of the record (historian compression, a frozen or coarsely quantised
//! transmitter) is left out: a held PV is a staircase that a sticky valve's trajectory fits.
//!
//! A band under [`crate::diagnose::evidence::valve::MIN_BAND_PERCENT`] of span is not counted:
//! where even the recorded valve position would not call so small a band stiction, PV's levels
//! cannot. On the catalogue's routine windows with load steps the test's best valve was such a band
//! at high ratios, where the sticky valves' bands it finds are larger.

use super::super::valve::MIN_BAND_PERCENT;
use super::super::Context;
use super::{clock_regular, CycleCancelled, ModelEvidence};
use crate::identify::levels::{levels_walk, LevelsWalk};
use crate::quantify::FitComparison;
use serde::{Deserialize, Serialize};

/// The levels test's ratio at and above which it votes stiction.
pub(crate) const LEVELS_STICTION: f64 = 50.0;
/// The ratio at which its vote is held with full strength.
const LEVELS_DECISIVE: f64 = 500.0;
/// Above this share of PV samples not recorded the test is not run.
const MAX_UNRECORDED: f64 = 0.2;

/// What the levels test found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LevelsEvidence {
    /// The log-likelihood ratio of the best Stenman valve against OP (PV's levels, AR noise).
    pub ratio: f64,
    /// The best valve's band, OP units.
    pub band: f64,
    /// The same in % of valve span.
    pub band_percent_of_span: f64,
    /// How far short of OP the best valve's slips land (He's fd), OP units; 0 for a Stenman valve.
    pub slip_short: f64,
    /// Distinct valve trajectories scored.
    pub trajectories: usize,
    /// The ratio at and above which the test votes stiction.
    pub threshold: f64,
    /// The smallest band (% of span) the test counts: a smaller one never votes stiction.
    #[serde(default)]
    pub min_band_percent_of_span: f64,
}

impl LevelsEvidence {
    /// Whether the test calls the valve sticky: the ratio at its threshold, with a band the
    /// valve family would count.
    pub fn sticky(&self) -> bool {
        self.ratio >= self.threshold && self.band_percent_of_span >= self.min_band_percent_of_span
    }
}

/// The outcome of the levels test on the analysed stretch.
pub enum LevelsTest {
    /// Not asked for (the request is not `thorough`).
    NotRun,
    /// Asked for but not run, and why.
    Skipped(String),
    /// Run.
    Ran(LevelsEvidence),
}

impl LevelsTest {
    /// Run the test when the request asks for it and the PV is recorded.
    pub fn of(ctx: &Context) -> Self {
        if !ctx.req.thorough {
            return LevelsTest::NotRun;
        }
        let n = ctx.unrecorded.len().max(1);
        let unrecorded = ctx.unrecorded.iter().filter(|&&u| u).count() as f64 / n as f64;
        if unrecorded > MAX_UNRECORDED {
            return LevelsTest::Skipped(format!(
                "the levels test is not run: PV looks not recorded in {:.0} % of the samples (a held PV is a staircase a sticky valve fits)",
                100.0 * unrecorded
            ));
        }
        match levels_walk(ctx.op, ctx.pv, ctx.req.integrating) {
            Some(LevelsWalk {
                ratio,
                band,
                slip_short,
                trajectories,
            }) => LevelsTest::Ran(LevelsEvidence {
                ratio,
                band,
                band_percent_of_span: ctx.req.percent_of_span(band),
                slip_short,
                trajectories,
                threshold: LEVELS_STICTION,
                min_band_percent_of_span: MIN_BAND_PERCENT,
            }),
            None => LevelsTest::Skipped(
                "the levels test is not run: too few samples, or OP does not move".into(),
            ),
        }
    }

    /// The evidence, when the test ran.
    pub fn evidence(&self) -> Option<&LevelsEvidence> {
        match self {
            LevelsTest::Ran(e) => Some(e),
            _ => None,
        }
    }

    /// The vote's strength when the test calls stiction.
    pub fn stiction_strength(&self) -> Option<f64> {
        let e = self.evidence()?;
        e.sticky().then(|| {
            (0.5 + 0.5 * (e.ratio / LEVELS_STICTION).ln()
                / (LEVELS_DECISIVE / LEVELS_STICTION).ln())
            .min(1.0)
        })
    }

    /// A clause for the family's note.
    pub fn words(&self) -> Option<String> {
        match self {
            LevelsTest::NotRun => None,
            LevelsTest::Skipped(why) => Some(why.clone()),
            LevelsTest::Ran(e) => Some(format!(
                "levels test: {} explains PV's levels {} than OP (ratio {:.0} over {} valve trajectories; stiction at {LEVELS_STICTION:.0}{})",
                if e.slip_short > 0.0 {
                    format!(
                        "a band of {:.2} % of span whose slips land {:.2} % short of OP (He)",
                        e.band_percent_of_span,
                        e.band_percent_of_span * e.slip_short / e.band.max(f64::MIN_POSITIVE)
                    )
                } else {
                    format!("a Stenman band of {:.2} % of span", e.band_percent_of_span)
                },
                if e.ratio >= LEVELS_STICTION { "far better" } else if e.ratio > 0.0 { "a little better" } else { "no better" },
                e.ratio,
                e.trajectories,
                if e.ratio >= LEVELS_STICTION && !e.sticky() {
                    format!(
                        ", with a band of at least {MIN_BAND_PERCENT} % of span: a smaller one is not counted"
                    )
                } else {
                    String::new()
                }
            )),
        }
    }
}

/// Where the levels test finds a band on a cycle as regular as an input of fixed period and the
/// fits compared over whole periods find nothing a band explains beyond what healthy loops give,
/// the band's gain on PV's levels is the cycle's alone, as the first comparison's is in that case
/// (`FORCED_REGULARITY`): why the levels test's is then no vote. `None` where it counts.
pub(super) fn cycle_alone(
    ctx: &Context,
    f: &FitComparison,
    evidence: &mut ModelEvidence,
) -> Option<String> {
    if !clock_regular(ctx) {
        return None;
    }
    let fresh = evidence.cycle_cancelled.is_none();
    if fresh {
        evidence.cycle_cancelled = CycleCancelled::of(ctx, f);
    }
    let c = evidence.cycle_cancelled.as_ref()?;
    c.only_the_cycle().then(|| {
        format!(
            "the levels test finds a band, but the cycle keeps time like an input of fixed period (regularity {:.0}){}: a band fits such an input's cycle too, so the levels test's is no vote",
            ctx.oscillation.regularity.regularity,
            if fresh { format!(", and {}", c.words()) } else { ", and over whole periods no band gains".into() }
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ran(ratio: f64, band_percent_of_span: f64) -> LevelsTest {
        LevelsTest::Ran(LevelsEvidence {
            ratio,
            band: band_percent_of_span,
            band_percent_of_span,
            slip_short: 0.0,
            trajectories: 100,
            threshold: LEVELS_STICTION,
            min_band_percent_of_span: MIN_BAND_PERCENT,
        })
    }

    #[test]
    fn a_band_the_valve_family_would_not_count_never_votes_stiction() {
        // far over the ratio's threshold, but a band of 0.04 % of span
        let small = ran(146.0, 0.04);
        assert!(!small.evidence().unwrap().sticky());
        assert_eq!(small.stiction_strength(), None);
        assert!(
            small.words().unwrap().contains("not counted"),
            "{:?}",
            small.words()
        );
        // the same ratio with a band at the floor counts, and says nothing of the floor
        let counted = ran(146.0, MIN_BAND_PERCENT);
        assert!(counted.evidence().unwrap().sticky());
        assert!(counted.stiction_strength().unwrap() > 0.5);
        assert!(!counted.words().unwrap().contains("not counted"));
        // under the ratio's threshold nothing counts, whatever the band
        assert_eq!(ran(49.0, 2.0).stiction_strength(), None);
    }
}
