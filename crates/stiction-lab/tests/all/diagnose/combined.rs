//! The families' statistics read together (`diagnose::combined`): on catalogue loops of the
//! benchmark set (other seeds than the loops the trees were trained on).

use super::judge_catalogue;
use stiction_core::diagnose::Verdict;

/// A sticky valve the rules call `no_stiction` (the closed-loop fit's test ratio between its
/// thresholds, no family sure) is called `stiction` by the statistics together, with the
/// probability as its confidence, the statistics named, and a band sized as for any stiction
/// verdict.
#[test]
fn a_sticky_valve_the_rules_miss_is_found_by_the_statistics_together() {
    let d = judge_catalogue("routine-b-0033");
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
    let c = d.combined.as_ref().unwrap();
    assert!(c.decided && c.probability >= c.threshold, "{c:?}");
    assert_eq!(d.confidence, Some(c.probability));
    let reason = d.reason.as_deref().unwrap();
    assert!(reason.contains("read together"), "{reason}");
    assert!(
        reason.ends_with("the rules alone said no_stiction"),
        "{reason}"
    );
    assert!(d.band.is_some());
    assert!(d
        .evidence
        .iter()
        .any(|e| e.starts_with("statistics combined: stiction")));
}

/// A healthy valve: the trees' probability is low, they cast no vote and the rules' verdict
/// stands; the statistics are reported all the same.
#[test]
fn a_healthy_valve_keeps_the_rules_verdict() {
    let d = judge_catalogue("routine-b-0296");
    assert_eq!(d.verdict, Verdict::NoStiction, "{:?}", d.evidence);
    let c = d.combined.as_ref().unwrap();
    assert!(!c.decided && c.probability < 0.2, "{c:?}");
    assert_eq!(
        c.statistics.len(),
        stiction_core::diagnose::combined::features::COUNT
    );
    assert!(c.statistics.iter().all(|s| s.value.is_finite()));
}
