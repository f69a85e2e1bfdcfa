//! The verdict on fixed votes.
use super::*;

fn family(family: Family, vote: Vote, leans: Option<Vote>) -> FamilyEvidence {
    let mut f = FamilyEvidence::abstains(family, "", String::new(), String::new());
    f.vote = vote;
    f.strength = if vote == Vote::Undetermined { 0.0 } else { 0.6 };
    f.leans = leans;
    f
}

fn calm() -> Motion {
    Motion::default()
}

#[test]
fn evidence_between_the_thresholds_is_undetermined_not_insufficient() {
    let families = [
        family(Family::Model, Vote::Undetermined, Some(Vote::Stiction)),
        family(Family::StickSlip, Vote::Undetermined, Some(Vote::Stiction)),
        family(Family::Shape, Vote::Undetermined, None),
    ];
    let d = decide(&families, &calm());
    assert_eq!(d.verdict, Verdict::Undetermined);
    let reason = d.reason.unwrap();
    assert!(
        reason.contains("towards stiction (closed-loop fit and stick-slip episodes)"),
        "{reason}"
    );
    assert!(d.confidence.is_none());
}

#[test]
fn nothing_measured_is_insufficient_data() {
    let families = [
        family(Family::Model, Vote::Undetermined, None),
        family(Family::StickSlip, Vote::Undetermined, None),
    ];
    let d = decide(&families, &calm());
    assert_eq!(d.verdict, Verdict::InsufficientData);
    assert!(d.reason.unwrap().contains("not excited enough"));
}

#[test]
fn a_vote_outranks_a_lean() {
    let families = [
        family(Family::Model, Vote::Undetermined, Some(Vote::Stiction)),
        family(Family::StickSlip, Vote::NoStiction, None),
    ];
    assert_eq!(decide(&families, &calm()).verdict, Verdict::NoStiction);
}

#[test]
fn weak_evidence_against_stiction_says_so_in_the_next_step() {
    let weak = |strength: f64| {
        let mut f = family(Family::StickSlip, Vote::NoStiction, None);
        f.strength = strength;
        f
    };
    let d = decide(&[weak(0.25)], &calm());
    assert_eq!(d.verdict, Verdict::NoStiction);
    assert!(d.next_step.contains("weak"), "{}", d.next_step);
    assert!(d.next_step.contains("valve travel test"), "{}", d.next_step);
    assert!(!d.next_step.contains("setpoint"), "{}", d.next_step);
    // a window whose setpoint holds: a window with setpoint changes would say more
    let steady = Motion {
        setpoint_steady: true,
        ..calm()
    };
    let d = decide(&[weak(0.25)], &steady);
    assert!(
        d.next_step.contains("a window that holds setpoint changes"),
        "{}",
        d.next_step
    );
    let d = decide(&[weak(0.9)], &steady);
    assert_eq!(d.next_step, "no action on the valve");
    let d = decide(&[weak(0.9)], &calm());
    assert_eq!(d.verdict, Verdict::NoStiction);
    assert_eq!(d.next_step, "no action on the valve");
    // a PV mostly not recorded: compression hides sticks, and the step says so
    let compressed = calm().with_pv_not_recorded(0.8, 0.5);
    let d = decide(&[weak(0.9)], &compressed);
    assert_eq!(d.verdict, Verdict::NoStiction);
    assert!(
        d.next_step
            .starts_with("no action on the valve; but PV is not recorded in 80 %"),
        "{}",
        d.next_step
    );
    assert!(
        d.next_step.contains("without compression"),
        "{}",
        d.next_step
    );
    // at or under the gate's limit it is the plain step
    let d = decide(&[weak(0.9)], &calm().with_pv_not_recorded(0.5, 0.5));
    assert_eq!(d.next_step, "no action on the valve");
}

#[test]
fn the_hidden_valve_outweighs_the_families_that_read_op_as_the_valve_input() {
    let mut against = vec![
        family(Family::Model, Vote::NoStiction, None),
        family(Family::StickSlip, Vote::NoStiction, None),
        family(Family::HiddenValve, Vote::Undetermined, None),
    ];
    assert_eq!(decide(&against, &calm()).verdict, Verdict::NoStiction);
    against[2].vote = Vote::Stiction;
    let d = decide(&against, &calm());
    assert_eq!(d.verdict, Verdict::Stiction);
    // every other voting family against: the lowest confidence it gives
    assert!(
        (d.confidence.unwrap() - 0.6).abs() < 1e-12,
        "{:?}",
        d.confidence
    );
    assert!(d.next_step.contains("valve travel test"), "{}", d.next_step);
    // the recorded valve position still decides over it
    let mut valve = family(Family::Valve, Vote::NoStiction, None);
    valve.strength = 0.9;
    against.push(valve);
    assert_eq!(decide(&against, &calm()).verdict, Verdict::NoStiction);
}

#[test]
fn a_stiction_verdict_on_the_cycle_alone_says_another_loop_can_give_it() {
    let shape = family(Family::Shape, Vote::Stiction, None);
    let cycle = family(Family::Loop, Vote::Stiction, None);
    for alone in [
        vec![shape.clone()],
        vec![cycle.clone()],
        vec![shape.clone(), cycle],
    ] {
        let d = decide(&alone, &calm());
        assert_eq!(d.verdict, Verdict::Stiction);
        assert!(
            d.next_step.contains("another loop's sticky valve"),
            "{}",
            d.next_step
        );
    }
    // with the closed-loop fit behind it, the caveat goes
    let fit = family(Family::Model, Vote::Stiction, None);
    let d = decide(&[shape, fit], &calm());
    assert_eq!(d.verdict, Verdict::Stiction);
    assert!(!d.next_step.contains("another loop"), "{}", d.next_step);
}
