//! The loop family's vote on fixed evidence.
use super::*;
use crate::diagnose::result::Vote;

/// A fast loop's cycle (fast-c-0004 of the plant benchmark: Stenman band 4.65 %, sampled every
/// 5 s, a cycle of 8.8 samples), its harmonics left out.
const SHORT_CYCLE: &str = r#"{"controller": {"kc": 0.65, "ki": 0.759, "ti": 4.278, "action": "reverse", "lag": 0, "r2": 0.83, "samples": 1999}, "setpoint_recorded": true, "process": "stiction_fit", "margins": {"gain_margin": 1.458, "critical_period": 28.194, "phase_margin": 21.054, "modulus_margin": 0.247}, "period": 44.1, "op_amplitude": 2.807, "pv_amplitude": 1.87, "samples_per_cycle": 8.82, "harmonic_count": 0, "residual_share": 0.284, "controller_residual_share": 0.153, "op_at_limit": 0.0, "needed_gain": 0.843, "needed_lag_degrees": 28.747, "describing": {"model": "kano", "slip_ratio": 0.5, "band": 3.477, "band_percent_of_span": 3.477, "amplitude_over_band": 0.807, "distance": 0.013, "predicted_period": 44.98, "period_matches": true}, "calibration": ""}"#;

fn judged(harmonics: Option<f64>, harmonic_count: usize) -> FamilyEvidence {
    let mut e: LoopEvidence = serde_json::from_str(SHORT_CYCLE).unwrap();
    e.harmonics = harmonics;
    e.harmonic_count = harmonic_count;
    super::vote::vote(e, "", String::new())
}

#[test]
fn harmonics_are_measured_up_to_the_nyquist_frequency() {
    assert_eq!(measure::measurable_harmonics(20.0), 5);
    assert_eq!(measure::measurable_harmonics(11.0), 5);
    assert_eq!(measure::measurable_harmonics(8.82), 4);
    assert_eq!(measure::measurable_harmonics(7.0), 3);
    assert_eq!(measure::measurable_harmonics(6.5), 2);
}

#[test]
fn a_cycle_too_short_for_harmonics_is_not_called_sinusoidal() {
    // distorted over the harmonics that could be measured: the valve's lag closes the balance
    let measured = judged(Some(0.06), 4);
    assert_eq!(measured.vote, Vote::Stiction, "{}", measured.note);
    assert!(
        measured.note.contains("harmonics 0.060 (2 to 4)"),
        "{}",
        measured.note
    );
    // none measurable: not asked for, and said so
    let unmeasured = judged(None, 0);
    assert_eq!(unmeasured.vote, Vote::Stiction, "{}", unmeasured.note);
    assert!(
        unmeasured.note.contains("harmonics not measured"),
        "{}",
        unmeasured.note
    );
    assert!(
        !unmeasured.note.contains("sinusoidal"),
        "{}",
        unmeasured.note
    );
    // measured and sinusoidal: no valve
    let sine = judged(Some(0.001), 5);
    assert_eq!(sine.vote, Vote::Undetermined);
    assert!(sine.note.contains("sinusoidal"), "{}", sine.note);
}

#[test]
fn a_loop_just_past_its_limit_still_needs_the_valves_lag() {
    let with_margin = |g: f64| {
        let mut e: LoopEvidence = serde_json::from_str(SHORT_CYCLE).unwrap();
        e.harmonics = Some(0.06);
        e.harmonic_count = 4;
        e.margins.gain_margin = Some(g);
        super::vote::vote(e, "", String::new())
    };
    let near = with_margin(0.9);
    assert_eq!(near.vote, Vote::Stiction, "{}", near.note);
    assert!(
        near.note
            .contains("just past its stability limit (gain margin 0.90)"),
        "{}",
        near.note
    );
    let unstable = with_margin(0.7);
    assert_eq!(unstable.vote, Vote::Undetermined);
    assert!(
        unstable.note.contains("unstable (gain margin under 0.8)"),
        "{}",
        unstable.note
    );
}

/// The cycle of issue 14's example as the family measures it (Kc at 0.996 of the ultimate gain,
/// a Stenman band of 2 %): the identified loop is at its limit and needs no valve lag.
fn marginal(scatter: f64, change: f64, wander: f64, setpoint: bool) -> FamilyEvidence {
    marginal_over(31, scatter, change, wander, setpoint)
}

fn marginal_over(
    cycles: usize,
    scatter: f64,
    change: f64,
    wander: f64,
    setpoint: bool,
) -> FamilyEvidence {
    let mut e: LoopEvidence = serde_json::from_str(SHORT_CYCLE).unwrap();
    e.needed_gain = 0.98;
    e.needed_lag_degrees = 5.0;
    e.margins.gain_margin = Some(1.0);
    e.harmonics = Some(0.0);
    e.harmonic_count = 5;
    e.residual_share = 0.01;
    e.setpoint_recorded = setpoint;
    e.amplitude = Some(AmplitudeTrend {
        cycles,
        mean: 10.0,
        change,
        scatter,
    });
    e.phase_wander = Some(wander);
    super::vote::vote(e, "", String::new())
}

#[test]
fn a_steady_cycle_whose_phase_runs_free_sustains_itself() {
    let held = marginal(0.06, 0.12, 3.8, true);
    assert_eq!(held.vote, Vote::Stiction, "{}", held.note);
    assert_eq!(held.strength, SELF_SUSTAINED);
    assert!(
        held.note.contains("the cycle sustains itself") && held.note.contains("phase wander 3.8"),
        "{}",
        held.note
    );
    // a cycle that keeps time with an input of fixed period (an external sinusoid the fit absorbed)
    let forced = marginal(0.02, 0.0, 1.1, true);
    assert_eq!(forced.vote, Vote::Undetermined, "{}", forced.note);
    assert!(
        forced.note.contains("sustains the cycle by itself"),
        "{}",
        forced.note
    );
    // a resonance that noise swells and shrinks, or a cycle that grows
    for (scatter, change) in [(0.4, 0.0), (0.05, 1.5)] {
        let linear = marginal(scatter, change, 8.0, true);
        assert_eq!(linear.vote, Vote::Undetermined, "{}", linear.note);
    }
    // without a setpoint an outer loop's cycle could move it: said, not voted
    let blind = marginal(0.06, 0.12, 3.8, false);
    assert_eq!(blind.vote, Vote::Undetermined, "{}", blind.note);
    assert!(
        blind.note.contains("sustains itself") && blind.note.contains("without a setpoint"),
        "{}",
        blind.note
    );
}

#[test]
fn a_long_record_lets_a_steady_amplitude_scatter_more() {
    // scatter 0.2: steady over 30 cycles or more (noise cannot bring a driven resonance's
    // scatter this low over so many), not over fewer
    let long = marginal_over(STEADY_CYCLES, 0.2, 0.1, 5.0, true);
    assert_eq!(long.vote, Vote::Stiction, "{}", long.note);
    let short = marginal_over(STEADY_CYCLES - 1, 0.2, 0.1, 5.0, true);
    assert_eq!(short.vote, Vote::Undetermined, "{}", short.note);
    // the Rayleigh-like scatter of a noise-driven resonance is never steady
    let swelling = marginal_over(200, 0.5, 0.1, 5.0, true);
    assert_eq!(swelling.vote, Vote::Undetermined, "{}", swelling.note);
}
