//! The record: usable stretches, manual mode, gaps, windows, OP's limits, a PV at its limit.

use super::*;
use stiction_core::diagnose::Action;

#[test]
fn sticky_healthy_and_disturbed_loops() {
    let sticky = run(2.0, |_| {});
    let d = diagnose(&record(&sticky), &DiagnoseRequest::default()).unwrap();
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
    let band = d.band.unwrap().band_percent_of_span;
    assert!((band - 2.0).abs() < 0.5, "band {band}");
    assert!(d.oscillation.unwrap().oscillating);
    for i in &d.indices {
        assert!(!i.threshold.is_empty() && !i.reference.is_empty());
    }

    let healthy = run(0.0, |_| {});
    let d = diagnose(&record(&healthy), &quick()).unwrap();
    assert_eq!(d.verdict, Verdict::NoStiction, "{:#?}", d.reasons);

    // an external sinusoidal disturbance through a healthy valve: oscillates, not stiction
    let disturbed = disturbed((1.0, 30.0, 5.0), (1.0, 30.0), 0.05);
    let d = diagnose(&record(&disturbed), &quick()).unwrap();
    assert!(d.oscillation.as_ref().unwrap().oscillating);
    assert_ne!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
}

#[test]
fn unusable_samples_are_left_out_and_gaps_split_the_record() {
    let sticky = run(2.0, |_| {});
    // every sample in manual
    let auto = vec![false; sticky.op.len()];
    let mut r = record(&sticky);
    r.auto = Some(&auto);
    let d = diagnose(&r, &quick()).unwrap();
    assert_eq!(d.verdict, Verdict::InsufficientData);
    assert!(d.indices.is_empty());
    // OP stuck at 100 %
    let op = vec![100.0; sticky.op.len()];
    let mut r = record(&sticky);
    r.op = &op;
    let d = diagnose(&r, &quick()).unwrap();
    assert_eq!(d.verdict, Verdict::InsufficientData);
    // a gap in time splits the record; the longer stretch is judged
    let mut t = sticky.t.clone();
    for v in &mut t[1200..] {
        *v += 500.0;
    }
    let mut r = record(&sticky);
    r.time = Some(&t);
    let d = diagnose(&r, &quick()).unwrap();
    assert_eq!(d.stretches, vec![[0, 1200], [1200, 2000]]);
    assert_eq!(d.analysed, [0, 1200]);
    assert!(d
        .quality
        .iter()
        .any(|f| f.gate == Gate::TimeGaps && !f.passed));
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
    // a missing value or three in a row are bridged by a straight line, with a note
    let mut pv = sticky.pv.clone();
    pv[300] = f64::NAN;
    pv[900..903].fill(f64::NAN);
    let mut r = record(&sticky);
    r.pv = &pv;
    let d = diagnose(&r, &quick()).unwrap();
    assert_eq!(d.stretches, vec![[0, 2000]]);
    assert!(
        d.warnings.iter().any(|w| w.starts_with(
            "2 short gaps (4 samples with a missing value) bridged by straight lines"
        )),
        "{:?}",
        d.warnings
    );
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
    // a longer run of missing values splits it
    pv[300] = sticky.pv[300];
    pv[900..904].fill(f64::NAN);
    let mut r = record(&sticky);
    r.pv = &pv;
    let d = diagnose(&r, &quick()).unwrap();
    assert_eq!(d.stretches, vec![[0, 900], [904, 2000]]);
    assert!(d.warnings.iter().all(|w| !w.contains("bridged")));
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
}

#[test]
fn manual_stretches_are_left_out_and_setpoint_changes_kept() {
    let sticky = run(2.0, |_| {});
    let n = sticky.op.len();
    let auto: Vec<bool> = (0..n).map(|k| k >= 400).collect();
    let mut r = record(&sticky);
    r.auto = Some(&auto);
    let d = diagnose(&r, &quick()).unwrap();
    assert_eq!(d.analysed, [400, n]);
    assert_eq!(d.verdict, Verdict::Stiction);
    // the default setpoint steps at 10 s: the whole record is analysed
    let d = diagnose(&record(&sticky), &quick()).unwrap();
    assert_eq!(d.analysed, [0, n]);
}

#[test]
fn too_short_for_its_oscillation_is_never_a_confident_no() {
    let sticky = run(2.0, |_| {});
    let r = LoopRecord {
        op: &sticky.op[500..700],
        pv: &sticky.pv[500..700],
        sp: None,
        mv: None,
        time: None,
        auto: None,
    };
    let d = diagnose(&r, &quick()).unwrap();
    // a few periods of a cycle, no stick, no fit to gain: no evidence of a sticky valve, which
    // the next step says is weak
    assert_ne!(d.verdict, Verdict::Stiction, "{:?}", d.reasons);
    assert!(
        matches!(
            d.next_step.action,
            Action::NoActionWeak | Action::SettleIt | Action::CheckTuning
        ),
        "{:?}",
        d.next_step
    );
}

#[test]
fn windows_cover_the_record_and_bad_requests_are_errors() {
    let sticky = run(2.0, |cl| cl.samples = 3000);
    let req = DiagnoseRequest {
        window: Some(1000),
        ..quick()
    };
    let d = diagnose(&record(&sticky), &req).unwrap();
    assert_eq!(d.windows.len(), 3);
    assert_eq!(d.windows[0].start, 0);
    assert_eq!(d.windows[2].end, 3000);
    // a 1000-sample window of a regular limit cycle can leave every family undecided (the
    // linear loop fits it at its stability limit): never `no_stiction`, never short of data
    let mut called = 0;
    for w in &d.windows {
        assert!(
            matches!(w.verdict, Verdict::Stiction | Verdict::Undetermined),
            "{w:?}"
        );
        if w.verdict == Verdict::Stiction {
            // the model's probability decided, and a family's statistics pushed it there
            assert!(w.probability.is_some_and(|p| p >= 0.5), "{w:?}");
            assert!(w.votes.iter().any(|v| v.1 == Vote::Stiction), "{w:?}");
            called += 1;
        }
    }
    assert!(called >= 2, "{:?}", d.windows);
    let bad = DiagnoseRequest {
        window: Some(5),
        ..quick()
    };
    assert!(diagnose(&record(&sticky), &bad).is_err());
    let mut r = record(&sticky);
    let short = &sticky.pv[..10];
    r.pv = short;
    assert!(diagnose(&r, &quick()).is_err());
}

#[test]
fn a_pv_held_at_its_transmitters_limit_is_left_out() {
    // a healthy loop whose PV reads 100 % while the process runs above it: OP winds up while PV
    // stays put, then PV moves OP's way, as a sticky valve's stick and slip would
    let mut l = run(0.0, |cl| {
        cl.samples = 3000;
        cl.setpoint = Signal::Constant { value: 95.0 };
        cl.op0 = 50.0;
        cl.load = Some(Signal::Steps {
            amplitude: 8.0,
            hold: 400.0,
            offset: 0.0,
            seed: 3,
        });
    });
    let clipped = l.pv.iter().filter(|&&v| v >= 100.0).count();
    for v in &mut l.pv {
        *v = v.min(100.0);
    }
    assert!(clipped > 30, "the PV must reach its limit: {clipped}");
    let d = diagnose(&record(&l), &quick()).unwrap();
    let f = d
        .quality
        .iter()
        .find(|f| f.gate == Gate::PvAtLimit)
        .unwrap_or_else(|| panic!("{:#?}", d.quality));
    assert!(
        f.message.contains("PV held at its extreme"),
        "{}",
        f.message
    );
    assert!(d.analysed[1] - d.analysed[0] <= l.pv.len() - clipped);
}
