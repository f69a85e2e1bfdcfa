//! The verdict's next step: one line on what to do, from the verdict and the families' evidence.

use super::{model_flag, Motion};
use crate::diagnose::evidence::{Family, FamilyEvidence};
use crate::diagnose::result::{Verdict, Vote};

/// Below this confidence a `no_stiction` rests only on weak votes against (a fit no better than
/// healthy loops give, no stick-slip episode found), which a sticky valve often gives too: on the
/// plant benchmark's routine windows such verdicts are right far less often than those at 0.8 or
/// more (stiction-lab/results/plant-benchmark.md, "What the confidence means here").
const WEAK_NO_STICTION: f64 = 0.6;

/// Added to a weak verdict's next step when the setpoint holds over the whole stretch.
const STEADY_SETPOINT: &str =
    ", or judge a window that holds setpoint changes (here the setpoint holds, so the fits can hardly tell the process from the load)";

/// One line: what to do next; on a record whose PV is mostly not recorded, a verdict other than
/// `stiction` also says that compression hides sticks (measured by the lab's `compressed_sticky`
/// study: the routine benchmark's sticky loops are called `stiction` far less often with their PV
/// compressed).
pub(super) fn next_step(
    verdict: Verdict,
    confidence: Option<f64>,
    families: &[FamilyEvidence],
    motion: &Motion,
) -> String {
    let step = next_step_of(verdict, confidence, families, motion);
    match motion.pv_not_recorded {
        Some(share) if matches!(verdict, Verdict::NoStiction | Verdict::Undetermined) => format!(
            "{step}; but PV is not recorded in {:.0} % of the samples (historian compression or a frozen transmitter), \
             and compression hides a sticky valve's sticks (simulated sticky valves recorded through it are found far less \
             often than stored whole): judge a record stored without compression before ruling the valve out",
            100.0 * share
        ),
        _ => step,
    }
}

/// A `stiction` verdict's next step without a recorded valve position.
const TRAVEL_TEST: &str = "valve travel test recommended (small OP steps in manual, watching PV or the valve position) to confirm before maintenance";

/// Added to a `stiction` verdict's next step when only the cycle voted stiction (its shape, or its
/// steady, free-running rhythm): another loop's stiction cycle, carried through the process or a
/// cascade's setpoint, gives both (the lab's `propagated_oscillation` study;
/// stiction-lab/results/propagated-oscillation.md).
const CYCLE_ALONE: &str = "only the cycle (its shape or its steady, free-running rhythm) points to the valve, and another \
loop's sticky valve cycling this loop gives that too (healthy loops cycled by one in simulation: 39 of 236 called stiction \
on the cycle alone): if other loops oscillate at this period, find the one the others follow first";

/// Whether the loop family found the identified linear loop at its stability limit at the
/// cycle's period.
fn marginal_loop(families: &[FamilyEvidence]) -> bool {
    families.iter().any(|f| {
        f.family == Family::Loop
            && f.limit_cycle
                .as_ref()
                .is_some_and(|e| e.linear_loop_sustains())
    })
}

/// Whether only the families that read the cycle itself (its shape, the loop's limit cycle) vote
/// stiction.
fn cycle_alone(families: &[FamilyEvidence]) -> bool {
    let mut voters = families
        .iter()
        .filter(|f| f.vote == Vote::Stiction)
        .peekable();
    voters.peek().is_some() && voters.all(|f| matches!(f.family, Family::Shape | Family::Loop))
}

/// Whether the closed-loop fit found that OP does not drive PV through any valve.
pub(in crate::diagnose) fn op_does_not_drive(families: &[FamilyEvidence]) -> bool {
    families.iter().any(|f| {
        f.family == Family::Model
            && f.vote == Vote::NoStiction
            && f.model
                .as_ref()
                .is_some_and(|m| m.explained < crate::diagnose::evidence::model::MIN_EXPLAINED)
    })
}

fn next_step_of(
    verdict: Verdict,
    confidence: Option<f64>,
    families: &[FamilyEvidence],
    motion: &Motion,
) -> String {
    let voted = |fam: Family, v: Vote| families.iter().any(|f| f.family == fam && f.vote == v);
    let op_does_not_drive = op_does_not_drive(families);
    // the closed-loop fit's stiction vote withdrawn: its gain lay in a cycle that keeps time
    let clock_cycle = families.iter().any(|f| {
        f.family == Family::Model
            && f.model
                .as_ref()
                .is_some_and(|m| m.gain_in_a_clock_regular_cycle)
    });
    match verdict {
        Verdict::Stiction => {
            if families
                .iter()
                .any(|f| f.family == Family::Valve && f.vote == Vote::Stiction)
            {
                "maintain the valve (packing, actuator, positioner): its recorded position shows the band".into()
            } else if cycle_alone(families) {
                format!("{TRAVEL_TEST}; {CYCLE_ALONE}")
            } else {
                TRAVEL_TEST.into()
            }
        }
        Verdict::NoStiction if voted(Family::Loop, Vote::NoStiction) => {
            "the valve is not the cause here: OP reaches its limits in the cycle (a disturbance larger than the valve can take, a valve too small for its duty, or tuning); judge the valve again once OP stays off its limits".into()
        }
        Verdict::NoStiction if op_does_not_drive => {
            "look upstream: OP does not drive this variation (an external disturbance or an interacting loop)".into()
        }
        Verdict::NoStiction if voted(Family::Shape, Vote::NoStiction) && marginal_loop(families) => {
            "check the tuning first: the cycle is sinusoidal and the identified loop sits at its stability limit at its period \
             (aggressive tuning gives that, and so does a sticky valve whose band is small beside the cycle): if the cycle stays \
             once the loop is detuned, test the valve".into()
        }
        Verdict::NoStiction if voted(Family::Shape, Vote::NoStiction) => {
            "the valve is not the cause: check the tuning and disturbances at the oscillation's period".into()
        }
        Verdict::NoStiction if confidence.is_some_and(|c| c < WEAK_NO_STICTION) => format!(
            "no action on the valve on this evidence, which is weak (a sticky valve that does not cycle often leaves no more): \
             if the loop performs poorly, a valve travel test settles it{}",
            if motion.setpoint_steady { STEADY_SETPOINT } else { "" }
        ),
        Verdict::NoStiction => "no action on the valve".into(),
        Verdict::Undetermined if clock_cycle => format!(
            "look for an input at the cycle's period, upstream or in an interacting loop (the cycle keeps time like one); \
             without one, record the valve position (MV) or run a valve travel test to settle it{}",
            if motion.setpoint_steady { STEADY_SETPOINT } else { "" }
        ),
        Verdict::Undetermined if model_flag(families, |m| m.op_moved_elsewhere) => {
            "OP moves with an input the record does not hold: if the controller has a feed-forward, a ratio or an override, \
             judge a window where it holds still, or record the valve position (MV), or run a valve travel test to settle it"
                .into()
        }
        Verdict::Undetermined => format!(
            "record the valve position (MV) or run a valve travel test to settle it{}",
            if motion.setpoint_steady { STEADY_SETPOINT } else { "" }
        ),
        Verdict::InsufficientData => match motion.unresolved_cycle {
            Some((period, _)) => format!(
                "record the loop at least ten samples a cycle (every {:.1} s or faster) and judge it again",
                period / 10.0
            ),
            None => "use a longer record in automatic with the loop excited (setpoint changes or disturbances)".into(),
        },
    }
}
