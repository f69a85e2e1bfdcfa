//! The shape and stick-slip families: indices, integrating loops, compressed PVs, a level's episodes.

use super::*;

#[test]
fn integrating_loops_use_the_second_difference_histogram() {
    let sticky = sticky_level(|cl| {
        cl.pi.kc = 2.0;
        cl.pi.ti = 100.0;
        cl.samples = 3000;
        cl.seed = 2;
    });
    let req = DiagnoseRequest {
        integrating: true,
        ..quick()
    };
    let d = diagnose(&record(&sticky), &req).unwrap();
    assert_eq!(d.verdict, Verdict::Stiction, "{:#?}", d.evidence);
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
    assert_eq!(d.verdict, Verdict::NoStiction, "{:#?}", d.evidence);

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
    assert_ne!(d.verdict, Verdict::Stiction, "{:#?}", d.evidence);
    let model = model_family(&d);
    assert_eq!(model.vote, Vote::NoStiction, "{model:#?}");
    assert!(
        model.note.contains("enters the loop elsewhere"),
        "{}",
        model.note
    );
    assert!(d.band.is_none());
}

#[test]
fn a_levels_stick_slip_episodes_are_judged_on_the_level_itself() {
    // a sticky level valve: the stick-slip family looks for OP travelling while the level
    // stays inside its own noise band (the band of PV, not of a rate)
    let sticky = sticky_level(|_| {});
    let req = DiagnoseRequest {
        integrating: true,
        ..quick()
    };
    let d = diagnose(&record(&sticky), &req).unwrap();
    let f = d
        .families
        .iter()
        .find(|f| f.family == Family::StickSlip)
        .unwrap();
    let e = f.stick_slip.as_ref().unwrap();
    let band =
        Thresholds::default().pv_band_sigmas * stiction_core::detect::measurement_noise(&sticky.pv);
    assert!(
        (e.pv_band - band).abs() < 1e-12,
        "{} against {band}",
        e.pv_band
    );
}
