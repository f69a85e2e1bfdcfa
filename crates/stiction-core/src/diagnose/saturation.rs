//! A record that OP's limits cut into stretches too short to judge: the loop family's saturation
//! rule, read off the whole record.
//!
//! A loop tuned hard, or a valve too small for its duty, drives OP to 0 or 100 % in its cycle.
//! Every sample at a limit is left out (the valve is not under the controller's command there),
//! and a cycle that reaches a limit every period leaves stretches of a fraction of a period,
//! too short for any family. What the record still shows is the saturation itself: where OP
//! reaches a limit in at least [`LIMIT_CYCLES`] of the cycles of the control error, the loop
//! family votes against stiction as it does on a long stretch ("saturation bounds the cycle"), if
//! OP also leaves the limit in those cycles (an OP held at a limit throughout was not moved by the
//! controller, and stays `insufficient_data`).
//! On the plant benchmark's catalogue (both sets), 24 fast loops with healthy valves move from
//! `insufficient_data` to `no_stiction` by it (22 whose OP saturates in a load's cycle, 2 tuned
//! near their stability limit); the 4 routine windows whose stretches OP's limits cut short
//! (level loops tuned so hard that the noise drives OP to its limits) show no regular cycle and
//! stay `insufficient_data`; no sticky loop's record was cut short so, and no other verdict moved.

use super::evidence::limit_cycle::{share_of_cycles, LIMIT_CYCLES, SATURATION_STRENGTH};
use super::evidence::{Family, FamilyEvidence};
use super::request::DiagnoseRequest;
use super::result::{Oscillation, Vote};
use super::{control_error, oscillation, stretch, LoopRecord};

/// The loop family's vote when OP's limits bound the whole record's cycle, with the cycle; `None`
/// when the record has gaps, manual mode or non-finite values, does not oscillate, or OP reaches
/// a limit in fewer of its cycles. `longest`: the longest usable stretch, samples.
pub(super) fn bounded(
    r: &LoopRecord,
    req: &DiagnoseRequest,
    longest: usize,
) -> Option<(FamilyEvidence, Oscillation)> {
    let finite = |x: &[f64]| x.iter().all(|v| v.is_finite());
    let automatic = r.auto.is_none_or(|a| a.iter().all(|&on| on));
    if !(finite(r.op) && finite(r.pv) && r.sp.is_none_or(finite) && automatic) {
        return None;
    }
    let saturated = stretch::saturated_samples(r.op, req.op_range);
    if !saturated.iter().any(|&s| s) {
        return None;
    }
    let error = control_error(r.pv, r.sp);
    let osc = oscillation::of_record(&error, r.sp, req.ts);
    let period = osc.period.filter(|_| osc.oscillating)?;
    let share = cycles_at_limit(&saturated, period / req.ts);
    if share < LIMIT_CYCLES {
        return None;
    }
    let note = format!(
        "OP reaches a limit of its range in {:.0} % of the cycles of the whole record (period {period:.0} s): saturation bounds the cycle; \
         between the limits the usable stretches are too short for the other families (the longest {longest} samples, a verdict needs {})",
        100.0 * share,
        req.min_samples
    );
    let threshold = format!(
        "none when OP reaches a limit in {:.0} % of the cycles or more (read off the whole record when OP's limits leave no stretch long enough)",
        100.0 * LIMIT_CYCLES
    );
    let mut e = FamilyEvidence::abstains(
        Family::Loop,
        "the share of the control error's cycles in which OP reaches a limit of its range",
        threshold,
        note,
    );
    (e.vote, e.strength, e.value) = (Vote::NoStiction, SATURATION_STRENGTH, Some(share));
    Some((e, osc))
}

/// The share of the cycles (consecutive windows of a period, `samples` long) in which OP reaches
/// a limit and leaves it: a sample at a limit and one off it (an OP held at a limit throughout
/// bounds no cycle: the controller did not act).
fn cycles_at_limit(saturated: &[bool], samples: f64) -> f64 {
    share_of_cycles(saturated, samples, |c| {
        c.iter().any(|&s| s) && c.iter().any(|&s| !s)
    })
}

#[cfg(test)]
mod tests {
    use super::cycles_at_limit;

    #[test]
    fn the_share_counts_the_cycles_that_reach_a_limit() {
        // period 10: a limit in the 1st and 3rd of four cycles; a short tail is no cycle
        let mut s = vec![false; 43];
        s[4] = true;
        s[25] = true;
        s[42] = true;
        assert_eq!(cycles_at_limit(&s, 10.0), 0.5);
        assert_eq!(cycles_at_limit(&[false; 40], 10.0), 0.0);
        // held at the limit throughout: no cycle leaves it
        assert_eq!(cycles_at_limit(&[true; 40], 10.0), 0.0);
    }
}
