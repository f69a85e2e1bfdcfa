//! When the closed-loop fit's stiction vote says nothing about the valve, and is withdrawn: a
//! fit that mirrors the controller ([`MIN_LOOP_GAIN`]), or OP steps the controller did not make
//! ([`super::MAX_UNPROVOKED_SHARE`]). Each sets its flag in the evidence, and the verdict of a
//! record left with no vote says which.

use super::{limit_cycles, ModelEvidence};
use crate::diagnose::evidence::Context;
use crate::diagnose::result::Vote;
use crate::quantify::FitComparison;

/// Below this loop gain (the fitted process gain times the identified PI's gain), on a loop that
/// does not limit-cycle, the stiction vote is withdrawn: the fit mirrors the controller. Where a
/// load that OP does not explain moves the loop (load steps above all), closed-loop data let a
/// linear fit explain PV's changes from OP's through the controller's own law (OP answers the
/// error), with a process gain near zero and no dead time, and a free band then gains on that fit
/// as it never would on the process's. Set between the look-alikes' loop gains and the sticky
/// valves' on the calibration set; limit cycles are left alone (there the valve drives the loop,
/// and a PI read off fast samples is unreliable).
pub(crate) const MIN_LOOP_GAIN: f64 = 0.1;

/// Why a stiction vote is withdrawn ([`mirrors_controller`], then [`moved_elsewhere`]), with the
/// evidence's flag set; `None` when it stands.
pub(super) fn withdrawn(
    ctx: &Context,
    e: &mut ModelEvidence,
    vote: Vote,
    why: &str,
) -> Option<String> {
    if let Some(w) = mirrors_controller(ctx, e, vote, why) {
        e.fit_mirrors_controller = true;
        return Some(w);
    }
    let w = moved_elsewhere(e, vote, why)?;
    e.op_moved_elsewhere = true;
    Some(w)
}

/// Why a stiction vote is withdrawn when the fit mirrors the controller ([`MIN_LOOP_GAIN`]), with
/// the vote's own words `why`; `None` when it stands.
fn mirrors_controller(ctx: &Context, e: &ModelEvidence, vote: Vote, why: &str) -> Option<String> {
    let g = e
        .loop_gain
        .filter(|&g| vote == Vote::Stiction && !limit_cycles(ctx) && g < MIN_LOOP_GAIN)?;
    Some(format!(
        "the fitted process and the identified PI make a loop gain of {g:.3}, under {MIN_LOOP_GAIN}: a loop that weak would not \
         hold PV at its setpoint, so the fit explains PV from OP through the controller's own law (what a load OP does not \
         explain leaves in closed loop), not through the valve, and its gain with a band is no vote ({why})"
    ))
}

/// Why a stiction vote is withdrawn when OP steps the control error did not provoke carry a share
/// of OP's travel ([`super::MAX_UNPROVOKED_SHARE`]), with the vote's own words `why`; `None` when it
/// stands.
fn moved_elsewhere(e: &ModelEvidence, vote: Vote, why: &str) -> Option<String> {
    let u = e
        .unprovoked_op_steps
        .filter(|u| vote == Vote::Stiction && u.withdraws())?;
    Some(format!(
        "OP steps {} time{} while the control error stays inside its noise ({:.0} % of OP's travel): a controller acting on the error \
         does not, so OP has an input the record does not hold (a feed-forward of a measured load, an override, an operator), \
         PV need not follow such steps, and a band that explains why it does not is no vote ({why})",
        u.steps,
        if u.steps == 1 { "" } else { "s" },
        100.0 * u.share
    ))
}

/// The loop gain the fit implies (see [`ModelEvidence::loop_gain`]): `None` for an integrating
/// structure, without a fitted gain, or without a PI that explains OP's increments.
pub(super) fn loop_gain(ctx: &Context, f: &FitComparison) -> Option<f64> {
    if f.structure.integrating {
        return None;
    }
    let k = f.gain?;
    let pi = crate::loop_analysis::identify_pi(ctx.op, &ctx.error, ctx.req.ts)?;
    Some((k * pi.kc_continuous).abs())
}
