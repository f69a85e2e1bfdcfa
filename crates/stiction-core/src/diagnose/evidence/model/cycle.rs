//! The model family's second look at a cycle: the fits compared over whole periods.
//!
//! A regular cycle is a few harmonics, and linear dynamics from OP fit it about as well as the
//! sticky valve that causes it: compared over about a response time, the fits with and without
//! stiction look alike. Changes over a whole number of the cycle's periods cancel the cycle, its
//! fundamental and every harmonic (`x[t + kP] - x[t]`); what is left are the loop's transients,
//! its responses to the setpoint and the loads, and the cycle's changes from one period to the
//! next. A valve that sticks shapes those as it shapes the cycle, and a linear loop does not; a
//! linear loop at its stability limit or an external input at the cycle's period leaves nothing
//! there a band explains. The same calibrated test then decides, at the first comparison's
//! threshold ([`CYCLE_CANCELLED_STICTION`]).
//!
//! It runs where the first comparison falls short of a stiction vote on a cycle: on a limit cycle
//! whose first test ratio stays under the stiction threshold, and on any other oscillating loop
//! (its period wandering) whose fits the first comparison finds alike while OP explains the PV
//! (`second_look` in the family). The threshold is calibrated on the healthy loops that reach it:
//! on the catalogue's calibration draws (other seeds than the benchmark's) they stay under it,
//! where the sticky loops that reach it give ratios many times over it.

use super::{Levels, MIN_EXPLAINED, SIGNIFICANCE_NONE, SIGNIFICANCE_STICTION};
use crate::diagnose::evidence::Context;
use crate::quantify::{compare_fits, CompareRequest, FitComparison};
use serde::{Deserialize, Serialize};

/// The test's ratio at and above which the comparison over whole periods votes stiction.
pub(crate) const CYCLE_CANCELLED_STICTION: f64 = SIGNIFICANCE_STICTION;

/// A cycle at least this regular (Thornhill's r: its period's standard deviation under a 300th of
/// the period) keeps time like an input of fixed period, or like a limit cycle the noise hardly
/// disturbs. A band fits such an input's cycle better than linear dynamics from OP do, where a
/// limit cycle is fitted about as well by both. So when the family votes stiction on such a cycle
/// with a gain of at least [`FORCED_GAIN`], the fits are compared over whole periods too; if the
/// band gains there no more than healthy loops give (`CycleCancelled::only_the_cycle`), its gain
/// was the cycle's alone and the vote is withdrawn (the family then leans towards stiction). Set
/// above the sticky limit cycles of the calibration set that gain nothing over whole periods, under
/// the externally oscillating loop that does the same.
pub(crate) const FORCED_REGULARITY: f64 = 100.0;
/// ... measured over at least this many zero crossings of the autocorrelation (two periods: a
/// regularity from fewer measures no spread).
pub(super) const FORCED_CROSSINGS: usize = crate::detect::SPREAD_CROSSINGS;
/// ... and the band's gain over the linear loop at least this share of the PV's variation above
/// its noise (a band that reshapes the fit of so regular a cycle by a twentieth of it; the
/// externally oscillating loops gain 7.8 % and more).
pub(super) const FORCED_GAIN: f64 = 0.05;

/// Whether the cycle keeps time like an input of fixed period ([`FORCED_REGULARITY`]).
pub(super) fn clock_regular(ctx: &Context) -> bool {
    let o = &ctx.oscillation;
    o.oscillating
        && o.regularity.regularity >= FORCED_REGULARITY
        && o.regularity.zero_crossings >= FORCED_CROSSINGS
}

/// The fits compared over whole periods of the cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleCancelled {
    /// Whole periods of the cycle the changes span.
    pub periods: usize,
    /// The lag of the changes compared, samples.
    pub lag: usize,
    /// R² in simulation of the changes without stiction.
    pub r2_without_stiction: f64,
    /// R² with the better stiction model.
    pub r2_with_stiction: f64,
    /// The improvement of the fit with stiction, share of the changes' variance above the noise.
    pub improvement: f64,
    /// The calibrated test's ratio (as the family's first comparison's); stiction at
    /// `CYCLE_CANCELLED_STICTION`.
    pub significance: f64,
    /// Share of the changes' variance above the noise explained with stiction.
    pub explained: f64,
}

impl CycleCancelled {
    /// Compare the fits over the whole periods nearest the first comparison's lag (at least one);
    /// `None` without a period or when no linear model fits.
    pub(super) fn of(ctx: &Context, first: &FitComparison) -> Option<Self> {
        let period = ctx.oscillation.period? / ctx.req.ts;
        if !period.is_finite() || period < 2.0 {
            return None;
        }
        let periods = (first.lag as f64 / period).round().max(1.0);
        let req = CompareRequest {
            ts: ctx.req.ts,
            max_delay: ctx.req.max_delay,
            integrating: Some(ctx.req.integrating),
            lag: Some((periods * period).round() as usize),
        };
        let f = compare_fits(ctx.op, ctx.pv, &req)?;
        let l = Levels::of(&f);
        Some(Self {
            periods: periods as usize,
            lag: f.lag,
            r2_without_stiction: f.linear.r2,
            r2_with_stiction: f.stenman.r2.max(f.slip_jump.r2),
            improvement: l.improvement,
            significance: l.significance,
            explained: l.explained,
        })
    }

    /// Whether the band gains over whole periods no more than healthy loops give: its gain in the
    /// first comparison was the cycle's alone.
    pub(super) fn only_the_cycle(&self) -> bool {
        self.significance <= SIGNIFICANCE_NONE
    }

    /// Whether the comparison calls the valve sticky.
    pub(super) fn sticky(&self) -> bool {
        self.significance >= CYCLE_CANCELLED_STICTION && self.explained >= MIN_EXPLAINED
    }

    /// A clause for the family's note.
    pub(super) fn words(&self) -> String {
        format!(
            "compared over {} whole period{} of the cycle ({} samples), where the cycle cancels, a sticky valve fits what is left {} (R² {:.3} without stiction, {:.3} with; test ratio {:.0}, stiction at {CYCLE_CANCELLED_STICTION:.0})",
            self.periods,
            if self.periods == 1 { "" } else { "s" },
            self.lag,
            if self.sticky() {
                "better than a valve that follows OP, beyond what healthy loops give"
            } else if self.significance > 0.0 {
                "a little better than a valve that follows OP, not enough"
            } else {
                "no better than a valve that follows OP"
            },
            self.r2_without_stiction,
            self.r2_with_stiction,
            self.significance,
        )
    }
}
