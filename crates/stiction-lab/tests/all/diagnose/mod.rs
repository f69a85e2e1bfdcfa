//! The diagnosis on catalogue loops: each case a loop id the studies found, judged as
//! `stiction diagnose loop.csv --sp sp` judges it. The helpers here are shared by the parts.

mod combined;
mod limit_cycle;
mod model;
mod record;
mod shape;
mod thorough;

use stiction_core::diagnose::{
    diagnose, BandSource, DiagnoseRequest, Diagnosis, Family, FamilyEvidence, LoopRecord,
    Thresholds, Verdict, Vote,
};
use stiction_core::models::{Model, Stenman};
use stiction_core::quality::Gate;
use stiction_core::sim::{ClosedLoop, LoopData, Process, Signal};

fn run(d: f64, f: impl FnOnce(&mut ClosedLoop)) -> LoopData {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d }));
    cl.samples = 2000;
    cl.noise = 0.05;
    cl.seed = 11;
    f(&mut cl);
    cl.run().unwrap()
}

/// The loop's record as `stiction diagnose loop.csv --sp sp` reads it.
pub(crate) fn record(l: &LoopData) -> LoopRecord<'_> {
    LoopRecord {
        op: &l.op,
        pv: &l.pv,
        sp: Some(&l.sp),
        mv: None,
        time: Some(&l.t),
        auto: None,
    }
}

/// The thresholds `diagnose` applies.
fn thresholds() -> Thresholds {
    Thresholds::default()
}

fn quick() -> DiagnoseRequest {
    DiagnoseRequest {
        quantify: false,
        ..DiagnoseRequest::default()
    }
}

/// A family's evidence in a diagnosis.
fn family_of(d: &Diagnosis, family: Family) -> &FamilyEvidence {
    d.families
        .iter()
        .find(|f| f.family == family)
        .unwrap_or_else(|| panic!("no {family:?} family in the diagnosis"))
}

/// The model family's evidence in a diagnosis.
fn model_family(d: &Diagnosis) -> &FamilyEvidence {
    family_of(d, Family::Model)
}

pub(crate) fn judge_catalogue(id: &str) -> stiction_core::diagnose::Diagnosis {
    let l = stiction_lab::catalogue::find(id).unwrap();
    let req = DiagnoseRequest {
        ts: l.ts(),
        integrating: l.integrating,
        ..DiagnoseRequest::default()
    };
    diagnose(&record(&l.data), &req).unwrap()
}

/// The catalogue loop `id` judged as the CLI judges it, without and with `thorough`: not
/// `stiction` without, `stiction` with. Both diagnoses.
fn stiction_only_when_thorough(
    id: &str,
) -> (
    stiction_core::diagnose::Diagnosis,
    stiction_core::diagnose::Diagnosis,
) {
    let l = stiction_lab::catalogue::find(id).unwrap();
    let req = DiagnoseRequest {
        ts: l.ts(),
        integrating: l.integrating,
        ..DiagnoseRequest::default()
    };
    let plain = diagnose(&record(&l.data), &req).unwrap();
    assert_ne!(plain.verdict, Verdict::Stiction, "{:?}", plain.evidence);
    let thorough = DiagnoseRequest {
        thorough: true,
        ..req
    };
    let d = diagnose(&record(&l.data), &thorough).unwrap();
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
    (plain, d)
}

/// The catalogue loop `id`, called `stiction` with its band from `source`, within 1.5x of the
/// simulated `truth` (% of span) and the closed-loop estimate beside it, more than `by` times
/// smaller. Its diagnosis.
pub(crate) fn band_replaces_the_closed_loop_estimate(
    id: &str,
    source: BandSource,
    truth: f64,
    by: f64,
) -> stiction_core::diagnose::Diagnosis {
    let d = judge_catalogue(id);
    assert_eq!(d.verdict, Verdict::Stiction, "{:?}", d.evidence);
    let band = d.band.as_ref().unwrap();
    assert_eq!(band.source, source, "{band:?}");
    assert!(
        (truth / 1.5..truth * 1.5).contains(&band.band_percent_of_span),
        "{band:?}"
    );
    let closed = band
        .others
        .iter()
        .find(|(s, _)| *s == BandSource::ClosedLoop)
        .map(|(_, v)| *v)
        .unwrap();
    assert!(closed < band.band_percent_of_span / by, "{band:?}");
    d
}

/// The hidden-valve family's evidence of a thorough diagnosis.
fn hidden_valve_of(
    d: &stiction_core::diagnose::Diagnosis,
) -> &stiction_core::diagnose::evidence::FamilyEvidence {
    family_of(d, Family::HiddenValve)
}

/// The catalogue loop `id` judged, asserted not `stiction` and its closed-loop fit's vote
/// withdrawn (`undetermined`).
fn judged_with_the_fit_withdrawn(id: &str) -> stiction_core::diagnose::Diagnosis {
    let d = judge_catalogue(id);
    assert_ne!(d.verdict, Verdict::Stiction, "{id}: {:?}", d.evidence);
    let m = model_family(&d);
    assert_eq!(m.vote, Vote::Undetermined, "{id}: {}", m.note);
    d
}
