//! The records the verdict's model is trained and judged on, each reduced to what the model
//! reads: its statistics, its truth, its group (a real loop's tag), where it comes from.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;
use stiction_core::diagnose::{diagnose, Diagnosis, Statistic, Verdict};
use stiction_lab::catalogue::{self, LoopClass, Set, Suite, Truth};
use stiction_lab::catalogue_loop;
use stiction_lab::real::{self, RealSource};

/// Where a sample comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Source {
    /// A real plant window (plant-dev).
    Plant,
    /// A real ISDB loop.
    Isdb,
    /// A catalogue loop of a suite.
    Routine,
    Fast,
    PlantSim,
}

impl Source {
    pub fn real(self) -> bool {
        matches!(self, Source::Plant | Source::Isdb)
    }

    pub fn name(self) -> &'static str {
        match self {
            Source::Plant => "plant windows (real)",
            Source::Isdb => "ISDB (real)",
            Source::Routine => "routine (simulated)",
            Source::Fast => "fast (simulated)",
            Source::PlantSim => "plant windows (simulated)",
        }
    }
}

/// One record as the model sees it.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Sample {
    pub id: String,
    /// Every record of one group is left out together (a real loop's tag; a simulated loop is its
    /// own group).
    pub group: String,
    pub source: Source,
    /// The catalogue class, or the real record's loop kind.
    pub class: String,
    pub sticky: bool,
    /// A simulated sticky valve's slip visibility (PV noise standard deviations).
    pub visibility: Option<f64>,
    /// The statistics, in `Statistic::ALL`'s order.
    pub measured: Vec<Option<f64>>,
    /// The verdict and probability of the embedded model.
    pub verdict: Verdict,
    pub probability: Option<f64>,
    /// Judged at all (a record `diagnose` finds too short or still is not).
    pub judged: bool,
}

fn sample(
    d: &Diagnosis,
    id: String,
    group: String,
    source: Source,
    class: String,
    sticky: bool,
) -> Sample {
    let measured = Statistic::ALL
        .iter()
        .map(|s| {
            d.statistics.as_ref().and_then(|r| {
                r.contributions
                    .iter()
                    .find(|c| c.statistic == *s)
                    .and_then(|c| c.value)
            })
        })
        .collect::<Vec<_>>();
    Sample {
        id,
        group,
        source,
        class,
        sticky,
        visibility: None,
        judged: measured.iter().any(Option::is_some),
        measured,
        verdict: d.verdict,
        probability: d.probability,
    }
}

/// The real records under `shared`, diagnosed; `None` when the data are absent.
pub fn real(shared: &Path) -> Option<Vec<Sample>> {
    let records = real::all(shared)?;
    Some(
        records
            .par_iter()
            .map(|r| {
                let d = diagnose(&r.record(), &r.request()).expect("a valid request");
                let source = match r.source {
                    RealSource::Plant => Source::Plant,
                    RealSource::Isdb => Source::Isdb,
                };
                sample(
                    &d,
                    r.name.clone(),
                    r.group.clone(),
                    source,
                    r.measurement.clone(),
                    r.sticky,
                )
            })
            .collect(),
    )
}

/// The catalogue's loops of `suite` and `set` (backlash valves left out: no goal asks for them),
/// diagnosed as `stiction diagnose loop.csv --sp sp` would.
pub fn simulated(suite: Suite, set: Set) -> Vec<Sample> {
    let source = match suite {
        Suite::Routine => Source::Routine,
        Suite::Fast => Source::Fast,
        Suite::Plant => Source::PlantSim,
    };
    (0..catalogue::size(suite))
        .into_par_iter()
        .filter_map(|i| {
            let l = catalogue::generate(suite, set, i)?;
            if l.truth == Truth::BacklashOnly || l.class == LoopClass::BacklashValve {
                return None;
            }
            let d = diagnose(&catalogue_loop::record(&l), &catalogue_loop::request(&l))
                .expect("a valid request");
            let mut s = sample(
                &d,
                l.id.clone(),
                l.id.clone(),
                source,
                l.class.name().to_string(),
                l.truth == Truth::Sticky,
            );
            s.visibility = l.visibility;
            Some(s)
        })
        .collect()
}
