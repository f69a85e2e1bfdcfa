//! The diagnosis of records on catalogue loops: a cycle across setpoint holds, saturation, a
//! cycle of a few samples.

use super::*;

#[test]
fn a_cycle_across_short_setpoint_holds_is_judged_across_them() {
    // routine-c-0218 of the catalogue's calibration set: a level loop whose He valve (fs = 2.81 %)
    // cycles every 6 minutes while the setpoint steps every 4-8 minutes. No hold has two whole
    // cycles; across the steps the loop's own cycle is judged, and the families name the valve.
    let d = judge_catalogue("routine-c-0218");
    let o = d.oscillation.clone().unwrap();
    assert!(o.oscillating && o.across_setpoint_steps, "{o:?}");
    assert_eq!(o.stretch, [0, d.samples]);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}

#[test]
fn a_cycle_that_saturation_cuts_short_is_judged_by_its_saturation() {
    // fast-b-0180 of the plant catalogue: a healthy flow valve near 0 % whose load oscillation
    // drives OP to its limit every cycle; the samples at the limit are left out, the longest
    // stretch left has 93 samples, and the record was `insufficient_data`
    let d = judge_catalogue("fast-b-0180");
    assert_eq!(d.verdict, Verdict::NoStiction, "{:?}", d.reason);
    assert_eq!(d.families.len(), 1);
    let f = &d.families[0];
    assert_eq!((f.family, f.vote), (Family::Loop, Vote::NoStiction));
    assert!(f.note.contains("saturation bounds the cycle"), "{}", f.note);
    assert!(d.next_step.contains("limits"), "{}", d.next_step);
    assert!(d.warnings.iter().any(|w| w.contains("too short")));
    // the verdict reads the whole record, and the record-length finding says so
    assert_eq!(d.analysed, [0, d.samples]);
    let length = d
        .quality
        .iter()
        .find(|f| f.gate == Gate::RecordLength)
        .unwrap();
    assert!(
        length.message.contains("whole record"),
        "{}",
        length.message
    );
    // windows use the same rule
    let l = stiction_lab::catalogue::find("fast-b-0180").unwrap();
    let req = DiagnoseRequest {
        ts: l.ts(),
        window: Some(500),
        ..DiagnoseRequest::default()
    };
    let d = diagnose(&record(&l.data), &req).unwrap();
    assert!(d.windows.iter().all(|w| w.verdict == Verdict::NoStiction));
    // a record cut short without a cycle that reaches the limits stays unjudged
    let mut quiet = run(0.0, |cl| cl.samples = 150);
    quiet.op[60] = 100.0;
    let d = diagnose(&record(&quiet), &DiagnoseRequest::default()).unwrap();
    assert_eq!(d.verdict, Verdict::InsufficientData);
}

#[test]
fn a_cycle_of_a_few_samples_is_named_not_called_unexcited() {
    // routine-b-0011 of the plant benchmark: a flow loop recorded every 10 s whose sticky valve
    // (Stenman d = 1.79 %) limit-cycles every 36 s; at 3.6 samples a cycle the cycle passes for
    // measurement noise, and no family can judge it
    let d = judge_catalogue("routine-b-0011");
    assert_eq!(d.verdict, Verdict::InsufficientData, "{:?}", d.evidence);
    let reason = d.reason.unwrap();
    assert!(
        reason.contains("cycles regularly every") && reason.contains("samples a cycle"),
        "{reason}"
    );
    assert!(
        d.next_step.contains("ten samples a cycle"),
        "{}",
        d.next_step
    );
    // a loop that is merely quiet keeps the usual reason (routine-b-0274: a healthy temperature
    // loop at a constant setpoint, its PV hardly moving above the noise)
    let q = judge_catalogue("routine-b-0274");
    assert_eq!(q.verdict, Verdict::InsufficientData, "{:?}", q.evidence);
    assert!(
        q.reason.as_deref().unwrap().contains("not excited enough"),
        "{:?}",
        q.reason
    );
    assert!(q.next_step.contains("longer record"), "{}", q.next_step);
}
