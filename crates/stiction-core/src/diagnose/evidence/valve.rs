//! The valve family: when the valve position (MV) is recorded, the direct evidence from OP to MV,
//! the paper's estimation problem, solved exactly for the Stenman band. It outweighs the indirect
//! families: it looks at the valve itself.

use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::diagnose::oscillation::noise_std;
use crate::diagnose::result::Vote;
use crate::estimate::{estimate, Method, Request};
use crate::models::ModelKind;
use serde::{Deserialize, Serialize};

/// The valve family.
pub struct Valve;

/// A band at least this many MV noise standard deviations ...
const BAND_NOISE_SIGMAS: f64 = 4.0;
/// ... and at least this share of the valve span (%) votes stiction, when the band removes at
/// least `MIN_IMPROVEMENT` of the misfit of a valve that follows OP.
pub(super) const MIN_BAND_PERCENT: f64 = 0.2;
/// The share of the misfit of a valve that follows OP that the band must remove to vote stiction.
const MIN_IMPROVEMENT: f64 = 0.3;

/// The valve position against OP.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ValveEvidence {
    /// Stenman's band, OP units and % of span, with its proven optimal set.
    pub d: f64,
    /// Stenman's band, % of valve span.
    pub d_percent_of_span: f64,
    /// The exact solver's proven interval of equally good bands, % of valve span.
    pub interval: Option<[f64; 2]>,
    /// R² of MV with the band and with a valve that follows OP.
    pub r2: f64,
    /// R² of MV with a valve that follows OP.
    pub r2_without_stiction: f64,
    /// The MV's noise standard deviation (robust, from first differences).
    pub mv_noise: f64,
}

impl EvidenceFamily for Valve {
    fn family(&self) -> Family {
        Family::Valve
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let statistic = "Stenman band fitted to the recorded valve position, % of span";
        let threshold = format!(
            "stiction when the band is at least {MIN_BAND_PERCENT} % of span and {BAND_NOISE_SIGMAS} MV noise standard deviations, \
             and removes at least {:.0} % of a following valve's misfit",
            100.0 * MIN_IMPROVEMENT
        );
        let Some(mv) = ctx.mv else {
            return FamilyEvidence::abstains(
                Family::Valve,
                statistic,
                threshold,
                "no valve position recorded".into(),
            );
        };
        let req = Request::new(ModelKind::Stenman, Method::Exact);
        let est = match estimate(ctx.op, mv, &req) {
            Ok(e) => e,
            Err(e) => {
                return FamilyEvidence::abstains(
                    Family::Valve,
                    statistic,
                    threshold,
                    format!("the band could not be estimated from OP and MV: {e}"),
                )
            }
        };
        let d = est.params.get("d").copied().unwrap_or(0.0);
        let mean_mv = mv.iter().sum::<f64>() / mv.len() as f64;
        let sst: f64 = mv.iter().map(|v| (v - mean_mv).powi(2)).sum();
        let sse0: f64 = ctx.op.iter().zip(mv).map(|(o, m)| (o - m).powi(2)).sum();
        let improvement = if sse0 > 0.0 {
            1.0 - est.sse / sse0
        } else {
            0.0
        };
        let mv_noise = noise_std(mv);
        let pct = ctx.req.percent_of_span(d);
        let evidence = ValveEvidence {
            d,
            d_percent_of_span: pct,
            interval: est
                .interval
                .get("d")
                .map(|i| [ctx.req.percent_of_span(i[0]), ctx.req.percent_of_span(i[1])]),
            r2: est.r2,
            r2_without_stiction: if sst > 0.0 { 1.0 - sse0 / sst } else { 0.0 },
            mv_noise,
        };
        let sticky = pct >= MIN_BAND_PERCENT
            && d >= BAND_NOISE_SIGMAS * mv_noise
            && improvement >= MIN_IMPROVEMENT;
        let (vote, strength, why) = if sticky {
            (
                Vote::Stiction,
                1.0,
                format!(
                    "the valve position holds until OP has moved {pct:.2} % of span, then jumps (R² {:.3} with the band, {:.3} without)",
                    evidence.r2, evidence.r2_without_stiction
                ),
            )
        } else if est.r2 < 0.0 {
            (
                Vote::Undetermined,
                0.0,
                format!(
                    "the valve position does not follow OP through any band (R² {:.3}): is MV really the valve position?",
                    est.r2
                ),
            )
        } else {
            (
                Vote::NoStiction,
                1.0,
                format!(
                    "the valve position follows OP: a band of {pct:.2} % of span ({:.1} MV noise standard deviations) removes {:.0} % of the misfit",
                    d / mv_noise.max(f64::MIN_POSITIVE),
                    100.0 * improvement.max(0.0)
                ),
            )
        };
        FamilyEvidence {
            family: Family::Valve,
            vote,
            strength,
            contribution: None,
            value: Some(pct),
            statistic: statistic.into(),
            threshold,
            note: why,
            leans: None,
            model: None,
            stick_slip: None,
            valve: Some(evidence),
            limit_cycle: None,
            hidden_valve: None,
        }
    }
}
