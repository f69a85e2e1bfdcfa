//! A long record: judged on its means at the loop's own time scale, or on the part where OP
//! moves most; what the diagnosis reports stays in the record's samples.

use super::*;

#[test]
fn a_long_sticky_record_is_judged_on_its_means() {
    let sticky = run(2.0, |cl| cl.samples = 24_000);
    let d = diagnose(&record(&sticky), &DiagnoseRequest::default()).unwrap();
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
    let on = d.judged_on.as_ref().expect("a long record is averaged");
    assert!(on.over > 1 && on.samples >= 2_000, "{on:?}");
    assert_eq!(on.ts, on.over as f64);
    assert!(on.stretch[1] <= d.samples && on.stretch[1] - on.stretch[0] == on.samples * on.over);
    let band = d.band.as_ref().unwrap().band_percent_of_span;
    assert!((1.0..3.0).contains(&band), "band {band}");
    // the ranges it reports are the record's samples
    let osc = d.oscillation.as_ref().unwrap().stretch;
    assert!(osc[0] < osc[1] && osc[1] <= d.samples, "{osc:?}");
    let q = d.quantified.unwrap();
    assert!(q[1] <= d.samples && q[1] - q[0] > 10_000, "{q:?}");
    let sticks = d
        .families
        .iter()
        .find_map(|f| f.stick_slip.as_ref())
        .unwrap();
    assert!(sticks
        .ranges
        .iter()
        .all(|r| r[0] < r[1] && r[1] <= d.samples));
}

#[test]
fn a_record_of_more_time_scales_than_the_most_is_judged_where_op_moves_most() {
    let healthy = run(0.0, |cl| cl.samples = 6_000);
    let mut req = quick();
    req.settings.averaging.min_samples = 1_000;
    req.settings.averaging.max_time_scales = 10;
    let d = diagnose(&record(&healthy), &req).unwrap();
    let on = d.judged_on.as_ref().expect("a part judged");
    // ten half-decay times are fewer than the thousand means a record keeps
    assert_eq!(on.samples, 1_000, "{on:?}");
    assert_eq!(on.stretch[1] - on.stretch[0], 1_000 * on.over);
    assert!(
        d.warnings.iter().any(|w| w.contains("where OP moves most")),
        "{:?}",
        d.warnings
    );
    // a record under twice the fewest means is judged sample by sample, and says nothing of it
    let short = run(0.0, |_| {});
    assert!(diagnose(&record(&short), &quick())
        .unwrap()
        .judged_on
        .is_none());
}
