//! The next step in words: what to do, per action, and what qualifies it (a steady setpoint, a
//! PV the historian did not record, the sampling a cycle needs).

use super::figures::fig;
use stiction_core::diagnose::{Action, NextStep};

/// Added to a weak verdict's next step when the setpoint holds over the whole stretch.
const STEADY_SETPOINT: &str = ", or judge a window that holds setpoint changes (here the setpoint holds, so the fits can hardly tell the process from the load)";

/// What to do, in words, for an action alone (the sampling of [`Action::SampleFaster`] left
/// general: [`next_step`] gives the figure).
pub fn action(a: Action) -> &'static str {
    match a {
        Action::MaintainValve => {
            "maintain the valve (packing, actuator, positioner): its recorded position shows the band"
        }
        Action::TravelTest => {
            "valve travel test recommended (small OP steps in manual, watching PV or the valve position) to confirm before maintenance"
        }
        Action::NoAction => "no action on the valve",
        Action::NoActionWeak => {
            "no action on the valve on this evidence, which is weak (a sticky valve that does not cycle often leaves no more): \
             if the loop performs poorly, a valve travel test settles it"
        }
        Action::CheckTuning => {
            "the valve is not the cause: check the tuning and disturbances at the oscillation's period"
        }
        Action::SettleIt => {
            "record the valve position (MV) or run a valve travel test to settle it"
        }
        Action::SampleFaster => {
            "record the loop at least ten samples a cycle and judge it again"
        }
        Action::LongerRecord => {
            "use a longer record in automatic with the loop excited (setpoint changes or disturbances)"
        }
        Action::UsableRecord => {
            "use a longer record in automatic with every signal present, OP as the controller wrote it"
        }
        Action::CheckTransmitter => {
            "check the PV transmitter and its historian tag, then judge a record in which PV moves"
        }
    }
}

/// The next step in words, with its qualifiers.
pub fn next_step(n: &NextStep) -> String {
    let mut s = match (n.action, n.sample_every) {
        (Action::SampleFaster, Some(every)) => format!(
            "record the loop at least ten samples a cycle (every {} s or faster) and judge it again",
            fig(every)
        ),
        (a, _) => action(a).to_string(),
    };
    if n.setpoint_steady {
        s.push_str(STEADY_SETPOINT);
    }
    if let Some(share) = n.pv_not_recorded {
        s.push_str(&format!(
            "; but PV is not recorded in {} % of the samples (historian compression or a frozen transmitter), \
             and compression hides a sticky valve's sticks: judge a record stored without compression before ruling the valve out",
            fig(100.0 * share)
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn qualifiers_are_added_to_the_action() {
        let mut n = NextStep::plain(Action::SettleIt);
        assert_eq!(next_step(&n), action(Action::SettleIt));
        n.setpoint_steady = true;
        n.pv_not_recorded = Some(0.62);
        let s = next_step(&n);
        assert!(
            s.contains("or judge a window that holds setpoint changes"),
            "{s}"
        );
        assert!(s.contains("not recorded in 62 % of the samples"), "{s}");
        let mut n = NextStep::plain(Action::SampleFaster);
        n.sample_every = Some(0.6);
        assert!(next_step(&n).contains("every 0.6 s or faster"));
    }

    #[test]
    fn no_next_step_quotes_a_benchmark() {
        for a in [
            Action::MaintainValve,
            Action::TravelTest,
            Action::NoAction,
            Action::NoActionWeak,
            Action::CheckTuning,
            Action::SettleIt,
            Action::SampleFaster,
            Action::LongerRecord,
            Action::UsableRecord,
            Action::CheckTransmitter,
        ] {
            let mut n = NextStep::plain(a);
            n.pv_not_recorded = Some(0.5);
            n.setpoint_steady = true;
            let s = next_step(&n);
            assert!(!s.is_empty());
            assert!(!s.contains("simulat") && !s.contains("benchmark"), "{s}");
        }
    }
}
