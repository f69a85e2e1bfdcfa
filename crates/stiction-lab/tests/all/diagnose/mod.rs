//! The diagnosis on catalogue loops: each case a loop id the studies found, judged as
//! `stiction diagnose loop.csv --sp sp` judges it. The helpers here are shared by the parts.

mod plant_windows;
mod record;
mod shape;

use stiction_core::diagnose::{diagnose, Diagnosis, Family, FamilyEvidence};

/// The catalogue loop `id` diagnosed as the CLI diagnoses its CSV.
pub(crate) fn judge_catalogue(id: &str) -> Diagnosis {
    let l = stiction_lab::catalogue::find(id).unwrap();
    let record = stiction_lab::catalogue_loop::record(&l);
    diagnose(&record, &stiction_lab::catalogue_loop::request(&l)).unwrap()
}

/// A family's evidence in a diagnosis.
fn family_of(d: &Diagnosis, family: Family) -> &FamilyEvidence {
    d.families
        .iter()
        .find(|f| f.family == family)
        .unwrap_or_else(|| panic!("no {family:?} family in the diagnosis"))
}
