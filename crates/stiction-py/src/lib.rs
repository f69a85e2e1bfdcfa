//! `stiction._stiction`: the native half of the Python package. Thin conversion only: numpy
//! arrays are read as the core's slices (without copies when contiguous), the core's result
//! structs go back as the same serde JSON the CLI prints (so `to_dict()` equals `--json` key
//! for key), a loop's HTML report is `stiction-report`'s page (as `stiction report` writes it),
//! and the core's errors become `StictionError` (a `ValueError`) with one sentence
//! naming the argument and the fix. The pandas side lives in `python/stiction/`.

mod diagnose;
mod fit;
mod many;
mod report;
mod sim;

use numpy::PyReadonlyArray1;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::borrow::Cow;

create_exception!(
    _stiction,
    StictionError,
    PyValueError,
    "Bad input to a stiction function: one sentence names the argument, the column or the row, and the fix."
);

/// A `StictionError` carrying `msg`.
pub(crate) fn bad(msg: impl Into<String>) -> PyErr {
    StictionError::new_err(msg.into())
}

/// A float array as a slice: borrowed when contiguous, else copied once.
pub(crate) fn slice<'a>(a: &'a PyReadonlyArray1<'_, f64>) -> Cow<'a, [f64]> {
    match a.as_slice() {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(a.as_array().iter().copied().collect()),
    }
}

/// A bool array as a slice: borrowed when contiguous, else copied once.
pub(crate) fn slice_bool<'a>(a: &'a PyReadonlyArray1<'_, bool>) -> Cow<'a, [bool]> {
    match a.as_slice() {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(a.as_array().iter().copied().collect()),
    }
}

/// A result struct as the JSON the CLI prints.
pub(crate) fn json<T: serde::Serialize>(v: &T) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| bad(format!("the result cannot be written as JSON: {e}")))
}

/// Controller mode cells (`auto`, `manual`, `1`, `0`, `cas`, ...) as automatic flags; `None`
/// cells (missing) are not automatic. Returns the flags and the index of the first cell that is
/// not a mode, if any (the caller names the column and the row).
#[pyfunction]
fn parse_modes(cells: Vec<Option<String>>) -> (Vec<bool>, Option<usize>) {
    let mut out = Vec::with_capacity(cells.len());
    for (k, c) in cells.iter().enumerate() {
        let Some(c) = c.as_deref() else {
            out.push(false);
            continue;
        };
        match stiction_core::record::mode_word(c) {
            Some(auto) => out.push(auto),
            None if stiction_core::record::is_missing(c) => out.push(false),
            None => return (out, Some(k)),
        }
    }
    (out, None)
}

/// Text cells as numbers, as the CLI reads a file's cells: missing cells (blank, NaN, #N/A,
/// historian states such as Bad Input; `None`) are NaN, a decimal comma reads as a point, and
/// digits grouped by thousands read with the convention the column shows.
/// Returns the values and the index of the first cell that is not a finite number, if any.
#[pyfunction]
fn parse_numbers(cells: Vec<Option<String>>) -> (Vec<f64>, Option<usize>) {
    use stiction_core::record::{is_missing, parse_number_grouped, Grouping};
    let grouping = Grouping::of(cells.iter().flatten().map(|c| c.trim()));
    let mut out = Vec::with_capacity(cells.len());
    for (k, c) in cells.iter().enumerate() {
        let v = match c.as_deref() {
            None => f64::NAN,
            Some(c) if is_missing(c) => f64::NAN,
            Some(c) => match parse_number_grouped(c.trim(), grouping).filter(|v| v.is_finite()) {
                Some(v) => v,
                None => return (out, Some(k)),
            },
        };
        out.push(v);
    }
    (out, None)
}

#[pymodule]
fn _stiction(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("StictionError", m.py().get_type::<StictionError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("TIME_NAMES", stiction_core::record::TIME_NAMES.to_vec())?;
    m.add_function(wrap_pyfunction!(parse_modes, m)?)?;
    m.add_function(wrap_pyfunction!(parse_numbers, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(many::diagnose_many, m)?)?;
    m.add_function(wrap_pyfunction!(report::report, m)?)?;
    m.add_function(wrap_pyfunction!(fit::quantify, m)?)?;
    m.add_function(wrap_pyfunction!(fit::estimate, m)?)?;
    m.add_function(wrap_pyfunction!(sim::simulate, m)?)?;
    sim::add_models(m)?;
    Ok(())
}
