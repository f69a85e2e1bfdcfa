//! Ranking a fleet of loops: one typed summary row per loop, built from its [`Diagnosis`], and
//! the order in which a maintenance planner should look at them.
//!
//! Every front end (the CLI's `batch`, the Python package) ranks with these functions, so the
//! same diagnoses always give the same ranking. The order is total (severity, then verdict, then
//! loop id): it never depends on which loop finished first or on the number of threads.

use crate::diagnose::{BandSource, Diagnosis, Verdict, Vote};
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;

/// A loop's outcome in the fleet: its verdict, or `failed` when it could not be read or
/// diagnosed. The order of the variants is the ranking order at equal severity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The diagnosis found stiction.
    Stiction,
    /// Diagnosed, but the evidence did not decide.
    Undetermined,
    /// The diagnosis found no stiction.
    NoStiction,
    /// The record was too short or too poor to judge.
    InsufficientData,
    /// The loop could not be read or diagnosed.
    Failed,
}

impl Outcome {
    /// Every outcome, in ranking order.
    pub const ALL: [Outcome; 5] = [
        Outcome::Stiction,
        Outcome::Undetermined,
        Outcome::NoStiction,
        Outcome::InsufficientData,
        Outcome::Failed,
    ];

    /// The name used in files (`no_stiction`), as serde writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Stiction => "stiction",
            Outcome::Undetermined => "undetermined",
            Outcome::NoStiction => "no_stiction",
            Outcome::InsufficientData => "insufficient_data",
            Outcome::Failed => "failed",
        }
    }
}

impl From<Verdict> for Outcome {
    fn from(v: Verdict) -> Self {
        match v {
            Verdict::Stiction => Outcome::Stiction,
            Verdict::Undetermined => Outcome::Undetermined,
            Verdict::NoStiction => Outcome::NoStiction,
            Verdict::InsufficientData => Outcome::InsufficientData,
        }
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One loop of the fleet summary (the columns of `stiction batch`'s summary.csv, in order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// The loop's identifier (the ranking's last key).
    pub loop_id: String,
    /// Where the loop came from, in words (a path, or a path and line range).
    pub source: String,
    /// Its outcome.
    pub verdict: Outcome,
    /// The probability of a sticky valve; `None` for a failed loop or one not judged.
    pub probability: Option<f64>,
    /// See [`severity`].
    pub severity: f64,
    /// The stiction band of a `stiction` verdict, % of valve span, and where it comes from.
    pub band_percent_of_span: Option<f64>,
    /// Where the band comes from.
    pub band_source: Option<BandSource>,
    /// The width of the ellipse fitted to an oscillation's PV-OP plot, % of valve span.
    pub ellipse_percent_of_span: Option<f64>,
    /// A small band for this record, % of valve span (4 of OP's noise standard deviations: a
    /// sticky valve with a band under it was found in 12-41 % of simulated records; see
    /// [`crate::diagnose::Reach`]): what a `no_stiction` row is nearly silent on.
    #[serde(default)]
    pub small_band_percent_of_span: Option<f64>,
    /// Oscillation period, seconds.
    pub period_s: Option<f64>,
    /// Thornhill's regularity of the oscillation; `None` when there is no oscillation analysis.
    pub regularity: Option<f64>,
    /// Why the verdict is what it is: the diagnosis' reasons in words (their `text`, which the
    /// front end fills before building the row) joined by "; ", else the families' votes; for a
    /// failed loop the error.
    pub reason: String,
    /// Samples in the record; `None` for a failed loop.
    pub samples: Option<u64>,
    /// Time the diagnosis took, seconds.
    pub seconds: Option<f64>,
    /// Why the loop could not be read or diagnosed (or, on a diagnosed loop, what went wrong
    /// beside the diagnosis); empty otherwise.
    pub error: String,
}

/// The severity of a loop, the ranking key: the stiction band in % of valve span times the
/// probability of a sticky valve for a `stiction` verdict, else 0 (never raw OP units: loops whose OP is scaled
/// differently rank alike).
///
/// The one place severity is defined: every ranking goes through here.
pub fn severity(d: &Diagnosis) -> f64 {
    if d.verdict != Verdict::Stiction {
        return 0.0;
    }
    let band = d.band.as_ref().map_or(0.0, |b| b.band_percent_of_span);
    band * d.probability.unwrap_or(0.0)
}

fn vote_name(v: Vote) -> &'static str {
    match v {
        Vote::Stiction => "stiction",
        Vote::NoStiction => "no_stiction",
        Vote::Undetermined => "undetermined",
    }
}

/// "votes: model stiction (0.310), stick_slip stiction (12), ...": why a verdict reached by the
/// families is what it is. Empty without families.
pub fn votes(d: &Diagnosis) -> String {
    let parts: Vec<String> = d
        .families
        .iter()
        .filter(|f| f.vote != Vote::Undetermined)
        .map(|f| {
            let name = f.family.as_str();
            match f.value {
                Some(v) if v.is_finite() => format!("{name} {} ({v:.3})", vote_name(f.vote)),
                _ => format!("{name} {}", vote_name(f.vote)),
            }
        })
        .collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!("votes: {}", parts.join(", "))
    }
}

impl Row {
    /// The row of a diagnosed loop.
    pub fn from_diagnosis(loop_id: &str, source: &str, d: &Diagnosis) -> Row {
        Row {
            loop_id: loop_id.into(),
            source: source.into(),
            verdict: d.verdict.into(),
            probability: d.probability,
            severity: severity(d),
            band_percent_of_span: d.band.as_ref().map(|b| b.band_percent_of_span),
            band_source: d.band.as_ref().map(|b| b.source),
            ellipse_percent_of_span: d.band.as_ref().and_then(|b| b.ellipse_percent_of_span),
            small_band_percent_of_span: d.reach.as_ref().map(|r| r.small_band_percent_of_span),
            period_s: d.oscillation.as_ref().and_then(|o| o.period),
            regularity: d.oscillation.as_ref().map(|o| o.regularity.regularity),
            reason: {
                let words: Vec<&str> = d
                    .reasons
                    .iter()
                    .map(|r| r.text.as_str())
                    .filter(|t| !t.is_empty())
                    .collect();
                if words.is_empty() {
                    votes(d)
                } else {
                    words.join("; ")
                }
            },
            samples: Some(d.samples as u64),
            seconds: Some(d.seconds),
            error: String::new(),
        }
    }

    /// The row of a loop that could not be read or diagnosed: last in the ranking, the error
    /// also as its reason.
    pub fn failed(loop_id: &str, source: &str, error: String) -> Row {
        Row {
            loop_id: loop_id.into(),
            source: source.into(),
            verdict: Outcome::Failed,
            probability: None,
            severity: 0.0,
            band_percent_of_span: None,
            band_source: None,
            ellipse_percent_of_span: None,
            small_band_percent_of_span: None,
            period_s: None,
            regularity: None,
            reason: error.clone(),
            samples: None,
            seconds: None,
            error,
        }
    }
}

/// Severity descending, then verdict (stiction, undetermined, no_stiction, insufficient_data,
/// failed), then loop id: a total order (`f64::total_cmp`), so a ranking never depends on the
/// order the rows arrived in.
pub fn ranking(a: &Row, b: &Row) -> Ordering {
    b.severity
        .total_cmp(&a.severity)
        .then(a.verdict.cmp(&b.verdict))
        .then_with(|| a.loop_id.cmp(&b.loop_id))
}

/// Sort rows into the fleet ranking (see [`ranking`]).
pub fn rank(rows: &mut [Row]) {
    rows.sort_by(ranking);
}

/// Two loops oscillate at one period when their periods lie within this share of each other: a
/// cycle carried from loop to loop (another loop's sticky valve, through the process or a
/// cascade's setpoint) keeps its period, but its estimate in a loop it reaches scatters (the
/// lab's `propagated_oscillation` study: 54 % of the regular ones within 5 % of the source's period,
/// 73 % within 10 %).
const SAME_PERIOD: f64 = 0.10;
/// A loop's cycle counts from this regularity (Thornhill's: over 1, a regular oscillation).
const REGULAR: f64 = 1.0;

/// For each row, how many other rows oscillate at its period (`SAME_PERIOD`; both regular,
/// `REGULAR`); 0 for a row that does not oscillate. Where several loops of one unit share a period,
/// one of them may drive the others: a stiction verdict on a loop that shares its period is read
/// with that in mind (stiction-lab/results/propagated-oscillation.md). Loops from different units
/// or time windows can share a period by chance.
pub fn same_period<'a>(rows: impl IntoIterator<Item = &'a Row>) -> Vec<usize> {
    let periods: Vec<Option<f64>> = rows
        .into_iter()
        .map(|r| {
            r.period_s
                .filter(|p| p.is_finite() && *p > 0.0)
                .filter(|_| r.regularity.is_some_and(|g| g >= REGULAR))
        })
        .collect();
    let mut sorted: Vec<f64> = periods.iter().flatten().copied().collect();
    sorted.sort_by(f64::total_cmp);
    periods
        .iter()
        .map(|p| match p {
            Some(p) => {
                let lo = sorted.partition_point(|&q| q < p / (1.0 + SAME_PERIOD));
                let hi = sorted.partition_point(|&q| q <= p * (1.0 + SAME_PERIOD));
                hi - lo - 1
            }
            None => 0,
        })
        .collect()
}

/// Number of loops per outcome.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Counts {
    /// Loops with a `stiction` verdict.
    pub stiction: usize,
    /// Loops with an `undetermined` verdict.
    pub undetermined: usize,
    /// Loops with a `no_stiction` verdict.
    pub no_stiction: usize,
    /// Loops with an `insufficient_data` verdict.
    pub insufficient_data: usize,
    /// Loops that could not be read or diagnosed.
    pub failed: usize,
}

impl Counts {
    /// Count the outcomes.
    pub fn of(outcomes: impl IntoIterator<Item = Outcome>) -> Counts {
        let mut c = Counts::default();
        for o in outcomes {
            *c.get_mut(o) += 1;
        }
        c
    }

    fn get_mut(&mut self, o: Outcome) -> &mut usize {
        match o {
            Outcome::Stiction => &mut self.stiction,
            Outcome::Undetermined => &mut self.undetermined,
            Outcome::NoStiction => &mut self.no_stiction,
            Outcome::InsufficientData => &mut self.insufficient_data,
            Outcome::Failed => &mut self.failed,
        }
    }

    /// The number of loops with outcome `o`.
    pub fn get(&self, o: Outcome) -> usize {
        match o {
            Outcome::Stiction => self.stiction,
            Outcome::Undetermined => self.undetermined,
            Outcome::NoStiction => self.no_stiction,
            Outcome::InsufficientData => self.insufficient_data,
            Outcome::Failed => self.failed,
        }
    }

    /// Loops in all.
    pub fn total(&self) -> usize {
        Outcome::ALL.iter().map(|&o| self.get(o)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Loops count each other at one period within 10 %, regular ones only; a loop that does not
    /// oscillate counts none and is counted by none.
    #[test]
    fn loops_at_one_period_count_each_other() {
        let at = |id: &str, period: Option<f64>, regularity: f64| Row {
            period_s: period,
            regularity: Some(regularity),
            ..Row::failed(id, "", String::new())
        };
        let rows = [
            at("a", Some(100.0), 3.0),
            at("b", Some(104.0), 2.0),
            at("c", Some(96.0), 5.0),
            at("d", Some(111.0), 3.0),
            at("e", Some(100.0), 0.5),
            at("f", None, 0.0),
        ];
        // a: b and c, not d (111 / 100 = 1.11); b: a, c and d (111 / 104 = 1.07); c: a and b
        // (111 / 96 = 1.16); d: b only; e is not regular, f does not oscillate
        assert_eq!(same_period(&rows), vec![2, 3, 2, 1, 0, 0]);
    }

    fn row(id: &str, verdict: Outcome, severity: f64) -> Row {
        Row {
            verdict,
            severity,
            ..Row::failed(id, "x.csv", String::new())
        }
    }

    #[test]
    fn severity_first_then_verdict_then_id() {
        let mut rows = vec![
            row("b", Outcome::Failed, 0.0),
            row("a", Outcome::NoStiction, 0.0),
            row("z", Outcome::Stiction, 0.5),
            row("c", Outcome::Stiction, 2.0),
            row("a2", Outcome::Stiction, 0.0),
            row("b", Outcome::Undetermined, 0.0),
        ];
        rank(&mut rows);
        let order: Vec<(&str, Outcome)> = rows
            .iter()
            .map(|r| (r.loop_id.as_str(), r.verdict))
            .collect();
        assert_eq!(
            order,
            [
                ("c", Outcome::Stiction),
                ("z", Outcome::Stiction),
                ("a2", Outcome::Stiction),
                ("b", Outcome::Undetermined),
                ("a", Outcome::NoStiction),
                ("b", Outcome::Failed),
            ]
        );
    }

    #[test]
    fn outcome_names_are_serde_names() {
        for o in Outcome::ALL {
            assert_eq!(serde_json::to_string(&o).unwrap(), format!("\"{o}\""));
        }
        let c = Counts::of([Outcome::Failed, Outcome::Stiction, Outcome::Failed]);
        assert_eq!((c.failed, c.stiction, c.total()), (2, 1, 3));
    }

    fn outcome() -> impl Strategy<Value = Outcome> {
        (0usize..5).prop_map(|k| Outcome::ALL[k])
    }

    proptest! {
        /// The ranking of a set of rows does not depend on the order they arrived in.
        #[test]
        fn ranking_is_independent_of_arrival_order(
            rows in prop::collection::vec(("[a-d]{1,2}", outcome(), prop_oneof![Just(0.0), 0.0..3.0f64]), 0..20),
            seed in any::<u64>(),
        ) {
            let rows: Vec<Row> = rows.iter().map(|(id, o, s)| row(id, *o, *s)).collect();
            let mut a = rows.clone();
            rank(&mut a);
            // a deterministic shuffle of the same rows
            let mut b = rows;
            let mut state = seed | 1;
            for i in (1..b.len()).rev() {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                b.swap(i, (state % (i as u64 + 1)) as usize);
            }
            rank(&mut b);
            prop_assert_eq!(&a, &b);
            // and it is sorted: severity never increases down the list
            for w in a.windows(2) {
                prop_assert!(w[0].severity >= w[1].severity);
                prop_assert!(ranking(&w[0], &w[1]) != Ordering::Greater);
            }
        }
    }
}
