//! Small text specs shared by the front ends: `NAME=VALUE` lists, signals
//! (`sine:amplitude=1,period=10`), processes (`foptd:K=3,tau=10,delay=10`), PI gains
//! (`Kc=0.2,Ti=10`) and model parameters. Each error is one sentence naming the flag or
//! argument (`flag`) and the fix.

use crate::models::{Model, ModelKind};
use crate::sim::{Pi, Process, Signal};

/// A spec that cannot be read, in one sentence.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SpecError(pub String);

macro_rules! bail {
    ($($t:tt)*) => {
        return Err(SpecError(format!($($t)*)))
    };
}

/// `a=1,b=2` (also `a=1 b=2`) into pairs, checking every name against `known` (case-insensitive).
pub fn pairs(text: &str, what: &str, known: &[&str]) -> Result<Vec<(String, f64)>, SpecError> {
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
            .ok_or_else(|| {
                SpecError(format!(
                    "{what}: unknown name '{name}'; the names are {}",
                    known.join(", ")
                ))
            })?;
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                SpecError(format!(
                    "{what}: {name} = '{}' is not a finite number",
                    value.trim()
                ))
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

/// The settings of a periodic signal: amplitude, period (seconds) and offset.
fn periodic(rest: &str, what: &str) -> Result<(f64, f64, f64), SpecError> {
    let p = pairs(rest, what, &["amplitude", "period", "offset"])?;
    Ok((
        get(&p, "amplitude", 1.0),
        get(&p, "period", 10.0),
        get(&p, "offset", 0.0),
    ))
}

/// `KIND:k=v,...` into a signal. Unnamed settings take the defaults shown in `--help`.
pub fn signal(text: &str, flag: &str) -> Result<Signal, SpecError> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    let what = format!("{flag} {text}");
    let kind = kind.trim().to_ascii_lowercase();
    let s = match kind.as_str() {
        "sine" => {
            let (amplitude, period, offset) = periodic(rest, &what)?;
            Signal::Sine { amplitude, period, offset }
        }
        "triangle" => {
            let (amplitude, period, offset) = periodic(rest, &what)?;
            Signal::Triangle { amplitude, period, offset }
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
    s.validate()
        .map_err(|e| SpecError(format!("{what}: {e}")))?;
    Ok(s)
}

fn seed_value(v: f64, what: &str) -> Result<u64, SpecError> {
    if v >= 0.0 && v.fract() == 0.0 && v < 1.8e19 {
        Ok(v as u64)
    } else {
        bail!("{what}: seed must be a whole number >= 0")
    }
}

/// `foptd:K=3,tau=10,delay=10` or `integrating:K=0.02,delay=2`.
pub fn process(text: &str, flag: &str) -> Result<Process, SpecError> {
    let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
    let what = format!("{flag} {text}");
    let p = match kind.trim().to_ascii_lowercase().as_str() {
        "foptd" => {
            let p = pairs(rest, &what, &["K", "tau", "delay"])?;
            Process::Foptd { k: get(&p, "K", 3.0), tau: get(&p, "tau", 10.0), delay: get(&p, "delay", 10.0) }
        }
        "integrating" => {
            let p = pairs(rest, &what, &["K", "delay"])?;
            Process::Integrating { k: get(&p, "K", 0.02), delay: get(&p, "delay", 2.0) }
        }
        other => bail!("{flag}: unknown process '{other}'; use foptd:K=3,tau=10,delay=10 or integrating:K=0.02,delay=2"),
    };
    p.validate()
        .map_err(|e| SpecError(format!("{what}: {e}")))?;
    Ok(p)
}

/// `Kc=0.2,Ti=10`.
pub fn pi(text: &str, flag: &str) -> Result<Pi, SpecError> {
    let p = pairs(text, &format!("{flag} {text}"), &["Kc", "Ti"])?;
    Ok(Pi {
        kc: get(&p, "Kc", 0.2),
        ti: get(&p, "Ti", 10.0),
    })
}

/// A model of `kind` from `NAME=VALUE` texts (each may hold several, comma-separated), every
/// parameter named once; `flag` names where they came from (`--param`, `params=`).
pub fn model(kind: ModelKind, params: &[String], flag: &str) -> Result<Model, SpecError> {
    let names = kind.param_names();
    let mut given: Vec<(String, f64)> = Vec::new();
    for text in params {
        for (n, v) in pairs(text, &format!("{flag} for model {kind}"), &names)? {
            if given.iter().any(|(g, _)| *g == n) {
                bail!("{flag}: {n} is given twice");
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
            .ok_or_else(|| {
                SpecError(format!(
                    "model {kind} needs {flag} {}=VALUE ({}, {}); its parameters are {}",
                    spec.name,
                    spec.description,
                    spec.unit,
                    names.join(", ")
                ))
            })?;
        values.push(v);
    }
    kind.build(&values)
        .map_err(|e| SpecError(format!("{flag}: {e}")))
}
