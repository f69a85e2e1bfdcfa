//! Small text specs from the command line: `NAME=VALUE` lists, signals (`sine:amplitude=1,period=10`),
//! processes (`foptd:K=3,tau=10,delay=10`), model parameters.

use anyhow::{bail, Context, Result};
use stiction_core::models::{Model, ModelKind};
use stiction_core::sim::{Pi, Process, Signal};

/// `a=1,b=2` (also `a=1 b=2`) into pairs, checking every name against `known` (case-insensitive).
pub fn pairs(text: &str, what: &str, known: &[&str]) -> Result<Vec<(String, f64)>> {
    let mut out: Vec<(String, f64)> = Vec::new();
    for item in text.split([',', ' ']).filter(|s| !s.trim().is_empty()) {
        let Some((name, value)) = item.split_once('=') else {
            bail!(
                "{what}: '{item}' is not NAME=VALUE; write e.g. {}=1",
                known.first().unwrap_or(&"x")
            )
        };
        let name = name.trim();
        let canonical = known
            .iter()
            .find(|k| k.eq_ignore_ascii_case(name))
            .with_context(|| {
                format!(
                    "{what}: unknown name '{name}'; the names are {}",
                    known.join(", ")
                )
            })?;
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .with_context(|| {
                format!("{what}: {name} = '{}' is not a finite number", value.trim())
            })?;
        if out.iter().any(|(n, _)| n == canonical) {
            bail!("{what}: {name} is given twice");
        }
        out.push((canonical.to_string(), value));
    }
    Ok(out)
}

fn get(p: &[(String, f64)], name: &str, default: f64) -> f64 {
    p.iter()
        .find(|(n, _)| n == name)
        .map_or(default, |(_, v)| *v)
}

/// `KIND:k=v,...` into a signal. Unnamed settings take the defaults shown in `--help`.
pub fn signal(text: &str, flag: &str) -> Result<Signal> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    let what = format!("{flag} {text}");
    let kind = kind.trim().to_ascii_lowercase();
    let s = match kind.as_str() {
        "sine" | "triangle" => {
            let p = pairs(rest, &what, &["amplitude", "period", "offset"])?;
            let (amplitude, period, offset) =
                (get(&p, "amplitude", 1.0), get(&p, "period", 10.0), get(&p, "offset", 0.0));
            if kind == "sine" {
                Signal::Sine { amplitude, period, offset }
            } else {
                Signal::Triangle { amplitude, period, offset }
            }
        }
        "random-walk" | "random_walk" | "randomwalk" => {
            let p = pairs(rest, &what, &["std", "offset", "seed"])?;
            Signal::RandomWalk {
                step_std: get(&p, "std", 0.1),
                offset: get(&p, "offset", 0.0),
                seed: seed_value(get(&p, "seed", 1.0), &what)?,
            }
        }
        "steps" => {
            let p = pairs(rest, &what, &["amplitude", "hold", "offset", "seed"])?;
            Signal::Steps {
                amplitude: get(&p, "amplitude", 1.0),
                hold: get(&p, "hold", 10.0),
                offset: get(&p, "offset", 0.0),
                seed: seed_value(get(&p, "seed", 1.0), &what)?,
            }
        }
        "step" => {
            let p = pairs(rest, &what, &["from", "to", "at"])?;
            Signal::Step { from: get(&p, "from", 50.0), to: get(&p, "to", 51.0), at: get(&p, "at", 10.0) }
        }
        "const" | "constant" => {
            let p = pairs(rest, &what, &["value"])?;
            Signal::Constant { value: get(&p, "value", 50.0) }
        }
        other => bail!(
            "{flag}: unknown signal '{other}'; the signals are sine, triangle, random-walk, steps, step, const (e.g. {flag} sine:amplitude=1,period=10)"
        ),
    };
    s.validate().map_err(|e| anyhow::anyhow!("{what}: {e}"))?;
    Ok(s)
}

fn seed_value(v: f64, what: &str) -> Result<u64> {
    if v >= 0.0 && v.fract() == 0.0 && v < 1.8e19 {
        Ok(v as u64)
    } else {
        bail!("{what}: seed must be a whole number >= 0")
    }
}

/// `foptd:K=3,tau=10,delay=10` or `integrating:K=0.02,delay=2`.
pub fn process(text: &str) -> Result<Process> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    let what = format!("--process {text}");
    let p = match kind.trim().to_ascii_lowercase().as_str() {
        "foptd" => {
            let p = pairs(rest, &what, &["K", "tau", "delay"])?;
            Process::Foptd { k: get(&p, "K", 3.0), tau: get(&p, "tau", 10.0), delay: get(&p, "delay", 10.0) }
        }
        "integrating" => {
            let p = pairs(rest, &what, &["K", "delay"])?;
            Process::Integrating { k: get(&p, "K", 0.02), delay: get(&p, "delay", 2.0) }
        }
        other => bail!("--process: unknown process '{other}'; use foptd:K=3,tau=10,delay=10 or integrating:K=0.02,delay=2"),
    };
    p.validate().map_err(|e| anyhow::anyhow!("{what}: {e}"))?;
    Ok(p)
}

/// `Kc=0.2,Ti=10`.
pub fn pi(text: &str) -> Result<Pi> {
    let p = pairs(text, &format!("--pi {text}"), &["Kc", "Ti"])?;
    Ok(Pi {
        kc: get(&p, "Kc", 0.2),
        ti: get(&p, "Ti", 10.0),
    })
}

pub fn model_kind(text: &str) -> Result<ModelKind> {
    text.parse::<ModelKind>()
        .map_err(|e| anyhow::anyhow!("--model: {e}"))
}

/// A model from `--param NAME=VALUE` flags (each flag may hold several, comma-separated).
pub fn model(kind: ModelKind, params: &[String]) -> Result<Model> {
    let names = kind.param_names();
    let mut given: Vec<(String, f64)> = Vec::new();
    for text in params {
        for (n, v) in pairs(text, &format!("--param for model {kind}"), &names)? {
            if given.iter().any(|(g, _)| *g == n) {
                bail!("--param: {n} is given twice");
            }
            given.push((n, v));
        }
    }
    let mut values = Vec::new();
    for spec in kind.params() {
        let v = given
            .iter()
            .find(|(n, _)| n == spec.name)
            .map(|(_, v)| *v)
            .with_context(|| {
                format!(
                    "model {kind} needs --param {}=VALUE ({}, {}); its parameters are {}",
                    spec.name,
                    spec.description,
                    spec.unit,
                    names.join(", ")
                )
            })?;
        values.push(v);
    }
    kind.build(&values)
        .map_err(|e| anyhow::anyhow!("--param: {e}"))
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
        if method == stiction_core::Method::Exact && kind != ModelKind::Stenman {
            bail!(
                "--method exact solves the Stenman model only; for {kind} use aco-r, aco or grid"
            );
        }
        Ok((kind, method))
    }
}
