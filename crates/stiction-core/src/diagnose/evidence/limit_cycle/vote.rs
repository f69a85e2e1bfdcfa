//! The loop family's vote on what it measured, and its note in words.

use super::{
    LoopEvidence, StictionBasis, FREE_RUNNING, FULL_LAG, LIMIT_CYCLES, MAX_CONTROLLER_RESIDUAL,
    MAX_DISTANCE, MAX_LAG, MAX_RESIDUAL, MIN_LAG, MIN_MARGIN, NO_SETPOINT, SATURATION_STRENGTH,
    SELF_SUSTAINED, STEADY_CYCLES, STEADY_SCATTER, STEADY_SCATTER_LONG, UNSTEADY_CHANGE,
    UNSTEADY_SCATTER,
};
use crate::diagnose::evidence::{Family, FamilyEvidence};
use crate::diagnose::result::Vote;
use crate::models::ModelKind;

/// A vote, its strength, why, and what a stiction vote rests on.
type Ballot = (Vote, f64, String, Option<StictionBasis>);

pub(super) fn vote(mut e: LoopEvidence, statistic: &str, threshold: String) -> FamilyEvidence {
    let (vote, strength, why, basis) = ballot(&e);
    e.stiction_basis = basis;
    FamilyEvidence {
        family: Family::Loop,
        vote,
        strength,
        contribution: None,
        value: Some(e.needed_lag_degrees),
        statistic: statistic.into(),
        threshold,
        note: format!("{why}; {}", facts(&e)),
        leans: None,
        model: None,
        stick_slip: None,
        valve: None,
        limit_cycle: Some(e),
        hidden_valve: None,
    }
}

/// Whether the valve's lag closes the balance: the describing function of a sticky valve gives
/// the lag the loop needs, the cycle is distorted (or too short to tell), OP explains the PV's
/// cycle and the identified loop is not unstable.
fn valve_lag_holds(e: &LoopEvidence) -> bool {
    let lag = e.needed_lag_degrees;
    (MIN_LAG..=MAX_LAG).contains(&lag)
        && describing_distance(e) <= MAX_DISTANCE
        && distorted(e)
        && e.residual_share <= MAX_RESIDUAL
        && e.margins.gain_margin.is_none_or(|g| g > MIN_MARGIN)
}

fn describing_distance(e: &LoopEvidence) -> f64 {
    e.describing.as_ref().map_or(f64::INFINITY, |d| d.distance)
}

/// A cycle too short in samples to show harmonics is not taken for a sinusoid.
fn distorted(e: &LoopEvidence) -> bool {
    e.harmonics
        .is_none_or(|h| h >= crate::diagnose::evidence::shape::SINUSOIDAL_HARMONICS)
}

fn ballot(e: &LoopEvidence) -> Ballot {
    if e.op_at_limit >= LIMIT_CYCLES {
        return (
            Vote::NoStiction,
            SATURATION_STRENGTH,
            "OP reaches a limit of its range in the cycle: saturation bounds it".into(),
            None,
        );
    }
    if e.controller_residual_share > MAX_CONTROLLER_RESIDUAL {
        return (
            Vote::Undetermined,
            0.0,
            format!(
                "the identified PI explains OP's cycle from the {} only to {:.0} %: a setpoint moving with an outer loop (a cascade) or a controller that is not a PI",
                if e.setpoint_recorded { "recorded error" } else { "PV (no setpoint recorded)" },
                100.0 * (1.0 - e.controller_residual_share).max(0.0)
            ),
            None,
        );
    }
    if valve_lag_holds(e) {
        return valve_lag_ballot(e);
    }
    if let Some(w) = self_sustained(e) {
        return self_sustained_ballot(e, w);
    }
    if e.linear_loop_sustains() {
        let (change, scatter) = e
            .amplitude
            .as_ref()
            .map_or((0.0, 0.0), |a| (a.change, a.scatter));
        let drifts = change.abs() >= UNSTEADY_CHANGE || scatter >= UNSTEADY_SCATTER;
        return (
            Vote::Undetermined,
            0.0,
            format!(
                "the identified linear loop sustains the cycle by itself (it is at its stability limit at this period{}): a marginal linear loop, \
                 an external input the fit absorbed, or a valve band small beside the cycle; the loop alone cannot tell them apart",
                if drifts { ", and the amplitude grows, decays or wanders as a linear loop's does" } else { "" }
            ),
            None,
        );
    }
    (Vote::Undetermined, 0.0, missing(e), None)
}

/// The valve's lag closes the balance: stiction, stronger the larger the lag.
fn valve_lag_ballot(e: &LoopEvidence) -> Ballot {
    let lag = e.needed_lag_degrees;
    let full = (0.6 + 0.4 * ((lag - MIN_LAG) / (FULL_LAG - MIN_LAG)).min(1.0)).min(1.0);
    let strength = if e.setpoint_recorded {
        full
    } else {
        NO_SETPOINT * full
    };
    let why = format!(
        "{}; a sticky valve's lag closes the balance{}",
        match e.margins.gain_margin {
            Some(g) if g <= 1.0 => format!(
                "the identified linear loop is at or just past its stability limit (gain margin {g:.2}) and cannot sustain this cycle without a lag in the valve"
            ),
            _ => "the identified linear loop is stable and cannot sustain this cycle".into(),
        },
        if e.setpoint_recorded { "" } else { " (weakened: without a setpoint a cascade's moving setpoint cannot be ruled out)" }
    );
    (Vote::Stiction, strength, why, Some(StictionBasis::ValveLag))
}

/// The phase wander of a cycle that sustains itself: amplitude steady, phase free, OP explaining
/// the PV's cycle (the caller has ruled out saturation and an unexplained OP).
fn self_sustained(e: &LoopEvidence) -> Option<f64> {
    let a = e.amplitude.as_ref()?;
    let w = e.phase_wander?;
    let steady = if a.cycles >= STEADY_CYCLES {
        STEADY_SCATTER_LONG
    } else {
        STEADY_SCATTER
    };
    (a.scatter < steady
        && a.change.abs() < UNSTEADY_CHANGE
        && w > FREE_RUNNING
        && e.residual_share <= MAX_RESIDUAL)
        .then_some(w)
}

/// A cycle that sustains itself: stiction with a setpoint recorded; without one, said but not voted
/// (the error is then PV's deviation, and a cascade's setpoint moving with an outer loop that
/// itself limit-cycles gives the same cycle).
fn self_sustained_ballot(e: &LoopEvidence, wander: f64) -> Ballot {
    let scatter = e.amplitude.as_ref().map_or(0.0, |a| a.scatter);
    let why = format!(
        "the cycle sustains itself: its amplitude holds (scatter {:.0} % from cycle to cycle) while its phase runs free (wander {wander:.1}, \
         over {FREE_RUNNING}); a linear loop at its stability limit would let the noise that drives it swell and shrink it, an input of \
         fixed period would hold its phase",
        100.0 * scatter
    );
    if e.setpoint_recorded {
        (
            Vote::Stiction,
            SELF_SUSTAINED,
            format!("{why}, so a non-linearity keeps it, and with OP off its limits that is the valve (a sticky valve, or a dead band)"),
            Some(StictionBasis::SelfSustained),
        )
    } else {
        (
            Vote::Undetermined,
            0.0,
            format!("{why}; but without a setpoint a cascade's setpoint moving with an outer loop's cycle looks the same, so this is no vote"),
            None,
        )
    }
}

/// What a stiction vote would have needed and did not find.
fn missing(e: &LoopEvidence) -> String {
    let lag = e.needed_lag_degrees;
    let dist = describing_distance(e);
    let mut missing = Vec::new();
    if !((MIN_LAG..=MAX_LAG).contains(&lag) && dist <= MAX_DISTANCE) {
        missing.push(format!(
            "no sticky valve gives the needed describing function (lag {lag:.0}°, {dist:.2} away)"
        ));
    }
    if !distorted(e) {
        missing.push("the cycle is sinusoidal where a valve's lag would distort it".into());
    }
    if e.residual_share > MAX_RESIDUAL {
        missing.push(format!(
            "{:.0} % of the PV's cycle is not explained by OP",
            100.0 * e.residual_share
        ));
    }
    if e.margins.gain_margin.is_some_and(|g| g <= MIN_MARGIN) {
        missing.push(format!(
            "the identified linear loop is unstable (gain margin under {MIN_MARGIN})"
        ));
    }
    missing.join("; ")
}

/// What the family measured, in words (the note's second half).
fn facts(e: &LoopEvidence) -> String {
    let harmonics_text = match e.harmonics {
        Some(h) if e.harmonic_count < 5 => format!("harmonics {h:.3} (2 to {})", e.harmonic_count),
        Some(h) => format!("harmonics {h:.3}"),
        None => format!(
            "harmonics not measured (a cycle of {:.1} samples puts the 3rd above the Nyquist frequency)",
            e.samples_per_cycle
        ),
    };
    let amplitude_text = e.amplitude.as_ref().map_or_else(
        || "amplitude from cycle to cycle not measured".to_string(),
        |a| {
            format!(
                "amplitude {:+.0} % over {} cycles, scatter {:.0} %{}",
                100.0 * a.change,
                a.cycles,
                100.0 * a.scatter,
                e.phase_wander
                    .map_or(String::new(), |w| format!(", phase wander {w:.1}"))
            )
        },
    );
    format!(
        "cycle of {:.0} s, OP amplitude {:.2}; the loop needs a valve gain {:.2} and lag {:.0}°{}; {harmonics_text}; \
         {:.0} % of the PV's cycle unexplained by OP; {}; gain margin {}; PI Kc {:.3}, Ti {} for a controller much faster than the samples, Kc {:.3}, Ti {} for one that runs once a sample (R² {:.2})",
        e.period,
        e.op_amplitude,
        e.needed_gain,
        e.needed_lag_degrees,
        e.describing.as_ref().map_or(String::new(), |d| format!(
            " ({} {:.2} % of span, {:.2} away)",
            match d.model {
                ModelKind::Stenman => "Stenman band".to_string(),
                _ => format!("Kano S with J/S {:.2},", d.slip_ratio),
            },
            d.band_percent_of_span,
            d.distance
        )),
        100.0 * e.residual_share,
        amplitude_text,
        e.margins.gain_margin.map_or("none (no crossing)".into(), |g| format!("{g:.2}")),
        e.controller.kc_continuous,
        seconds(e.controller.ti_continuous),
        e.controller.kc,
        seconds(e.controller.ti),
        e.controller.r2
    )
}

/// An integral time in words: seconds (a tenth under 10 s), or "-" when the fit gives none.
fn seconds(t: Option<f64>) -> String {
    match t {
        Some(t) if t.abs() < 10.0 => format!("{t:.1} s"),
        Some(t) => format!("{t:.0} s"),
        None => "-".into(),
    }
}
