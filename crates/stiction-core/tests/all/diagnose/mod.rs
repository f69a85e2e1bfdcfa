//! The diagnosis: usable stretches, the families of evidence, the verdict, windows. The
//! helpers here are shared by the parts.

mod long;
mod record;
mod shape;

use stiction_core::diagnose::{diagnose, DiagnoseRequest, Family, LoopRecord, Verdict, Vote};
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

/// A healthy valve on FOPTD (K, tau, delay) under PI (Kc, Ti), with a sine of amplitude 1 and
/// period 150 s added to the PV.
fn disturbed((k, tau, delay): (f64, f64, f64), (kc, ti): (f64, f64), noise: f64) -> LoopData {
    run(0.0, |cl| {
        cl.process = Process::Foptd { k, tau, delay };
        cl.pi.kc = kc;
        cl.pi.ti = ti;
        cl.noise = noise;
        cl.disturbance = Some(Signal::Sine {
            amplitude: 1.0,
            period: 150.0,
            offset: 0.0,
        });
    })
}

fn quick() -> DiagnoseRequest {
    DiagnoseRequest {
        quantify: false,
        ..DiagnoseRequest::default()
    }
}

/// A sticky valve (Stenman d = 2) on a level: an integrating process, K = 0.05 /s, delay 5 s.
fn sticky_level(f: impl FnOnce(&mut ClosedLoop)) -> LoopData {
    run(2.0, |cl| {
        cl.process = Process::Integrating {
            k: 0.05,
            delay: 5.0,
        };
        f(cl);
    })
}

/// A family's evidence in a diagnosis.
fn family_of(
    d: &stiction_core::diagnose::Diagnosis,
    family: Family,
) -> &stiction_core::diagnose::evidence::FamilyEvidence {
    d.families
        .iter()
        .find(|f| f.family == family)
        .unwrap_or_else(|| panic!("no {family:?} family in the diagnosis"))
}

/// The model family's evidence in a diagnosis.
fn model_family(
    d: &stiction_core::diagnose::Diagnosis,
) -> &stiction_core::diagnose::evidence::FamilyEvidence {
    family_of(d, Family::Model)
}
