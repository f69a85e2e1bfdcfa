//! The closed-loop fit (the model family) and the band it sizes.

use super::*;

#[test]
fn pv_changes_the_fit_explains_are_not_taken_for_noise() {
    // routine-b-0286 of the plant benchmark: a healthy flow loop recorded every 10 s under a load
    // ramp; its PV's fast changes pass for measurement noise, but OP explains part of them, so
    // the noise is no more than what the best fit leaves and the fits are compared (before, the
    // record was "barely varying above its noise" and left `insufficient_data`)
    let d = judge_catalogue("routine-b-0286");
    assert_eq!(d.verdict, Verdict::NoStiction, "{:?}", d.evidence);
    let m = model_family(&d).model.as_ref().unwrap();
    let unexplained = m.sse_linear.min(m.sse_stiction) / m.sst;
    assert!(
        m.noise_share <= unexplained + 1e-12,
        "noise share {} over the best fit's unexplained share {unexplained}",
        m.noise_share
    );
}

#[test]
fn where_no_band_found_fits_better_the_note_says_so() {
    // routine-c-0046 of the plant catalogue (a sticky Stenman valve on a pressure loop at 1 s,
    // high noise): the band search settles at R² 0.51 where the linear loop reaches 0.71; a valve
    // with no band is a sticky valve too, so the note says no band found fits better instead of
    // reading as if the stiction model fitted worse
    let d = judge_catalogue("routine-c-0046");
    let m = model_family(&d);
    let e = m.model.as_ref().unwrap();
    assert!(!e.band_fits_better(), "{}", m.note);
    assert!(m.note.contains("no band found fits better"), "{}", m.note);
    assert!(e.improvement <= 0.0 && e.significance <= 0.0, "{e:?}");
    // a sticky valve whose band fits better keeps the plain words
    let d = judge_catalogue("routine-b-0000");
    let m = model_family(&d);
    assert!(m.model.as_ref().unwrap().band_fits_better());
    assert!(!m.note.contains("no band found"), "{}", m.note);
}

#[test]
fn a_lag_at_its_bound_is_also_compared_over_a_third_of_it() {
    // routine-c-0215 of the plant catalogue: a sticky He valve on a pressure loop at 1 s whose
    // slow, irregular cycle lengthened the lag to its bound (200 samples, a tenth of the record;
    // the process responds in about 35 s); over it no band fitted better than OP and the loop
    // was called `no_stiction`. Over a third of the bound a slip-jump valve explains PV's
    // changes clearly better
    let d = judge_catalogue("routine-c-0215");
    let m = model_family(&d);
    let e = m.model.as_ref().unwrap();
    assert_eq!(e.lag_bound, Some(200), "{}", m.note);
    assert_eq!(e.lag, 200 / thresholds().bound_lag_divisor);
    assert_eq!(m.vote, Vote::Stiction, "{}", m.note);
    assert!(m.note.contains("a third of the bound"), "{}", m.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
    // a lag inside its bound is the only comparison
    let d = judge_catalogue("routine-b-0000");
    let e = model_family(&d).model.clone().unwrap();
    assert!(e.lag < stiction_core::quantify::max_lag(d.samples) && e.lag_bound.is_none());
}

#[test]
fn a_limit_cycle_whose_fits_look_alike_is_compared_over_whole_periods() {
    // fast-c-0043 of the catalogue's calibration set: a flow loop recorded every 5 s, its Kano
    // valve (S = 0.76 %, J = 0.68 %) limit-cycling. Over a response time the fits with and
    // without stiction look alike; over whole periods the cycle cancels, and the valve explains
    // what is left far better than OP. (fast-c-0035, a loop of this kind too, is found over the
    // response time since its first samples no longer choose the band's cells alone.)
    let model = found_over_whole_periods("fast-c-0043");
    assert!(model.note.contains("whole period"), "{}", model.note);
    // healthy valves: a loop at its stability limit (fast-c-0151, 0.97 of the ultimate gain) and
    // an external sinusoid (fast-c-0126) reach the same comparison, and the valve explains nothing
    for id in ["fast-c-0151", "fast-c-0126"] {
        let d = judge_catalogue(id);
        let model = model_family(&d);
        let c = model.model.as_ref().unwrap().cycle_cancelled.clone();
        let c = c.unwrap_or_else(|| panic!("{id}: {}", model.note));
        assert!(c.significance < 10.0, "{id}: {c:?}");
        assert_ne!(model.vote, Vote::Stiction, "{id}: {}", model.note);
        assert_ne!(d.verdict, Verdict::Stiction, "{id}: {:?}", d.evidence);
    }
}

#[test]
fn a_limit_cycle_whose_fit_falls_short_of_a_vote_is_compared_over_whole_periods() {
    // routine-x1-0017 (the first further draw of the routine suite): a flow loop recorded every
    // second, its Stenman valve (d = 1.54 %) limit-cycling under high noise. Over a response
    // time the band gains more than most healthy loops give, too little to decide; over whole
    // periods the cycle cancels and the valve explains what is left.
    let model = found_over_whole_periods("routine-x1-0017");
    let m = model.model.as_ref().unwrap();
    assert!(
        m.significance > thresholds().significance_none
            && m.significance < thresholds().significance_stiction,
        "{}",
        model.note
    );
}

#[test]
fn the_comparison_over_whole_periods_votes_at_the_first_comparisons_threshold() {
    // routine-c-0030 of the calibration set: a temperature loop (second order, 34 s dead time)
    // whose Stenman valve (d = 2.66 %) limit-cycles; over whole periods the test ratio is 84,
    // beyond the healthy loops that reach this comparison (under 50 on the calibration draws),
    // short of the 100 it was first held to
    let model = found_over_whole_periods("routine-c-0030");
    let c = model
        .model
        .as_ref()
        .unwrap()
        .cycle_cancelled
        .clone()
        .unwrap();
    assert!(
        c.significance < 2.0 * thresholds().significance_stiction,
        "{c:?}"
    );
    assert_eq!(
        thresholds().cycle_cancelled_stiction,
        thresholds().significance_stiction
    );
}

#[test]
fn an_oscillation_whose_period_wanders_is_compared_over_whole_periods_too() {
    // fast-x1-0010 (the first further draw of the fast suite): a pressure loop whose Stenman
    // valve (d = 1.43 %) cycles with a wandering period (regularity under 5: no limit cycle).
    // Over a response time the band gains nothing; over whole periods it explains what is left.
    let d = judge_catalogue("fast-x1-0010");
    let o = d.oscillation.as_ref().unwrap();
    assert!(o.oscillating && o.regularity.regularity < 5.0, "{o:?}");
    let model = found_over_whole_periods("fast-x1-0010");
    let m = model.model.as_ref().unwrap();
    assert!(
        m.significance <= thresholds().significance_none,
        "{}",
        model.note
    );
}

/// The model family's evidence on a catalogue loop it finds sticky by comparing the fits over
/// whole periods of the cycle, and the verdict `stiction`.
fn found_over_whole_periods(id: &str) -> stiction_core::diagnose::evidence::FamilyEvidence {
    let d = judge_catalogue(id);
    let model = model_family(&d).clone();
    let c = model.model.as_ref().and_then(|m| m.cycle_cancelled.clone());
    let c = c.unwrap_or_else(|| panic!("{id}: {}", model.note));
    assert!(
        c.significance >= thresholds().cycle_cancelled_stiction,
        "{id}: {c:?}"
    );
    assert_eq!(model.vote, Vote::Stiction, "{id}: {}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{id}: {:?}", d.evidence);
    model
}

#[test]
fn the_stiction_fit_is_also_polished_from_the_linear_loops_dynamics() {
    // fast-c-0024 of the catalogue's calibration set: a flow loop at 0.90 of its ultimate gain
    // with a Stenman valve (d = 0.88 %), not cycling. The stiction fit's own output-error search
    // stopped short of the linear loop's (R² 0.416 against 0.430); started from the linear loop's
    // dynamics it reaches 0.449, and the band's gain is beyond what healthy loops give
    let d = judge_catalogue("fast-c-0024");
    let model = model_family(&d);
    let m = model.model.as_ref().unwrap();
    assert!(
        m.r2_stenman.max(m.r2_slip_jump) >= m.r2_without_stiction,
        "{}",
        model.note
    );
    assert_eq!(model.vote, Vote::Stiction, "{}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}

#[test]
fn where_the_stenman_fit_settles_near_op_the_slip_jump_band_is_reported() {
    // routine-c-0153 of the catalogue's calibration set: a flow loop recorded every second under
    // a slow load drift, its Kano valve S = 2.99 %, J = 0.87 %. The closed-loop estimate (Stenman,
    // exact) settles on a band near OP; the closed-loop fit's slip-jump valve finds S near the
    // truth and is reported, the Stenman band beside it.
    band_replaces_the_closed_loop_estimate("routine-c-0153", BandSource::SlipJumpFit, 2.99, 1.2);
}

#[test]
fn the_valves_changes_stop_short_of_the_sample_where_pvs_change_starts() {
    // routine-c-0033 of the catalogue's calibration set: a pressure loop under tight PI (Kc 5.1)
    // with a Stenman valve, d = 1.07 %, recorded every second under a slow load drift. Fitted on
    // changes over a lag of 25 samples, a delay of 25 let OP's change end at the sample where PV's
    // begins, where the controller has just put PV's noise into OP: that structure won, and the
    // fits with and without stiction both explained 27 %. With the delay kept short of the lag,
    // the process is found, and with it the band.
    let d = judge_catalogue("routine-c-0033");
    let model = model_family(&d);
    let m = model.model.as_ref().unwrap();
    assert!(
        m.structure.nk + m.structure.nb - 1 < m.lag,
        "{:?}, lag {}",
        m.structure,
        m.lag
    );
    assert!(m.r2_stenman > m.r2_without_stiction + 0.2, "{}", model.note);
    assert!((m.stenman_d - 1.07).abs() < 0.1, "{}", model.note);
    assert_eq!(model.vote, Vote::Stiction, "{}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}

#[test]
fn a_band_under_the_ops_noise_is_none_the_fits_resolve_and_the_ellipse_stands_in() {
    // fast-c-0010 of the catalogue's calibration set: a flow loop with a Stenman valve, d = 1.64 %,
    // limit-cycling. The closed-loop estimate and the slip-jump fit find bands of 0.01 and 0.03 %,
    // under twice the OP's noise: no band they resolve. The ellipse of the cycle (1.55 %) is
    // reported, the fits' bands beside it.
    let d = band_replaces_the_closed_loop_estimate("fast-c-0010", BandSource::Ellipse, 1.64, 10.0);
    let band = d.band.as_ref().unwrap();
    assert!(
        band.others
            .iter()
            .any(|(s, v)| *s == BandSource::SlipJumpFit && *v < 0.1),
        "{band:?}"
    );
    assert!(
        d.warnings
            .iter()
            .any(|w| w.contains("the fits resolve no band")),
        "{:?}",
        d.warnings
    );
}

#[test]
fn a_band_that_only_fits_a_clock_regular_cycle_is_no_vote() {
    // routine-c-0465 of the catalogue's calibration set: a healthy pressure valve whose load
    // carries a sine (period about 200 s). A band fits the cycle better than a valve that follows
    // OP (test ratio 96), but the cycle keeps time like an input of fixed period (regularity
    // 125), and over whole periods, where it cancels, the band gains nothing: no vote.
    let d = judge_catalogue("routine-c-0465");
    let model = model_family(&d);
    let osc = d.oscillation.as_ref().unwrap();
    assert!(
        osc.regularity.regularity >= thresholds().forced_regularity,
        "{osc:?}"
    );
    let m = model.model.as_ref().unwrap();
    assert!(m.significance >= 50.0, "{}", model.note);
    assert!(
        m.cycle_cancelled.as_ref().unwrap().significance <= 15.0,
        "{}",
        model.note
    );
    assert_eq!(model.vote, Vote::Undetermined, "{}", model.note);
    assert_eq!(model.leans, Some(Vote::Stiction), "{}", model.note);
    assert!(
        model
            .note
            .contains("keeps time like an input of fixed period"),
        "{}",
        model.note
    );
    assert!(m.gain_in_a_clock_regular_cycle, "{}", model.note);
    assert_eq!(d.verdict, Verdict::Undetermined, "{:?}", d.evidence);
    assert!(
        d.next_step
            .starts_with("look for an input at the cycle's period"),
        "{}",
        d.next_step
    );
    // a sticky valve's cycle that regular, on which the band gains as much, is checked too and
    // keeps the vote: over whole periods the band still explains what is left (fast-c-0047: a
    // Kano valve, regularity 128, the band gaining 16 % of the PV's variation)
    let d = judge_catalogue("fast-c-0047");
    let model = model_family(&d);
    assert!(
        d.oscillation.as_ref().unwrap().regularity.regularity >= thresholds().forced_regularity
    );
    let c = model.model.as_ref().unwrap().cycle_cancelled.clone();
    assert!(c.is_some_and(|c| c.significance > 15.0), "{}", model.note);
    assert!(!model.model.as_ref().unwrap().gain_in_a_clock_regular_cycle);
    assert_eq!(model.vote, Vote::Stiction, "{}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}

#[test]
fn a_band_whose_steps_the_recorded_cycle_lacks_is_no_vote() {
    // loop L000662 of the batch benchmark's mix: a healthy valve on FOPTD (1, 30 s, 5 s) under PI
    // (1, 30 s), PV noise 0.3, a sine of amplitude 1 and period 178 s added to PV, the setpoint
    // constant. The fitted valve (a band about OP's whole swing) slips twice a period in step with
    // the sine and explains far more of PV than a valve that follows OP (test ratio in the
    // hundreds), but the PV it gives carries its steps' harmonics and the recorded PV, a sine in
    // noise, does not: no vote, and the loop is not called sticky.
    let l = run(0.0, |cl| {
        cl.process = Process::Foptd {
            k: 1.0,
            tau: 30.0,
            delay: 5.0,
        };
        cl.pi.kc = 1.0;
        cl.pi.ti = 30.0;
        cl.noise = 0.3;
        cl.seed = 90441349846404486;
        cl.disturbance = Some(Signal::Sine {
            amplitude: 1.0,
            period: 177.62339365848646,
            offset: 0.0,
        });
    });
    let d = diagnose(&record(&l), &quick()).unwrap();
    let model = model_family(&d);
    let m = model.model.as_ref().unwrap();
    assert!(
        m.significance >= thresholds().significance_stiction,
        "{}",
        model.note
    );
    let shape = m
        .cycle_shape
        .as_ref()
        .expect("the cycle's shape is checked");
    assert!(shape.foreign(), "{shape:?}");
    assert!(
        shape.fit_harmonics >= thresholds().foreign_shape * shape.pv_harmonics,
        "{shape:?}"
    );
    assert_eq!(model.vote, Vote::Undetermined, "{}", model.note);
    assert_eq!(model.leans, None, "{}", model.note);
    assert!(
        model.note.contains("a shape PV does not have"),
        "{}",
        model.note
    );
    assert_ne!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
    // a sticky valve's own limit cycle carries the harmonics its fit gives: the vote stands
    // (routine-c-0171, a Stenman valve cycling every 59 s: the fit's PV 0.031, the recorded 0.012,
    // the largest ratio of the calibration set's sticky valves)
    let d = judge_catalogue("routine-c-0171");
    let model = model_family(&d);
    let shape = model.model.as_ref().unwrap().cycle_shape.as_ref();
    assert!(
        shape.is_some_and(|s| !s.foreign()),
        "{shape:?}: {}",
        model.note
    );
    assert_eq!(model.vote, Vote::Stiction, "{}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}

#[test]
fn a_fit_that_mirrors_the_controller_casts_no_stiction_vote() {
    // routine-c-0490 of the plant catalogue (calibration set): a healthy pressure valve whose
    // load steps OP does not explain; the linear fit reads PV from OP through the controller's own
    // law (a process gain near zero), a band gained on it (test ratio 360) and the loop was called
    // sticky before the loop gain was checked
    let d = judged_with_the_fit_withdrawn("routine-c-0490");
    let m = model_family(&d);
    let g = m.model.as_ref().unwrap().loop_gain.unwrap();
    assert!(g < thresholds().min_loop_gain, "{g}");
    assert!(m.note.contains("loop gain"), "{}", m.note);
    assert!(m.model.as_ref().unwrap().fit_mirrors_controller);
    // routine-c-0507: the withdrawn vote was the only one; the verdict says so instead of calling
    // a loop that load steps move "not excited enough"
    let d = judge_catalogue("routine-c-0507");
    assert_eq!(d.verdict, Verdict::Undetermined, "{:?}", d.reason);
    let reason = d.reason.unwrap();
    assert!(reason.contains("controller's own law"), "{reason}");
    // a sticky valve's fit keeps its vote: the loop gain it implies is the loop's
    let sticky = run(2.0, |_| {});
    let d = diagnose(&record(&sticky), &DiagnoseRequest::default()).unwrap();
    let m = model_family(&d);
    assert!(
        m.model.as_ref().unwrap().loop_gain.unwrap() > 0.1,
        "{}",
        m.note
    );
}

#[test]
fn op_steps_the_error_did_not_provoke_cast_no_stiction_vote() {
    // routine-c-0514 of the plant catalogue (calibration set): a healthy flow valve whose
    // controller feeds a measured load's steps forward to OP; OP jumps while PV, the load
    // compensated, stays at its setpoint, and the closed-loop fit explains that by a valve that
    // sticks through the jumps (a level of the same class, routine-c-0518, was called `stiction`
    // so at a test ratio of 69 before its fits saw the valve's inflow)
    let d = judged_with_the_fit_withdrawn("routine-c-0514");
    let m = model_family(&d);
    let e = m.model.as_ref().unwrap();
    assert!(e.op_moved_elsewhere);
    let u = e.unprovoked_op_steps.unwrap();
    assert!(u.steps > 0 && u.withdraws(), "{u:?}");
    assert!(
        m.note.contains("control error stays inside its noise"),
        "{}",
        m.note
    );
    // with no other vote the verdict says why, and what to do
    assert_eq!(d.verdict, Verdict::Undetermined, "{:?}", d.reason);
    assert!(d
        .reason
        .as_deref()
        .unwrap()
        .contains("OP steps while the control error stays at rest"));
    assert!(d.next_step.contains("feed-forward"), "{}", d.next_step);
    // a sticky valve's OP is its controller's: no unprovoked step
    for id in ["routine-c-0000", "routine-c-0100", "routine-c-0200"] {
        let d = judge_catalogue(id);
        let e = model_family(&d).model.clone().unwrap();
        assert_eq!(e.unprovoked_op_steps.unwrap().steps, 0, "{id}");
        assert!(!e.op_moved_elsewhere, "{id}");
    }
}

#[test]
fn a_record_that_starts_at_rest_is_walked_whole() {
    // routine-c-0003 of the catalogue's calibration set: a flow loop whose Stenman valve (4.5 %)
    // holds for 620 s while a load ramp winds OP up, then slips and limit-cycles every 27 s. The
    // first 600 samples, where a staged walk keeps its cells, see 3 % of OP's travel: every band
    // keeps the valve still there, so the whole record is walked, and the valve is found.
    let d = judge_catalogue("routine-c-0003");
    let model = model_family(&d);
    assert_eq!(model.vote, Vote::Stiction, "{}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}

#[test]
fn a_levels_changes_are_fitted_to_the_valves_inflow() {
    // routine-c-0014 of the catalogue's calibration set: a level (integration rate 0.00424 per s)
    // whose Stenman valve (3.72 %) slips 154 times in 2,000 samples at 1 s, with setpoint steps
    // and high noise. Its changes over the lag against the valve's changes need an output lag at
    // the unit circle, whose least-squares fits simulate at random: the walk chose 4.9 % and the
    // stiction fit fell below the linear loop's (`no_stiction`). Against the valve's position
    // summed over the lag (the level's inflow), the walk finds the band and the rate.
    let d = judge_catalogue("routine-c-0014");
    let model = model_family(&d);
    let m = model.model.as_ref().expect("the fits' figures");
    assert_eq!(m.over_lag, stiction_core::quantify::OverLag::Sum);
    assert!(m.structure.integrating, "{:?}", m.structure);
    let rate = m.gain.expect("an integration rate");
    assert!((rate / 0.00424 - 1.0).abs() < 0.1, "rate {rate}");
    assert!(
        (m.stenman_d / 3.72 - 1.0).abs() < 0.1,
        "band {}",
        m.stenman_d
    );
    assert_eq!(model.vote, Vote::Stiction, "{}", model.note);
    assert!(model.note.contains("its inflow"), "{}", model.note);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
}
