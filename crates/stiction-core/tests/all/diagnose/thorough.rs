//! `thorough`: the levels test and the hidden valve on loops of the public simulation (the
//! catalogue's cases are in the lab's tests).

use super::*;

#[test]
fn thorough_runs_the_hidden_valve_only_where_it_can_judge_and_change_the_verdict() {
    let thorough = DiagnoseRequest {
        thorough: true,
        ..DiagnoseRequest::default()
    };
    let hidden = |d: &stiction_core::diagnose::Diagnosis| hidden_valve_of(d).clone();
    // a healthy valve under noise alone: no oscillation, no judgement
    let calm = run(0.0, |_| {});
    let d = diagnose(&record(&calm), &thorough).unwrap();
    let h = hidden(&d);
    assert_eq!(h.vote, Vote::Undetermined);
    assert!(h.note.contains("does not oscillate"), "{}", h.note);
    assert!(h.hidden_valve.is_none());
    // a sticky valve the other families already call sticky: not run
    let sticky = run(2.0, |_| {});
    let d = diagnose(&record(&sticky), &thorough).unwrap();
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
    assert!(hidden(&d).note.contains("not run"), "{}", hidden(&d).note);
}
