//! The loop family on simulated fast loops (issue 14): a cooling-water-like loop sampled every 2 s
//! under a PI with a 25-minute integral time, its valve held by a Stenman band of 2 %, cycles
//! with a period of about two minutes; through a healthy valve, the same loop with an external
//! sinusoid at that period, or tuned to its stability limit, does not.

use stiction_core::diagnose::{
    diagnose, DiagnoseRequest, Diagnosis, Family, FamilyEvidence, Verdict, Vote,
};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, LoopData, Pi, Process, Signal};

/// The loop: K = 1, τ = 12 s, dead time 30 s, Kc = 1.3, Ti = 1500 s, Ts = 2 s.
fn fast_loop(d: f64, kc: f64, disturbance: Option<Signal>) -> LoopData {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d }));
    cl.process = Process::Foptd {
        k: 1.0,
        tau: 12.0,
        delay: 30.0,
    };
    cl.pi = Pi { kc, ti: 1500.0 };
    cl.ts = 2.0;
    cl.samples = 2000;
    cl.noise = 0.05;
    cl.seed = 3;
    cl.op0 = 41.5;
    cl.setpoint = Signal::Step {
        from: 50.0,
        to: 51.0,
        at: 10.0,
    };
    cl.disturbance = disturbance;
    cl.run().unwrap()
}

fn judge(l: &LoopData) -> Diagnosis {
    let req = DiagnoseRequest {
        ts: 2.0,
        quantify: false,
        ..DiagnoseRequest::default()
    };
    diagnose(&crate::diagnose::record(l), &req).unwrap()
}

fn loop_family(d: &Diagnosis) -> &FamilyEvidence {
    d.families
        .iter()
        .find(|f| f.family == Family::Loop)
        .unwrap()
}

#[test]
fn a_fast_sticky_loops_limit_cycle_needs_the_valves_lag_and_its_describing_function_band() {
    let d = judge(&fast_loop(2.0, 1.3, None));
    let period = d.oscillation.as_ref().and_then(|o| o.period).unwrap();
    assert!((90.0..150.0).contains(&period), "period {period}");
    // the loop family measures the lag the linear loop needs (the verdict's model does not read
    // it: on the real records it calls a healthy level loop sticky)
    let f = loop_family(&d);
    let e = f.limit_cycle.as_ref().unwrap();
    assert!(e.margins.gain_margin.unwrap() > 1.0, "{e:?}");
    assert!((25.0..90.0).contains(&e.needed_lag_degrees), "{e:?}");
    assert!(
        e.controller.ti.is_some_and(|t| (t - 1500.0).abs() < 30.0),
        "{e:?}"
    );
    let df = e.describing.as_ref().unwrap();
    assert!(
        (1.5..2.6).contains(&df.band_percent_of_span),
        "describing-function band {df:?}"
    );
    // the predicted period is reported; with the process identified from the record's changes it
    // is within about a third of the observed one here
    let predicted = df.predicted_period.unwrap();
    assert!((predicted / period - 1.0).abs() < 0.4, "{df:?}");
    // (the verdict: a near-sinusoidal limit cycle gives no sticks, a shape near a sine's and fits
    // alike with and without a band; the verdict's model reads none of this family's figures, so
    // such a valve can go unfound: the lab's verdict tables show the trade)
    assert!(d.verdict != Verdict::InsufficientData, "{:?}", d.reasons);
}

#[test]
fn an_external_sinusoid_at_the_loops_period_is_not_stiction() {
    for amplitude in [0.5, 2.0] {
        let sine = Signal::Sine {
            amplitude,
            period: 120.0,
            offset: 0.0,
        };
        let d = judge(&fast_loop(0.0, 1.3, Some(sine)));
        assert!(d.oscillation.as_ref().unwrap().oscillating);
        assert_ne!(
            loop_family(&d).vote,
            Vote::Stiction,
            "{}",
            loop_family(&d).note
        );
        assert_ne!(d.verdict, Verdict::Stiction, "{:?}", d.reasons);
    }
}

#[test]
fn a_loop_tuned_to_its_stability_limit_is_not_stiction() {
    // Kc = 1.4 sits at this loop's limit: the cycle drifts and grows
    let d = judge(&fast_loop(0.0, 1.4, None));
    let f = loop_family(&d);
    assert_ne!(f.vote, Vote::Stiction, "{}", f.note);
    let e = f.limit_cycle.as_ref().unwrap();
    assert!(e.needed_lag_degrees.abs() < 10.0, "{e:?}");
    assert_ne!(d.verdict, Verdict::Stiction, "{:?}", d.reasons);
}

#[test]
fn no_oscillation_no_loop_vote() {
    let d = judge(&fast_loop(0.0, 0.4, None));
    let f = loop_family(&d);
    assert_eq!(f.vote, Vote::Undetermined);
    assert!(
        f.limit_cycle.is_none() && f.note.contains("no oscillation"),
        "{}",
        f.note
    );
}
