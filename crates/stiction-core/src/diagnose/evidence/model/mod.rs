//! The model family: the closed-loop Hammerstein fit with and without stiction (Stenman, and Kano's
//! model with a slip jump of its own), always computed, on the whole analysed record
//! (Srinivasan, Rengaswamy and Miller 2005 use the fit for detection, not only quantification).
//! The fits compare the PV's changes over about a response time (`quantify::compare_fits`), so
//! loads that drift beside the valve do not decide the comparison.
//!
//! The statistics are the fit's improvement over the best linear loop (a valve that follows OP),
//! in shares of the PV's variance above its noise, and the test ratio: a free band always explains
//! noise a little better, so the improvement is held against the stiction fit's own residual per
//! independent change of the record, an F-like ratio. The verdict's model reads them (and the
//! band the fit finds over OP's noise); the family itself decides nothing.
//!
//! An independent change spans the samples of the residual's long-run overlap with the change the
//! band makes to the fit ([`FitComparison::correlation_span`]): about the lag for noise, many more
//! where the residual and the band's effect share a cycle that OP does not drive. A band that
//! follows an external cycle therefore gains less than a valve's stick would, per independent
//! change.

mod bound;
mod figures;

pub(crate) use bound::compared;
pub use figures::ModelEvidence;
use figures::{fits_words, model_evidence};

use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::diagnose::result::Vote;

/// The model family.
pub struct Model;

/// Fewest changes over the lag that do not overlap (samples over the lag) for the test.
const MIN_INDEPENDENT: f64 = 8.0;
/// Below this share of the PV's variance above its noise the record carries too little signal. The
/// noise is PV's fast changes, but no more than the best fit leaves: a loop's own fast moves,
/// recorded every 10 s, would otherwise pass for noise.
const MIN_SIGNAL_SHARE: f64 = 0.05;

/// The statistics of a comparison: shares of the compared output's variance above its noise.
#[derive(Clone, Copy)]
struct Levels {
    noise_share: f64,
    improvement: f64,
    significance: f64,
    explained: f64,
}

impl Levels {
    fn of(f: &crate::quantify::FitComparison) -> Self {
        let sst = f.sst.max(f64::MIN_POSITIVE);
        // the stiction fit can always do what the linear fit does
        let sticky = f.stenman.sse.min(f.slip_jump.sse).min(f.linear.sse);
        // PV's noise, estimated from its fast changes, cannot exceed what the best fit leaves:
        // where it does, the fast changes were the loop's (a valve slipping between samples)
        let noise = (f.samples_used as f64 * f.noise_var)
            .min(sticky)
            .min(0.99 * sst);
        let above = (sst - noise).max(f64::MIN_POSITIVE);
        let gain = f.linear.sse - sticky;
        // changes over the lag overlap, and a residual that shares a cycle with the band's
        // effect gives a free band more: samples over the span one independent change covers
        let independent = f.samples_used as f64 / f.correlation_span.max(1.0);
        Self {
            noise_share: noise / sst,
            improvement: gain / above,
            significance: gain / (sticky / independent).max(f64::MIN_POSITIVE),
            explained: 1.0 - (sticky - noise).max(0.0) / above,
        }
    }
}

impl EvidenceFamily for Model {
    fn family(&self) -> Family {
        Family::Model
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let statistic =
            "improvement of the fit with stiction over the linear loop, share of the PV's variance above its noise";
        let threshold = "read by the verdict's model as the test ratio (the improvement held against the stiction fit's residual per independent change)".to_string();
        let Some(f) = &ctx.fits else {
            return FamilyEvidence::abstains(
                Family::Model,
                statistic,
                threshold,
                "no linear model could be fitted (too few samples, or OP or PV constant)".into(),
            );
        };
        let levels = Levels::of(f);
        let mut evidence = model_evidence(ctx, f, &levels);
        let fits = fits_words(ctx, f, &evidence);
        let independent = f.samples_used as f64 / f.lag.max(1) as f64;
        let why = if independent < MIN_INDEPENDENT {
            evidence.judged = false;
            format!(
                "only {independent:.0} independent changes over {} samples: too few for the test",
                f.lag
            )
        } else if 1.0 - levels.noise_share < MIN_SIGNAL_SHARE {
            evidence.judged = false;
            format!(
                "the PV barely varies above its noise ({:.0} % of its variance is noise): nothing for a fit to explain",
                100.0 * levels.noise_share
            )
        } else {
            format!(
                "a stiction band improves the fit by {:.1} % of the PV's variation above its noise (test ratio {:.1}); OP explains {:.0} % of it",
                100.0 * levels.improvement.max(0.0),
                levels.significance,
                100.0 * levels.explained.max(0.0)
            )
        };
        FamilyEvidence {
            family: Family::Model,
            vote: Vote::Undetermined,
            strength: 0.0,
            contribution: None,
            value: Some(levels.improvement),
            statistic: statistic.into(),
            threshold,
            note: format!("{why}; {fits}"),
            leans: None,
            model: Some(evidence),
            stick_slip: None,
            valve: None,
            limit_cycle: None,
            hidden_valve: None,
        }
    }
}
