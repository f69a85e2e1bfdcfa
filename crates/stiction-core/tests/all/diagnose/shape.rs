//! The shape and stick-slip families: indices, integrating loops, compressed PVs, a level's episodes.

use super::*;
use stiction_core::diagnose::Statistic;

#[test]
fn integrating_loops_use_the_second_difference_histogram() {
    let sticky = sticky_level(|cl| {
        cl.pi.kc = 2.0;
        cl.pi.ti = 100.0;
        cl.samples = 3000;
        cl.seed = 2;
    });
    let req = DiagnoseRequest {
        integrating: Some(true),
        ..quick()
    };
    let d = diagnose(&record(&sticky), &req).unwrap();
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
    let ddpv = d
        .indices
        .iter()
        .find(|i| i.name == "ddpv_histogram")
        .unwrap();
    assert_eq!(ddpv.vote, Vote::Stiction);
    assert!(d.indices.iter().all(|i| i.name != "cross_correlation"));
}

#[test]
fn a_sinusoidal_oscillation_is_linear_whatever_its_phase() {
    // a slow disturbance against an integral-dominated controller puts OP about 90 degrees
    // behind PV, which Horch's cross-correlation reads as stiction; OP and PV are sinusoids,
    // which the harmonics index reads as a linear oscillation
    let disturbed = disturbed((3.0, 10.0, 10.0), (0.2, 10.0), 0.02);
    let d = diagnose(&record(&disturbed), &quick()).unwrap();
    let vote = |name: &str| d.indices.iter().find(|i| i.name == name).unwrap().vote;
    assert_eq!(vote("harmonics"), Vote::NoStiction, "{:#?}", d.indices);
    assert_eq!(d.verdict, Verdict::NoStiction, "{:#?}", d.reasons);

    // a sticky valve's jumps put harmonics into the loop: the index stays silent
    let sticky = run(2.0, |_| {});
    let d = diagnose(&record(&sticky), &quick()).unwrap();
    let h = d.indices.iter().find(|i| i.name == "harmonics").unwrap();
    assert_eq!(h.vote, Vote::Undetermined, "{h:#?}");
    assert!(h.value.unwrap() > 0.01);
}

#[test]
fn an_oscillation_that_op_does_not_drive_is_not_stiction() {
    // OP ramps up and down like a controller behind a sticky valve, but the PV's oscillation
    // (another period, square) does not come from it: the shape indices see stiction, the
    // closed-loop fit finds that OP explains almost none of the PV
    let n = 3000;
    let mut state = 7u64;
    let mut noise = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.02
    };
    let op: Vec<f64> = (0..n)
        .map(|i| {
            let p = (i as f64 / 100.0).fract();
            50.0 + if p < 0.5 {
                4.0 * p - 1.0
            } else {
                3.0 - 4.0 * p
            } + noise()
        })
        .collect();
    let pv: Vec<f64> = (0..n)
        .map(|i| {
            let p = (i as f64 / 37.0).fract();
            10.0 + if p < 0.5 { 1.0 } else { -1.0 } + noise()
        })
        .collect();
    let rec = LoopRecord {
        op: &op,
        pv: &pv,
        sp: None,
        mv: None,
        time: None,
        auto: None,
    };
    let d = diagnose(&rec, &DiagnoseRequest::default()).unwrap();
    assert_ne!(d.verdict, Verdict::Stiction, "{:#?}", d.reasons);
    // OP explains none of PV's cycle: its shape and PV's steps are not read as a valve's
    let model = model_family(&d).model.as_ref().unwrap();
    assert!(model.explained < 0.3, "{model:?}");
    let read = d.statistics.as_ref().unwrap();
    for s in [Statistic::CycleShape, Statistic::StickShare] {
        let c = read
            .contributions
            .iter()
            .find(|c| c.statistic == s)
            .unwrap();
        assert!(c.value.is_none(), "{c:?}");
    }
    assert!(d.band.is_none());
}

#[test]
fn a_levels_sticks_are_judged_on_the_level_itself() {
    // a sticky level valve: the stick-slip family reads PV's levels against the level's own noise
    // (not a rate's)
    let sticky = sticky_level(|_| {});
    let req = DiagnoseRequest {
        integrating: Some(true),
        ..quick()
    };
    let d = diagnose(&record(&sticky), &req).unwrap();
    let f = d
        .families
        .iter()
        .find(|f| f.family == Family::StickSlip)
        .unwrap();
    let e = f.stick_slip.as_ref().unwrap();
    let noise = stiction_core::detect::measurement_noise(&sticky.pv);
    assert!(
        (e.pv_noise - noise).abs() < 1e-12,
        "{} against {noise}",
        e.pv_noise
    );
    assert!(e.steps > 0, "{e:?}");
}
