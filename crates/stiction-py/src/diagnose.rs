//! `diagnose`: one loop, through the core's record preparation and diagnosis (as the CLI's
//! `diagnose`), the GIL released while it runs.

use crate::{bad, json, slice, slice_bool};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use stiction_core::diagnose::{self as core, DiagnoseError, DiagnoseRequest, Diagnosis};
use stiction_core::record::{self, PrepareError, Prepared, Signals};

/// What every diagnosis is asked besides the signals (the CLI's column flags).
#[derive(Clone, Debug)]
pub struct Settings {
    pub ts: Option<f64>,
    /// The loop's kind as the caller says (`None`: a tag in `tags` hints it, else the record's
    /// behaviour decides).
    pub integrating: Option<bool>,
    /// The names of PV's and OP's columns, read for an ISA-5.1 tag (the CLI reads its columns').
    pub tags: Vec<String>,
    pub window: Option<usize>,
    pub quantify: bool,
    pub op_range: [f64; 2],
    pub estimate_start: bool,
    /// The hidden-valve family (the CLI's `--thorough`).
    pub thorough: bool,
    /// The time column's name, for the sentence when time does not increase.
    pub time_name: String,
}

impl Settings {
    /// The core's request, as the CLI's `Columns::request` builds it.
    pub fn request(&self, ts: f64) -> DiagnoseRequest {
        let (integrating, integrating_tag) = match self.integrating {
            Some(i) => (Some(i), None),
            None => self
                .tags
                .iter()
                .find_map(|t| core::loop_kind::hinted_by_tag(t))
                .map_or((None, None), |(i, tag)| (Some(i), Some(tag))),
        };
        DiagnoseRequest {
            ts,
            integrating,
            integrating_tag,
            estimate_start: self.estimate_start,
            thorough: self.thorough,
            op_range: self.op_range,
            window: self.window,
            quantify: self.quantify,
            ..DiagnoseRequest::default()
        }
    }
}

/// The core's preparation error in one sentence naming the argument.
fn prepare_error(e: PrepareError, s: &Settings) -> String {
    match e {
        PrepareError::Ts(ts) => {
            format!("ts={ts}: the sampling time must be a positive number of seconds")
        }
        PrepareError::TimeNotIncreasing => format!(
            "the time column '{}' does not increase; give the sampling time with ts=SECONDS",
            s.time_name
        ),
        e => e.to_string(),
    }
}

/// The core's diagnosis error in one sentence naming the argument (the CLI's `core_error`, with
/// keyword arguments for flags).
fn diagnose_error(e: DiagnoseError) -> String {
    match e {
        DiagnoseError::Window { window, least } => format!(
            "window={window}: a window needs at least {least} samples; give a larger window"
        ),
        DiagnoseError::Ts(ts) => {
            format!("ts={ts}: the sampling time must be a positive number of seconds")
        }
        DiagnoseError::OpRange { lo, hi } => format!(
            "op_range=({lo}, {hi}): the value of a fully open valve must exceed that of a closed one"
        ),
        e => e.to_string(),
    }
}

/// Prepare and diagnose one loop: the diagnosis, its words filled by `stiction-report`'s
/// `words::fill` (as the CLI fills them), and the prepared record (its signals in time order,
/// sampling time and notes), or one sentence.
pub fn run<'a>(signals: Signals<'a>, s: &Settings) -> Result<(Diagnosis, Prepared<'a>), String> {
    let p = record::prepare(signals, s.ts).map_err(|e| prepare_error(e, s))?;
    let req = s.request(p.ts).check().map_err(diagnose_error)?;
    let mut d = core::diagnose_checked(&p.signals.record(), &req).map_err(diagnose_error)?;
    stiction_report::words::fill(&mut d);
    Ok((d, p))
}

/// Diagnose one loop: the `Diagnosis` as JSON (the CLI's `diagnose --json`) and the notes of
/// the record's preparation (rows sorted, repeated times dropped).
#[pyfunction]
#[pyo3(signature = (op, pv, sp=None, mv=None, auto=None, time=None, ts=None, integrating=None,
    window=None, quantify=true, op_range=(0.0, 100.0), estimate_start=false, thorough=false, time_name=None,
    tags=None))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose(
    py: Python<'_>,
    op: PyReadonlyArray1<'_, f64>,
    pv: PyReadonlyArray1<'_, f64>,
    sp: Option<PyReadonlyArray1<'_, f64>>,
    mv: Option<PyReadonlyArray1<'_, f64>>,
    auto: Option<PyReadonlyArray1<'_, bool>>,
    time: Option<PyReadonlyArray1<'_, f64>>,
    ts: Option<f64>,
    integrating: Option<bool>,
    window: Option<usize>,
    quantify: bool,
    op_range: (f64, f64),
    estimate_start: bool,
    thorough: bool,
    time_name: Option<String>,
    tags: Option<Vec<String>>,
) -> PyResult<(String, Vec<String>)> {
    let settings = Settings {
        ts,
        integrating,
        tags: tags.unwrap_or_default(),
        window,
        quantify,
        op_range: [op_range.0, op_range.1],
        estimate_start,
        thorough,
        time_name: time_name.unwrap_or_else(|| "time".into()),
    };
    let signals = Signals {
        op: slice(&op),
        pv: slice(&pv),
        sp: sp.as_ref().map(slice),
        mv: mv.as_ref().map(slice),
        auto: auto.as_ref().map(slice_bool),
        time: time.as_ref().map(slice),
    };
    let (d, p) = py.detach(|| run(signals, &settings)).map_err(bad)?;
    Ok((json(&d)?, p.notes))
}
