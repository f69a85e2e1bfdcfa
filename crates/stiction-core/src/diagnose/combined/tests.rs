use super::features::{COUNT, NAMES};
use super::forest;

#[test]
fn the_trees_read_the_statistics_the_families_report_in_order() {
    let f = forest().expect("trained trees are embedded");
    assert_eq!(f.features.len(), COUNT);
    for (name, (expected, ..)) in f.features.iter().zip(NAMES) {
        assert_eq!(name, expected);
    }
    assert!(
        (0.5..1.0).contains(&f.threshold),
        "threshold {}",
        f.threshold
    );
}

#[test]
fn the_trees_give_the_trainers_probabilities() {
    let f = forest().expect("trained trees are embedded");
    assert!(f.checks.len() >= 10);
    for c in &f.checks {
        let r = f.read(&c.x).expect("a full input");
        assert!(
            (r.probability - c.p).abs() < 1e-9,
            "{} against {}",
            r.probability,
            c.p
        );
    }
}

#[test]
fn the_contributions_add_up_to_the_log_odds() {
    let f = forest().expect("trained trees are embedded");
    let roots: f64 = f.trees.iter().map(|t| t[0].4).sum();
    for c in &f.checks {
        let r = f.read(&c.x).expect("a full input");
        let log_odds = f.baseline + roots + r.contributions.iter().sum::<f64>();
        let p = 1.0 / (1.0 + (-log_odds).exp());
        assert!((p - r.probability).abs() < 1e-9);
    }
}

#[test]
fn a_short_or_long_input_is_no_reading() {
    let f = forest().expect("trained trees are embedded");
    assert!(f.read(&[0.0; COUNT - 1]).is_none());
    assert!(f.read(&[0.0; COUNT + 1]).is_none());
}

fn evidence(probability: f64) -> super::CombinedEvidence {
    super::CombinedEvidence {
        probability,
        threshold: 0.8,
        decided: false,
        before: None,
        statistics: Vec::new(),
        calibration: String::new(),
    }
}

fn abstaining(
    family: crate::diagnose::evidence::Family,
) -> crate::diagnose::evidence::FamilyEvidence {
    crate::diagnose::evidence::FamilyEvidence::abstains(family, "", String::new(), String::new())
}

#[test]
fn the_trees_only_ever_add_a_stiction_verdict() {
    use crate::diagnose::evidence::Family;
    use crate::diagnose::result::{Verdict, Vote};
    let quiet = [abstaining(Family::Valve), abstaining(Family::Model)];
    let sure = evidence(0.99);
    assert!(sure.decides(Verdict::NoStiction, &quiet));
    assert!(sure.decides(Verdict::Undetermined, &quiet));
    // never a stiction verdict taken away (there is nothing to add), nor a record nobody could judge
    assert!(!sure.decides(Verdict::Stiction, &quiet));
    assert!(!sure.decides(Verdict::InsufficientData, &quiet));
    // under the threshold: no vote, whatever the rules said
    assert!(!evidence(0.79).decides(Verdict::NoStiction, &quiet));
    // a recorded valve position decides, not the trees
    let mut valve = abstaining(Family::Valve);
    valve.vote = Vote::NoStiction;
    assert!(!sure.decides(Verdict::NoStiction, &[valve]));
}

#[test]
fn the_reason_names_the_statistics_that_weighed_most() {
    let mut e = evidence(0.93);
    e.statistics = NAMES
        .iter()
        .enumerate()
        .map(|(i, &(name, ..))| super::Statistic {
            name: name.into(),
            value: if i == 0 { 12.0_f64.ln_1p() } else { 0.0 },
            contribution: match i {
                0 => 1.5,
                12 => 0.7,
                20 => -2.0,
                _ => 0.0,
            },
        })
        .collect();
    let why = e.reason(crate::diagnose::result::Verdict::NoStiction);
    assert!(why.contains("0.93"), "{why}");
    assert!(
        why.contains("the closed-loop fit's test ratio (12.0) and the stick-slip episodes (0)"),
        "{why}"
    );
    assert!(why.ends_with("the rules alone said no_stiction"), "{why}");
}

#[test]
fn the_shape_indices_are_read_by_name_and_missing_ones_say_so() {
    use super::features::{Scale, Stretch, NOT_COMPUTED};
    use crate::diagnose::result::{Index, Vote};
    let index = |name: &str, value: Option<f64>| Index {
        name: name.into(),
        reference: String::new(),
        value,
        threshold: String::new(),
        vote: Vote::Undetermined,
        weight: 1.0,
        only_votes: None,
        note: String::new(),
    };
    // out of order, one not computed, one unknown to the trees
    let indices = [
        index("harmonics", Some(0.4)),
        index("cross_correlation", Some(0.9)),
        index("curve_fitting", None),
        index("a_new_index", Some(5.0)),
    ];
    let error: Vec<f64> = (0..200).map(|i| (i as f64 * 0.7).sin() * 1e-3).collect();
    let oscillation = crate::diagnose::oscillation::of_record(&error, None, 1.0);
    let x = super::features::of(&Stretch {
        families: &[],
        oscillation: &oscillation,
        indices: &indices,
        op_noise: 0.1,
        ts: 1.0,
        samples: 100,
    });
    let at = |name: &str| x[NAMES.iter().position(|n| n.0 == name).expect(name)];
    assert_eq!(at("cross_correlation"), 0.9);
    assert_eq!(at("harmonics"), 0.4);
    assert_eq!(at("curve_fitting"), NOT_COMPUTED);
    assert_eq!(at("bicoherence"), NOT_COMPUTED);
    // a missing index reads "not computed" in the reason, a computed one its value
    let mut e = evidence(0.9);
    e.statistics = ["curve_fitting", "cross_correlation"]
        .iter()
        .map(|&name| super::Statistic {
            name: name.into(),
            value: at(name),
            contribution: 1.0,
        })
        .collect();
    let words = e.leading();
    assert!(
        words.contains("the curve-fitting index (not computed)")
            && words.contains("the cross-correlation index (0.900)"),
        "{words}"
    );
    assert!(NAMES.iter().filter(|n| n.2 == Scale::Index).count() == 6);
}

#[test]
fn where_the_rules_are_undetermined_the_trees_decide_from_their_lower_threshold() {
    use crate::diagnose::result::Verdict;
    let f = forest().expect("trained trees are embedded");
    let under = f
        .threshold_undetermined
        .expect("a threshold for undetermined verdicts");
    assert!((0.5..=f.threshold).contains(&under), "{under}");
    assert_eq!(f.threshold_for(Verdict::Undetermined), under);
    assert_eq!(f.threshold_for(Verdict::NoStiction), f.threshold);
    // a probability between the two turns an undetermined verdict, not a no_stiction one
    let between = (under + f.threshold) / 2.0;
    let quiet = [abstaining(crate::diagnose::evidence::Family::Valve)];
    let mut e = evidence(between);
    e.for_verdict(Verdict::Undetermined);
    assert_eq!(e.threshold, under);
    assert!(e.decides(Verdict::Undetermined, &quiet));
    e.for_verdict(Verdict::NoStiction);
    assert_eq!(e.threshold, f.threshold);
    assert!(!e.decides(Verdict::NoStiction, &quiet));
}
