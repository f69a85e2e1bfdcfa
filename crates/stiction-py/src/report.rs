//! `report`: one loop's HTML page, the page of `stiction report` from the same code (the
//! `stiction-report` crate): the record prepared and diagnosed as `diagnose` does, then rendered.
//! The GIL is released while it runs.

use crate::diagnose::{run, Settings};
use crate::{bad, slice, slice_bool};
use numpy::PyReadonlyArray1;
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::collections::HashMap;
use stiction_core::record::Signals;
use stiction_report::{ColumnNames, LoopData, PageOptions};

/// The columns' names for the page's header: keys op, pv (both needed), sp, mode, time.
fn column_names(names: &HashMap<String, String>, integrating: bool) -> Result<ColumnNames, String> {
    let get = |k: &str| names.get(k).cloned();
    match (get("op"), get("pv")) {
        (Some(op), Some(pv)) => Ok(ColumnNames {
            op,
            pv,
            sp: get("sp"),
            mode: get("mode"),
            time: get("time"),
            integrating,
        }),
        _ => Err("columns must name op and pv".into()),
    }
}

/// Prepare, diagnose and render one loop: the page, or one sentence (bad input) or an error of
/// the rendering (a bug).
fn page(
    signals: Signals<'_>,
    s: &Settings,
    loop_id: &str,
    names: Option<&ColumnNames>,
) -> Result<String, PyErr> {
    let (d, p) = run(signals, s).map_err(bad)?;
    let v = &p.signals;
    let data = LoopData {
        op: &v.op,
        pv: &v.pv,
        sp: v.sp.as_deref(),
        time: v.time.as_deref(),
        auto: v.auto.as_deref(),
        ts: p.ts,
    };
    let options = PageOptions {
        columns: names,
        back_link: None,
        reading: &p.notes,
    };
    stiction_report::loop_page(loop_id, &data, &d, &options).map_err(|e| {
        PyRuntimeError::new_err(format!(
            "the report cannot be rendered (a bug: please report it): {e:#}"
        ))
    })
}

/// Diagnose one loop and render its report (`stiction report`'s page) as HTML text.
/// `loop_id` names the loop in the title; `columns` (op, pv, sp, mode, time) the columns in the
/// header, when the signals came from named columns.
#[pyfunction]
#[pyo3(signature = (op, pv, sp=None, mv=None, auto=None, time=None, ts=None, integrating=None,
    window=None, quantify=true, op_range=(0.0, 100.0), estimate_start=false, thorough=false, time_name=None,
    loop_id="loop".to_string(), columns=None))]
#[allow(clippy::too_many_arguments)]
pub fn report(
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
    loop_id: String,
    columns: Option<HashMap<String, String>>,
) -> PyResult<String> {
    let tags: Vec<String> = columns
        .as_ref()
        .map(|c| {
            ["pv", "op"]
                .iter()
                .filter_map(|k| c.get(*k).cloned())
                .collect()
        })
        .unwrap_or_default();
    let settings = Settings {
        ts,
        integrating,
        tags,
        window,
        quantify,
        op_range: [op_range.0, op_range.1],
        estimate_start,
        thorough,
        time_name: time_name.unwrap_or_else(|| "time".into()),
    };
    let names = columns
        .map(|c| column_names(&c, integrating == Some(true)))
        .transpose()
        .map_err(bad)?;
    let signals = Signals {
        op: slice(&op),
        pv: slice(&pv),
        sp: sp.as_ref().map(slice),
        mv: mv.as_ref().map(slice),
        auto: auto.as_ref().map(slice_bool),
        time: time.as_ref().map(slice),
    };
    py.detach(|| page(signals, &settings, &loop_id, names.as_ref()))
}
