//! The hidden-valve family (with `thorough`): a sticky valve whose position the record does not
//! hold, against a valve that follows OP, as a likelihood ratio ([`crate::hidden_valve`]).
//!
//! Where the controller moves OP between the recorded samples, the valve slips at instants the
//! record does not hold, so no valve model run on the recorded OP reproduces it and the fits with
//! and without a band look alike (stiction-lab/results/sampled-valve.md); a particle filter over
//! the valve's position sees every slip in PV. It costs seconds a loop (a few hundred particle
//! filters), so it runs only with `thorough`, only where the other families have not already
//! decided `stiction`, and only where it was calibrated: an oscillating loop, PV recorded (not
//! compressed, not quantised), OP moving over a narrow range (a valve's characteristic is not
//! linear over a wide one, and the hidden valve's slips then absorb the linear loop's misfit), and
//! OP free of steps the control error did not provoke (`model::unprovoked`: a feed-forward's steps,
//! through which a valve that sticks explains PV's stillness, as for the closed-loop fit; on a
//! routine draw a fed-forward load reached a ratio of 253, and no sticky loop of the catalogue's
//! sets has such a step). It votes stiction or not at all: a sticky valve's ratio can be small, so
//! a small ratio is no evidence against it.

#[path = "hidden_valve_unprovoked.rs"]
mod unprovoked_steps;
use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::diagnose::oscillation::amplitude;
use crate::diagnose::result::Vote;
use crate::hidden_valve::{test, HiddenValveTest, Particles, Record, TestSettings};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use unprovoked_steps::{unprovoked, Unprovoked};

/// The hidden-valve family.
pub struct HiddenValve;

/// The log-likelihood ratio from which the family votes stiction: above every look-alike the
/// oscillation, compression and OP-range gates let through on the two calibration sets, rounded up
/// to 5.
pub(crate) const THRESHOLD: f64 = 75.0;
/// OP's travel (5th to 95th percentile, twice its amplitude) above this share of the valve span
/// leaves the family silent: on the routine calibration windows an equal-percentage valve under a
/// load ramp (OP over 14 % of span) reached a ratio of 288; the sticky valves the family found
/// moved OP over at most 6.5 %.
const MAX_OP_TRAVEL: f64 = 0.10;
/// PV samples not recorded (runs of repeats or exactly straight lines) above this share leave the
/// family silent: a held or straight-lined PV is no Gaussian measurement, and compressed records
/// reach ratios in the thousands (stiction-lab/results/hidden-valve-routine.md).
const MAX_UNRECORDED: f64 = 0.05;
/// Particles of the sticky hypothesis's filter (the calibrated setting): on the fast sets as many
/// sticky loops found as with twice as many, every look-alike under the threshold, at half the
/// cost.
pub(crate) const PARTICLES: usize = 50;
/// Valves each sticky search starts from: the scan's best and the best a band away from it
/// ([`TestSettings::band_starts`]). With the best alone the search stayed at a small band on
/// three of four seeds of ISDB loop PAP2 (ratios near -12; the fourth 182), with both every seed
/// found a ratio of 149 to 179.
const BAND_STARTS: usize = 2;
/// Draws of the particle filter's noise (seeds 1, 2, ...) whose median ratio decides a stiction
/// vote: a ratio at or above the threshold is drawn again with other seeds, since one draw against
/// another can carry a ratio across it.
pub(crate) const DRAWS: u64 = 3;
/// How far short of OP the hidden valve's slips may land, as shares of its band (0: Stenman's
/// valve; He's lands `fd` short).
const SHORT_SHARES: &[f64] = &[0.0, 0.35, 0.7];

/// What the hidden-valve test found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HiddenValveEvidence {
    /// Log-likelihood ratio (natural log), a hidden sticky valve against one that follows OP.
    pub ratio: f64,
    /// The sticky hypothesis's best band, OP units (a grid of 10 bands, 0.3-8 % of span, each
    /// with slips landing on OP or 35 or 70 % of the band short of it).
    pub band: f64,
    /// The same in % of the valve span.
    pub band_percent_of_span: f64,
    /// How far short of OP its slips land, % of the valve span (0: Stenman's valve, which lands
    /// on OP; else He's, with `fd` this).
    pub short_percent_of_span: f64,
    /// The ratio of each draw of the particle filter's noise, in the order of their seeds: one
    /// when the first is under the threshold, else `DRAWS`, whose median is `ratio`.
    pub draws: Vec<f64>,
    /// Particles of the sticky hypothesis's filter.
    pub particles: usize,
    /// Likelihoods evaluated: Kalman filters (valve following OP), particle filters (hidden
    /// valve).
    pub evaluations: [usize; 2],
}

const STATISTIC: &str =
    "log-likelihood ratio of a sticky valve whose position the record does not hold against a valve that follows OP";

fn threshold() -> String {
    format!(
        "stiction at a ratio of {THRESHOLD:.0} or more (above every look-alike of the calibration sets; a first ratio that reaches it \
         is drawn {DRAWS} times in all with the particle filter's noise and the median decides); below it, no vote \
         (a sticky valve's ratio can be small). Judged only on an oscillating loop with PV recorded and OP within {:.0} % of span",
        100.0 * MAX_OP_TRAVEL
    )
}

/// The abstention of a record the other families already call `stiction`.
pub fn not_needed() -> FamilyEvidence {
    FamilyEvidence::abstains(
        Family::HiddenValve,
        STATISTIC,
        threshold(),
        "not run: the other families already decide stiction".into(),
    )
}

/// Why the family cannot judge this record, if it cannot.
fn gated(ctx: &Context) -> Option<String> {
    let [lo, hi] = ctx.req.op_range;
    let unrecorded =
        ctx.unrecorded.iter().filter(|&&u| u).count() as f64 / ctx.unrecorded.len().max(1) as f64;
    if !ctx.oscillation.oscillating {
        Some("the loop does not oscillate: the ratio is calibrated on limit cycles only".into())
    } else if unrecorded > MAX_UNRECORDED {
        Some(format!(
            "PV is not recorded in {:.0} % of the samples (compression or a frozen transmitter): no Gaussian measurement",
            100.0 * unrecorded
        ))
    } else if ctx.pv_quantum.is_some() {
        Some("PV is quantised: no Gaussian measurement".into())
    } else if ctx.op.is_empty() || 2.0 * amplitude(ctx.op) > MAX_OP_TRAVEL * (hi - lo) {
        Some(format!(
            "OP travels over more than {:.0} % of span, where a valve's characteristic is not linear",
            100.0 * MAX_OP_TRAVEL
        ))
    } else {
        // as the closed-loop fit's vote is withdrawn there: a valve that sticks through OP's
        // unprovoked steps explains PV's stillness under a fed-forward load
        unprovoked(ctx.op, &ctx.error, ctx.pv_noise)
            .filter(Unprovoked::withdraws)
            .map(|u| {
                format!(
                    "OP makes {} steps the control error did not provoke ({:.0} % of its travel: a feed-forward, an override or an operator), \
                     through which a valve that sticks explains PV's stillness",
                    u.steps,
                    100.0 * u.share
                )
            })
    }
}

impl EvidenceFamily for HiddenValve {
    fn family(&self) -> Family {
        Family::HiddenValve
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let abstain = |note: String| {
            FamilyEvidence::abstains(Family::HiddenValve, STATISTIC, threshold(), note)
        };
        if let Some(why) = gated(ctx) {
            return abstain(why);
        }
        let [lo, hi] = ctx.req.op_range;
        let rec = Record {
            op: ctx.op,
            pv: ctx.pv,
            ts: ctx.req.ts,
            limits: Some((lo, hi)),
        };
        // the cycling load may sit at the period of the cycle the loop shows (on routine-b-0472,
        // a sine on the load under setpoint steps, PV's strongest cycle was the steps', and the
        // sine left to the sticky hypothesis reached a ratio of 185)
        let period = ctx.oscillation.period.map(|p| p / ctx.req.ts);
        let Some((t, draws, evaluations)) = drawn(&rec, hi - lo, ctx.integrating, period) else {
            return abstain("PV does not move above its resolution: nothing to filter".into());
        };
        let pct = 100.0 * t.band / (hi - lo);
        let sticky = t.ratio >= THRESHOLD;
        let note = note(&t, &draws, pct, hi - lo);
        let evidence = HiddenValveEvidence {
            ratio: t.ratio,
            band: t.band,
            band_percent_of_span: pct,
            short_percent_of_span: 100.0 * t.short / (hi - lo),
            draws,
            particles: PARTICLES,
            evaluations,
        };
        FamilyEvidence {
            vote: if sticky {
                Vote::Stiction
            } else {
                Vote::Undetermined
            },
            strength: if sticky { 0.9 } else { 0.0 },
            value: Some(t.ratio),
            hidden_valve: Some(evidence),
            ..abstain(note)
        }
    }
}

/// The test with the first draw of the particle filter's noise, and where its ratio reaches the
/// threshold, with [`DRAWS`] in all (in parallel): the median draw's test, every draw's ratio in
/// seed order, and the likelihoods evaluated by all of them.
fn drawn(
    rec: &Record,
    op_span: f64,
    integrating: bool,
    cycle_period: Option<f64>,
) -> Option<(HiddenValveTest, Vec<f64>, [usize; 2])> {
    let run = |seed: u64| {
        let settings = TestSettings {
            op_span,
            integrating,
            particles: Particles {
                count: PARTICLES,
                seed,
            },
            short_shares: SHORT_SHARES,
            band_starts: BAND_STARTS,
            cycle_period,
            ..TestSettings::default()
        };
        test(rec, &settings)
    };
    let first = run(1)?;
    let mut tests = vec![first];
    if tests[0].ratio >= THRESHOLD {
        let more: Vec<HiddenValveTest> = (2..=DRAWS).into_par_iter().filter_map(run).collect();
        tests.extend(more);
    }
    let draws: Vec<f64> = tests.iter().map(|t| t.ratio).collect();
    let evaluations = tests.iter().fold([0, 0], |[k, p], t| {
        [k + t.evaluations.0, p + t.evaluations.1]
    });
    tests.sort_by(|a, b| a.ratio.total_cmp(&b.ratio));
    let median = tests.swap_remove(tests.len() / 2);
    Some((median, draws, evaluations))
}

/// The family's note on the (median) test `t`, its band `pct` in % of span, and the draws' ratios.
fn note(t: &HiddenValveTest, draws: &[f64], pct: f64, op_span: f64) -> String {
    let of_draws = if draws.len() > 1 {
        let each: Vec<String> = draws.iter().map(|r| format!("{r:.0}")).collect();
        format!(
            ", the median of {} draws of the particle filter's noise: {}",
            draws.len(),
            each.join(", ")
        )
    } else {
        String::new()
    };
    if t.ratio >= THRESHOLD {
        let lands = if t.short > 0.0 {
            format!(", landing {:.1} % short of OP,", 100.0 * t.short / op_span)
        } else {
            String::new()
        };
        format!(
            "PV is far likelier through a hidden valve with a band of {:.1} % of span{lands} that slips between the samples than through one \
             that follows OP (ratio {:.0} against {THRESHOLD:.0}{of_draws})",
            pct,
            t.ratio
        )
    } else {
        format!(
            "a hidden sticky valve explains PV no better than the threshold asks (ratio {:.1} against {THRESHOLD:.0}{of_draws})",
            t.ratio
        )
    }
}
