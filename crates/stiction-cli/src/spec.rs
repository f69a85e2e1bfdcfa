//! Small text specs from the command line: `NAME=VALUE` lists, signals (`sine:amplitude=1,period=10`),
//! processes (`foptd:K=3,tau=10,delay=10`), model parameters.

use anyhow::{Context, Result};
use stiction_core::estimate::EstimateError;
use stiction_core::models::{Model, ModelKind};
use stiction_core::sim::{Pi, Process, Signal};
use stiction_core::spec as core_spec;

/// `KIND:k=v,...` into a signal (the core's reading, shared with Python).
pub fn signal(text: &str, flag: &str) -> Result<Signal> {
    Ok(core_spec::signal(text, flag)?)
}

/// `foptd:K=3,tau=10,delay=10` or `integrating:K=0.02,delay=2`.
pub fn process(text: &str) -> Result<Process> {
    Ok(core_spec::process(text, "--process")?)
}

/// `Kc=0.2,Ti=10`.
pub fn pi(text: &str) -> Result<Pi> {
    Ok(core_spec::pi(text, "--pi")?)
}

pub fn model_kind(text: &str) -> Result<ModelKind> {
    text.parse::<ModelKind>()
        .map_err(|e| anyhow::anyhow!("--model: {e}"))
}

/// A model from `--param NAME=VALUE` flags (each flag may hold several, comma-separated).
pub fn model(kind: ModelKind, params: &[String]) -> Result<Model> {
    Ok(core_spec::model(kind, params, "--param")?)
}

/// `--bounds NAME=LO:HI` flags applied over default ranges (one per parameter of the model).
pub fn bounds(
    kind: ModelKind,
    texts: &[String],
    mut ranges: Vec<(f64, f64)>,
) -> Result<Vec<(f64, f64)>> {
    for text in texts {
        let parsed = text.split_once('=').and_then(|(n, r)| {
            let (lo, hi) = r.split_once(':')?;
            Some((
                n.trim(),
                lo.trim().parse::<f64>().ok()?,
                hi.trim().parse::<f64>().ok()?,
            ))
        });
        let (name, lo, hi) = parsed.with_context(|| {
            format!(
                "--bounds {text}: write NAME=LO:HI, e.g. --bounds {}=0.01:10",
                kind.param_names()[0]
            )
        })?;
        let i = kind
            .param_index(name)
            .map_err(|e| anyhow::anyhow!("--bounds: {e}"))?;
        ranges[i] = (lo, hi);
    }
    Ok(ranges)
}

/// Flags every estimating command shares: which model, which method, the seed, JSON output.
#[derive(clap::Args)]
pub struct FitArgs {
    /// Stiction model: stenman, he, kano, choudhury
    #[arg(long, default_value = "stenman")]
    pub model: String,
    /// aco (the paper's), aco-r, exact (stenman only), grid [default: exact for stenman, else aco-r]
    #[arg(long)]
    pub method: Option<String>,
    /// Seed of the random methods
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print one JSON object instead of text
    #[arg(long)]
    pub json: bool,
}

impl FitArgs {
    /// The model and method, checked (exact is for Stenman only).
    pub fn resolve(&self) -> Result<(ModelKind, stiction_core::Method)> {
        let kind = model_kind(&self.model)?;
        let method = match &self.method {
            Some(m) => m
                .parse::<stiction_core::Method>()
                .map_err(|e| anyhow::anyhow!("--method: {e}"))?,
            None => stiction_core::Method::default_for(kind),
        };
        // the core's rule (exact is for Stenman only), before any file is read
        stiction_core::Request::new(kind, method)
            .check()
            .map_err(setting_error)?;
        Ok((kind, method))
    }
}

/// The core's request error in the words of the flag that sets the value: a search setting out
/// of range (`--ants must be at least 1, got 0`; ACO_R's `q` is `--locality`, ACO's `--q`), the
/// sampling time (`--ts`), the exact method for another model (`--method`); other errors as they
/// are.
pub fn setting_error(e: EstimateError) -> anyhow::Error {
    match e {
        EstimateError::Ts(ts) => {
            anyhow::anyhow!("--ts {ts}: the sampling time must be a positive number of seconds")
        }
        EstimateError::ExactNeedsStenman(kind) => anyhow::anyhow!(
            "--method exact solves the Stenman model only; for {kind} use aco-r, aco or grid"
        ),
        EstimateError::Setting {
            method,
            name,
            rule,
            value,
        } => {
            let flag = method.setting_key(name).replace('_', "-");
            anyhow::anyhow!("--{flag} must be {rule}, got {value}")
        }
        e => e.into(),
    }
}
