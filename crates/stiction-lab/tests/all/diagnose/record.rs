//! The diagnosis of records on catalogue loops: a cycle across setpoint holds, a cycle of a few
//! samples.

use super::*;
use stiction_core::diagnose::{Action, Finding, Verdict};

#[test]
fn a_cycle_across_short_setpoint_holds_is_judged_across_them() {
    // routine-c-0218 of the catalogue's calibration set: a level loop whose He valve (fs = 2.81 %)
    // cycles every 6 minutes while the setpoint steps every 4-8 minutes. No hold has two whole
    // cycles; across the steps the loop's own cycle is judged
    let d = judge_catalogue("routine-c-0218");
    let o = d.oscillation.clone().unwrap();
    assert!(o.oscillating && o.across_setpoint_steps, "{o:?}");
    assert_eq!(o.stretch, [0, d.samples]);
    assert!(family_of(&d, Family::Shape).value.is_some());
}

#[test]
fn a_cycle_of_a_few_samples_is_named_not_called_unexcited() {
    // routine-b-0011 of the plant benchmark: a flow loop recorded every 10 s whose sticky valve
    // (Stenman d = 1.79 %) limit-cycles every 36 s; at 3.6 samples a cycle the cycle passes for
    // measurement noise: whatever the statistics say, the next step asks for faster records
    let d = judge_catalogue("routine-b-0011");
    assert_ne!(d.verdict, Verdict::Stiction, "{:?}", d.reasons);
    if d.verdict == Verdict::InsufficientData {
        let named = d
            .reasons
            .iter()
            .any(|r| matches!(r.finding, Finding::UnresolvedCycle { .. }));
        assert!(named, "{:?}", d.reasons);
    }
    assert_eq!(
        d.next_step.action,
        Action::SampleFaster,
        "{:?}",
        d.next_step
    );
    assert!(
        d.next_step.sample_every.is_some_and(|s| s < 10.0),
        "{:?}",
        d.next_step
    );
}
