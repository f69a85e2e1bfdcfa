//! `quantify` (OP and PV, closed loop) and `estimate` (OP and MV, the paper's problem): the
//! core's fits on the longest stretch without gaps, as the CLI's `quantify` and `estimate`.

use crate::{bad, json, slice};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;
use std::collections::HashMap;
use stiction_core::estimate::{self as core_estimate, EstimateError, Method, Request};
use stiction_core::models::ModelKind;
use stiction_core::quantify::{self as core_quantify, QuantifyRequest};
use stiction_core::record::{self, longest_clean, PrepareError, Signals};

/// The core's error in one sentence naming the keyword argument, as the CLI names its flag: a
/// method's setting out of range (ACO_R's `q` is `locality=`), the sampling time, the exact
/// method for another model.
fn estimate_error(e: EstimateError) -> PyErr {
    match e {
        EstimateError::Ts(ts) => bad(format!(
            "ts={ts}: the sampling time must be a positive number of seconds"
        )),
        EstimateError::ExactNeedsStenman(kind) => bad(format!(
            "method='exact' solves the Stenman model only; for {kind} use aco-r, aco or grid"
        )),
        EstimateError::Setting {
            method,
            name,
            rule,
            value,
        } => {
            let key = method.setting_key(name);
            bad(format!("{key}={value}: {key} must be {rule}"))
        }
        e => bad(e.to_string()),
    }
}

/// The model and method, checked (exact is for Stenman only), as the CLI's `--model/--method`.
fn model_method(model: &str, method: Option<&str>) -> PyResult<(ModelKind, Method)> {
    let kind: ModelKind = model
        .parse()
        .map_err(|e| bad(format!("model='{model}': {e}")))?;
    let method = match method {
        Some(m) => m
            .parse::<Method>()
            .map_err(|e| bad(format!("method='{m}': {e}")))?,
        None => Method::default_for(kind),
    };
    // the core's rule (exact is for Stenman only), before the data are looked at
    Request::new(kind, method).check().map_err(estimate_error)?;
    Ok((kind, method))
}

/// Search ranges `{name: (lo, hi)}` over `defaults`, one per parameter of the model.
fn bounds(
    kind: ModelKind,
    given: HashMap<String, (f64, f64)>,
    mut ranges: Vec<(f64, f64)>,
) -> PyResult<Vec<(f64, f64)>> {
    let mut names: Vec<_> = given.into_iter().collect();
    names.sort_by(|a, b| a.0.cmp(&b.0));
    for (name, range) in names {
        let i = kind
            .param_index(&name)
            .map_err(|e| bad(format!("bounds: {e}")))?;
        ranges[i] = range;
    }
    Ok(ranges)
}

/// `a` and `b` over the longest stretch where neither has a gap once their short gaps are
/// bridged ([`record::short_gaps`]), with a note when they were bridged or it is not the whole
/// record, or the sentence why none is long enough (the CLI's `fit_stretch`, in samples).
type FitStretch = (Vec<f64>, Vec<f64>, Option<String>);
fn fit_stretch(
    (a_name, a): (&str, &[f64]),
    (b_name, b): (&str, &[f64]),
    least: usize,
) -> PyResult<FitStretch> {
    let n = a.len();
    let runs = record::short_gaps(&[a, b], &|_| true);
    let (a, b) = (record::bridged(a, &runs), record::bridged(b, &runs));
    let bridged = (!runs.is_empty()).then(|| record::bridged_note(&runs, ("sample", "samples")));
    let gaps = |v: &[f64]| v.iter().filter(|x| !x.is_finite()).count();
    let (ga, gb) = (gaps(&a), gaps(&b));
    if ga + gb == 0 {
        if n < least {
            return Err(bad(format!(
                "only {n} samples; at least {least} samples are needed"
            )));
        }
        return Ok((a, b, bridged));
    }
    let which = [(a_name, ga), (b_name, gb)]
        .iter()
        .filter(|(_, k)| *k > 0)
        .map(|(name, k)| format!("{name} {k}"))
        .collect::<Vec<_>>()
        .join(", ");
    let (s, e) = longest_clean(&[&a, &b]).unwrap_or((0, 0));
    if e - s < least {
        return Err(bad(format!(
            "no stretch of at least {least} samples without missing values ({} missing: {which}; the longest stretch without gaps has {} samples); fill the gaps or pass a longer stretch",
            ga + gb,
            e - s
        )));
    }
    let mut note = format!(
        "{} values missing ({which}); using samples {s} to {}, the longest stretch without gaps ({} of {n})",
        ga + gb,
        e - 1,
        e - s
    );
    if let Some(bridged) = bridged {
        note = format!("{bridged}; {note}");
    }
    Ok((a[s..e].to_vec(), b[s..e].to_vec(), Some(note)))
}

/// Quantify stiction from OP and PV alone: the `Quantification` as JSON (the CLI's `quantify
/// --json`) and notes.
#[pyfunction]
#[pyo3(signature = (op, pv, time=None, ts=None, model="stenman", method=None, seed=1,
    max_delay=30, integrating=None, quick=false, full=false, estimate_start=false, ants=None,
    iterations=None, points=40, bounds=None, time_name=None))]
#[allow(clippy::too_many_arguments)]
pub fn quantify(
    py: Python<'_>,
    op: PyReadonlyArray1<'_, f64>,
    pv: PyReadonlyArray1<'_, f64>,
    time: Option<PyReadonlyArray1<'_, f64>>,
    ts: Option<f64>,
    model: &str,
    method: Option<&str>,
    seed: u64,
    max_delay: usize,
    integrating: Option<bool>,
    quick: bool,
    full: bool,
    estimate_start: bool,
    ants: Option<usize>,
    iterations: Option<usize>,
    points: usize,
    bounds: Option<HashMap<String, (f64, f64)>>,
    time_name: Option<String>,
) -> PyResult<(String, Vec<String>)> {
    let (kind, method) = model_method(model, method)?;
    let signals = Signals {
        op: slice(&op),
        pv: slice(&pv),
        sp: None,
        mv: None,
        auto: None,
        time: time.as_ref().map(slice),
    };
    let p = record::prepare(signals, ts).map_err(|e| match e {
        PrepareError::TimeNotIncreasing => bad(format!(
            "the time column '{}' does not increase; give the sampling time with ts=SECONDS",
            time_name.as_deref().unwrap_or("time")
        )),
        PrepareError::Ts(ts) => bad(format!(
            "ts={ts}: the sampling time must be a positive number of seconds"
        )),
        e => bad(e.to_string()),
    })?;
    let (op, pv, note) = fit_stretch(("op", &p.signals.op), ("pv", &p.signals.pv), 2)?;
    let (op, pv) = (&op[..], &pv[..]);
    let mut req = QuantifyRequest::new(kind, method);
    req.ts = p.ts;
    req.seed = seed;
    req.max_delay = max_delay;
    req.full_partition = !quick;
    req.staged = !full;
    req.estimate_start = estimate_start;
    req.integrating = integrating;
    req.grid.points = points;
    if let Some(n) = ants {
        req.aco.ants = n;
        req.acor.ants = n;
    }
    if let Some(n) = iterations {
        req.aco.iterations = n;
        req.acor.iterations = n;
    }
    if let Some(given) = bounds.filter(|b| !b.is_empty()) {
        let (lo, hi) = op
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let range = (0.0, (hi - lo).max(f64::MIN_POSITIVE));
        req.bounds = Some(self::bounds(kind, given, vec![range; kind.dim()])?);
    }
    let req = req.check().map_err(estimate_error)?;
    let q = py
        .detach(|| core_quantify::quantify_checked(op, pv, &req))
        .map_err(estimate_error)?;
    let notes = note.into_iter().chain(p.notes).collect();
    Ok((json(&q)?, notes))
}

/// Apply `estimate`'s keyword settings (the CLI's flags, same names) to a request.
fn settings(req: &mut Request, kind: ModelKind, given: &Bound<'_, PyDict>) -> PyResult<()> {
    let (mut lo, mut hi, mut ranges) = (None, None, None);
    for (key, value) in given.iter() {
        let key: String = key.extract()?;
        let wrong = |e: PyErr| bad(format!("{key}: {e}"));
        let int = || value.extract::<usize>().map_err(wrong);
        let float = || value.extract::<f64>().map_err(wrong);
        match key.as_str() {
            "ants" => (req.aco.ants, req.acor.ants) = (int()?, int()?),
            "iterations" => (req.aco.iterations, req.acor.iterations) = (int()?, int()?),
            "rho" => req.aco.rho = float()?,
            "q" => req.aco.q = float()?,
            "elitist" => req.aco.elitist = float()?,
            "resolution" => req.aco.resolution = float()?,
            "tau0" => req.aco.tau0 = float()?,
            "epsilon" => req.aco.epsilon = float()?,
            "local_search" => req.aco.local_search = int()?,
            "archive" => req.acor.archive = int()?,
            "locality" => req.acor.q = float()?,
            "xi" => req.acor.xi = float()?,
            "points" => req.grid.points = int()?,
            "lo" => lo = Some(float()?),
            "hi" => hi = Some(float()?),
            "bounds" => ranges = Some(value.extract::<HashMap<String, (f64, f64)>>().map_err(wrong)?),
            _ => return Err(bad(format!(
                "unknown setting '{key}'; the settings are ants, iterations, rho, q, elitist, resolution, tau0, epsilon, local_search, archive, locality, xi, points, lo, hi, bounds"
            ))),
        }
    }
    if lo.is_some() || hi.is_some() || ranges.is_some() {
        let defaults = kind
            .params()
            .iter()
            .map(|p| (lo.unwrap_or(p.search.0), hi.unwrap_or(p.search.1)))
            .collect();
        req.bounds = Some(bounds(kind, ranges.unwrap_or_default(), defaults)?);
    }
    Ok(())
}

/// Estimate a stiction model's parameters from OP and the valve position MV: the `Estimate`
/// as JSON (the CLI's `estimate --json`) and notes.
#[pyfunction]
#[pyo3(signature = (op, mv, model="stenman", method=None, seed=1, settings=None))]
pub fn estimate(
    py: Python<'_>,
    op: PyReadonlyArray1<'_, f64>,
    mv: PyReadonlyArray1<'_, f64>,
    model: &str,
    method: Option<&str>,
    seed: u64,
    settings: Option<Bound<'_, PyDict>>,
) -> PyResult<(String, Vec<String>)> {
    let (kind, method) = model_method(model, method)?;
    let mut req = Request::new(kind, method);
    req.seed = seed;
    if let Some(given) = &settings {
        self::settings(&mut req, kind, given)?;
    }
    // the request is checked once, before the data, so a typo fails fast
    let req = req.check().map_err(estimate_error)?;
    let (op, mv): (Cow<'_, [f64]>, Cow<'_, [f64]>) = (slice(&op), slice(&mv));
    if op.len() != mv.len() {
        return Err(bad(format!(
            "op has {} samples but mv has {}: the signals must have the same length",
            op.len(),
            mv.len()
        )));
    }
    let (op, mv, note) = fit_stretch(("op", &op), ("mv", &mv), core_estimate::MIN_SAMPLES)?;
    let (op, mv) = (&op[..], &mv[..]);
    let (lo, hi) = op
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    if hi - lo <= 0.0 {
        return Err(bad(format!(
            "op (controller output op) is constant at {lo}; a valve whose command never moves shows no stiction, choose a stretch of data where op varies"
        )));
    }
    let est = py
        .detach(|| core_estimate::estimate_checked(op, mv, &req))
        .map_err(estimate_error)?;
    Ok((json(&est)?, note.into_iter().collect()))
}
