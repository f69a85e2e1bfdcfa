//! `simulate` (open loop or a PI loop, as the CLI's `simulate`, with the same text specs) and the
//! stiction models as classes (`Stenman(d=0.5).simulate(op)`).

use crate::{bad, slice};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use stiction_core::models::{Model, ModelKind};
use stiction_core::sim::{simulate_open_loop, ClosedLoop};
use stiction_core::spec;

fn spec_error(e: spec::SpecError) -> PyErr {
    bad(e.0)
}

/// A model of `kind` from `{name: value}`, every parameter named.
fn model_of(kind: ModelKind, params: &Bound<'_, PyDict>) -> PyResult<Model> {
    let mut texts = Vec::new();
    for (k, v) in params.iter() {
        let name: String = k.extract()?;
        let value: f64 = v
            .extract()
            .map_err(|_| bad(format!("params: {name} must be a number")))?;
        texts.push(format!("{name}={value}"));
    }
    spec::model(kind, &texts, "params").map_err(spec_error)
}

/// Simulate a sticky valve open loop (a command signal) or in a PI loop: a dict of numpy arrays
/// t, sp, op, mv, pv (sp and pv empty open loop).
#[pyfunction]
#[pyo3(signature = (model, params, closed=false, signal=None, ts=None, samples=None, noise=0.0,
    seed=1, process=None, pi=None, sp=None, op0=None, disturbance=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    model: &str,
    params: &Bound<'py, PyDict>,
    closed: bool,
    signal: Option<&str>,
    ts: Option<f64>,
    samples: Option<usize>,
    noise: f64,
    seed: u64,
    process: Option<&str>,
    pi: Option<&str>,
    sp: Option<&str>,
    op0: Option<f64>,
    disturbance: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let kind: ModelKind = model
        .parse()
        .map_err(|e| bad(format!("model='{model}': {e}")))?;
    let model = model_of(kind, params)?;
    let ts = ts.unwrap_or(if closed { 1.0 } else { 0.1 });
    let samples = samples.unwrap_or(if closed { 2000 } else { 1001 });
    if !(ts > 0.0 && ts.is_finite()) {
        return Err(bad(format!(
            "ts={ts}: the sampling time must be a positive number of seconds"
        )));
    }
    if samples < 2 {
        return Err(bad(format!(
            "samples={samples}: simulate at least 2 samples"
        )));
    }
    if !(noise >= 0.0 && noise.is_finite()) {
        return Err(bad(format!(
            "noise={noise}: the noise standard deviation must be >= 0"
        )));
    }
    let data = if closed {
        if signal.is_some() {
            return Err(bad("signal= drives an open loop; a closed loop follows sp= (the setpoint) and disturbance="));
        }
        let mut cl = ClosedLoop::new(model);
        cl.process = spec::process(process.unwrap_or("foptd:K=3,tau=10,delay=10"), "process=")
            .map_err(spec_error)?;
        cl.pi = spec::pi(pi.unwrap_or("Kc=0.2,Ti=10"), "pi=").map_err(spec_error)?;
        cl.setpoint =
            spec::signal(sp.unwrap_or("step:from=50,to=51,at=10"), "sp=").map_err(spec_error)?;
        cl.disturbance = disturbance
            .map(|d| spec::signal(d, "disturbance="))
            .transpose()
            .map_err(spec_error)?;
        (cl.ts, cl.samples, cl.noise, cl.seed) = (ts, samples, noise, seed);
        cl.op0 = op0.unwrap_or(50.0);
        py.detach(|| cl.run())
            .map_err(|e| bad(format!("closed loop: {e}")))?
    } else {
        let given = [
            ("process", process.is_some()),
            ("pi", pi.is_some()),
            ("sp", sp.is_some()),
            ("op0", op0.is_some()),
            ("disturbance", disturbance.is_some()),
        ];
        if let Some((name, _)) = given.iter().find(|(_, g)| *g) {
            return Err(bad(format!(
                "{name}= applies to a closed loop; pass loop='closed', or leave {name} out"
            )));
        }
        let signal = spec::signal(signal.unwrap_or("sine:amplitude=1,period=10"), "signal=")
            .map_err(spec_error)?;
        simulate_open_loop(&model, &signal, ts, samples, noise, seed)
            .map_err(|e| bad(format!("open loop: {e}")))?
    };
    let out = PyDict::new(py);
    out.set_item("t", data.t.into_pyarray(py))?;
    out.set_item("sp", data.sp.into_pyarray(py))?;
    out.set_item("op", data.op.into_pyarray(py))?;
    out.set_item("mv", data.mv.into_pyarray(py))?;
    out.set_item("pv", data.pv.into_pyarray(py))?;
    Ok(out)
}

/// The valve position a model gives for a command `op` (numpy array), from `start` (default:
/// as if the valve had just moved to the first OP).
fn run_model<'py>(
    py: Python<'py>,
    m: &Model,
    op: PyReadonlyArray1<'py, f64>,
    start: Option<f64>,
) -> Bound<'py, PyArray1<f64>> {
    let op = slice(&op);
    m.simulate_from(&op, start).into_pyarray(py)
}

fn params_of<'py>(py: Python<'py>, m: &Model) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (n, v) in m.kind().param_names().iter().zip(m.values()) {
        d.set_item(n, v)?;
    }
    Ok(d)
}

fn repr(m: &Model) -> String {
    let args: Vec<String> = m
        .kind()
        .param_names()
        .iter()
        .zip(m.values())
        .map(|(n, v)| format!("{n}={v}"))
        .collect();
    let name = match m.kind() {
        ModelKind::Stenman => "Stenman",
        ModelKind::He => "He",
        ModelKind::Kano => "Kano",
        ModelKind::Choudhury => "Choudhury",
    };
    format!("{name}({})", args.join(", "))
}

macro_rules! model_class {
    ($name:ident, $doc:literal, $kind:expr, ($($arg:ident),+)) => {
        #[doc = $doc]
        #[pyclass(module = "stiction", frozen)]
        pub struct $name {
            model: Model,
        }

        #[pymethods]
        impl $name {
            #[new]
            #[allow(non_snake_case)]
            fn new($($arg: f64),+) -> PyResult<Self> {
                let model = $kind
                    .build(&[$($arg),+])
                    .map_err(|e| bad(e.to_string()))?;
                Ok(Self { model })
            }

            /// The valve position (numpy array) for the command `op`, from `start` (default:
            /// as if the valve had just moved to the first OP).
            #[pyo3(signature = (op, start=None))]
            fn simulate<'py>(
                &self,
                py: Python<'py>,
                op: PyReadonlyArray1<'py, f64>,
                start: Option<f64>,
            ) -> Bound<'py, PyArray1<f64>> {
                run_model(py, &self.model, op, start)
            }

            /// The parameters, `{name: value}` (% of valve span).
            #[getter]
            fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
                params_of(py, &self.model)
            }

            fn __repr__(&self) -> String {
                repr(&self.model)
            }
        }
    };
}

model_class!(
    Stenman,
    "Stenman's one-parameter model: the valve moves to OP when OP is more than the stiction band d away (d in % of valve span).",
    ModelKind::Stenman,
    (d)
);
model_class!(
    He,
    "He et al. (2007): static band fs and kinetic band fd (fs >= fd), % of valve span.",
    ModelKind::He,
    (fs, fd)
);
model_class!(
    Kano,
    "Kano et al. (2004): S, deadband plus stickband, and J, the slip jump, % of valve span.",
    ModelKind::Kano,
    (S, J)
);
model_class!(
    Choudhury,
    "Choudhury et al. (2005): S, deadband plus stickband, and J, the slip jump, % of valve span.",
    ModelKind::Choudhury,
    (S, J)
);

pub fn add_models(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Stenman>()?;
    m.add_class::<He>()?;
    m.add_class::<Kano>()?;
    m.add_class::<Choudhury>()?;
    Ok(())
}
