//! What `estimate` is asked: the method, the request and its check, and the errors of a request
//! or its data.

use crate::checked::Checked;
use crate::models::{ModelError, ModelKind};
use serde::{Deserialize, Serialize};

use super::{AcoSettings, AcorSettings, ExactSettings, GridSettings};

/// Estimation methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The paper's ant colony optimisation (Ant System on a grid of nodes).
    Aco,
    /// Ant colony optimisation for continuous domains.
    AcoR,
    /// The exact partition solver (Stenman only).
    Exact,
    /// Brute-force grid.
    Grid,
}

impl Method {
    /// The name the front ends give one of this method's settings (the CLI's flag, Python's
    /// keyword): the field's name, except ACO_R's `q`, which they call `locality` (ACO's `q` is its
    /// pheromone deposit).
    pub fn setting_key(self, name: &'static str) -> &'static str {
        match (self, name) {
            (Method::AcoR, "q") => "locality",
            _ => name,
        }
    }

    /// Every method.
    pub const ALL: [Method; 4] = [Method::Aco, Method::AcoR, Method::Exact, Method::Grid];

    /// The method's name as the CLI and serde write it (`aco-r`).
    pub fn name(self) -> &'static str {
        match self {
            Method::Aco => "aco",
            Method::AcoR => "aco-r",
            Method::Exact => "exact",
            Method::Grid => "grid",
        }
    }

    /// The method used when none is named: exact for Stenman, ACO_R for two-parameter models.
    pub fn default_for(kind: ModelKind) -> Method {
        if kind == ModelKind::Stenman {
            Method::Exact
        } else {
            Method::AcoR
        }
    }
}

impl std::str::FromStr for Method {
    type Err = EstimateError;
    fn from_str(s: &str) -> Result<Self, EstimateError> {
        match s.trim().to_ascii_lowercase().replace('_', "-").as_str() {
            "aco" => Ok(Method::Aco),
            "aco-r" | "acor" => Ok(Method::AcoR),
            "exact" => Ok(Method::Exact),
            "grid" => Ok(Method::Grid),
            _ => Err(EstimateError::UnknownMethod(s.to_string())),
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Errors in an estimation request or its data.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EstimateError {
    /// A method name that is not one of aco, aco-r, exact, grid.
    #[error("unknown method '{0}'; the methods are aco, aco-r, exact, grid")]
    UnknownMethod(String),
    /// The exact method asked for another model than Stenman.
    #[error("the exact method solves the Stenman model only; for {0} use aco-r, aco or grid")]
    ExactNeedsStenman(ModelKind),
    /// An invalid model parameter.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A search range that cannot be searched.
    #[error("bounds for {name} are [{lo}, {hi}]: {why}")]
    Bounds {
        /// The parameter.
        name: String,
        /// Its lower end.
        lo: f64,
        /// Its upper end.
        hi: f64,
        /// What is wrong with it.
        why: &'static str,
    },
    /// A method's setting out of range, named as in the method's settings (`ants`, `rho`, ...).
    #[error("{method} {name} must be {rule}, got {value}")]
    Setting {
        /// The method whose setting it is.
        method: Method,
        /// The setting's name, that of its field in the method's settings.
        name: &'static str,
        /// What it must be.
        rule: &'static str,
        /// The value given.
        value: f64,
    },
    /// Bounds for another number of parameters than the model has.
    #[error("model {model} has {parameters} parameters but {given} bounds were given")]
    BoundsCount {
        /// The model.
        model: ModelKind,
        /// Its number of parameters.
        parameters: usize,
        /// The number of bounds given.
        given: usize,
    },
    /// The sampling time (seconds) is not a positive number.
    #[error("the sampling time must be a positive number of seconds, got {0}")]
    Ts(f64),
    /// The valve position at the first sample is not a finite number.
    #[error("the valve's position at the first sample must be a finite number, got {0}")]
    ValveStart(f64),
    /// Two signals of different lengths.
    #[error("{a} has {a_len} samples but {b} has {b_len}")]
    Lengths {
        /// The first signal.
        a: &'static str,
        /// Its samples.
        a_len: usize,
        /// The second signal.
        b: &'static str,
        /// Its samples.
        b_len: usize,
    },
    /// A value that is not a finite number.
    #[error("{signal} sample {index} is {value}; every value must be a finite number")]
    NotFinite {
        /// The signal.
        signal: &'static str,
        /// The sample's index.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Too few samples to estimate from.
    #[error("only {samples} samples; at least {least} are needed")]
    TooFewSamples {
        /// The samples given.
        samples: usize,
        /// The fewest accepted.
        least: usize,
    },
    /// A command that never moves.
    #[error("the command op is constant ({0}); a valve that is never moved shows no stiction")]
    ConstantOp(f64),
}

/// What to estimate and how.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Request {
    /// The stiction model to fit.
    pub model: ModelKind,
    /// The search method.
    pub method: Method,
    /// Search range per parameter, in the model's parameter order; `None` uses the model's defaults.
    pub bounds: Option<Vec<(f64, f64)>>,
    /// Seed of the random searches (aco, aco-r).
    pub seed: u64,
    /// Settings of the paper's ACO.
    pub aco: AcoSettings,
    /// Settings of ACO_R.
    pub acor: AcorSettings,
    /// Settings of the grid search.
    pub grid: GridSettings,
    /// Settings of the exact solver's initial bound.
    pub exact: ExactSettings,
    /// Keep the per-iteration trace (population methods).
    pub trace: bool,
    /// Stenman with a heuristic method: also run the exact solver and say whether the answer is
    /// in the proven optimal set.
    pub certify: bool,
}

impl Request {
    /// A request for `model` by `method` with every setting at its default (seed 1, certified).
    pub fn new(model: ModelKind, method: Method) -> Self {
        Self {
            model,
            method,
            bounds: None,
            seed: 1,
            aco: AcoSettings::default(),
            acor: AcorSettings::default(),
            grid: GridSettings::default(),
            exact: ExactSettings::default(),
            trace: false,
            certify: true,
        }
    }

    /// Check the request once, before any data are read: the chosen method's settings (the first
    /// one out of range is the error), the exact method asked for Stenman only, and the search
    /// range. [`super::estimate_checked`] runs the checked request without checking it again.
    pub fn check(&self) -> Result<Checked<Request>, EstimateError> {
        self.check_settings()?;
        check_bounds(self.model, &self.search_range())?;
        Ok(Checked::new(self.clone()))
    }

    /// The search range asked for, or the model's defaults.
    pub(super) fn search_range(&self) -> Vec<(f64, f64)> {
        match &self.bounds {
            Some(b) => b.clone(),
            None => self.model.params().iter().map(|p| p.search).collect(),
        }
    }

    /// The method's settings and the model it is asked for.
    pub(crate) fn check_settings(&self) -> Result<(), EstimateError> {
        let method = self.method;
        let check = |ok: bool, name: &'static str, rule: &'static str, value: f64| {
            if ok {
                Ok(())
            } else {
                Err(EstimateError::Setting {
                    method,
                    name,
                    rule,
                    value,
                })
            }
        };
        const AT_LEAST_1: &str = "at least 1";
        const POSITIVE: &str = "a finite number > 0";
        // the ant methods' population: at least one ant and one iteration
        let population = |ants: usize, iterations: usize| {
            check(ants >= 1, "ants", AT_LEAST_1, ants as f64)?;
            check(iterations >= 1, "iterations", AT_LEAST_1, iterations as f64)
        };
        match method {
            Method::Aco => {
                let s = &self.aco;
                population(s.ants, s.iterations)?;
                check(
                    positive(s.rho) && s.rho < 1.0,
                    "rho",
                    "between 0 and 1, exclusive",
                    s.rho,
                )?;
                check(positive(s.q), "q", POSITIVE, s.q)?;
                check(
                    s.elitist == 0.0 || positive(s.elitist),
                    "elitist",
                    "a finite number >= 0",
                    s.elitist,
                )?;
                check(positive(s.resolution), "resolution", POSITIVE, s.resolution)?;
                check(positive(s.tau0), "tau0", POSITIVE, s.tau0)?;
                check(positive(s.epsilon), "epsilon", POSITIVE, s.epsilon)?;
            }
            Method::AcoR => {
                let s = &self.acor;
                population(s.ants, s.iterations)?;
                check(s.archive >= 2, "archive", "at least 2", s.archive as f64)?;
                check(positive(s.q), "q", POSITIVE, s.q)?;
                check(positive(s.xi), "xi", POSITIVE, s.xi)?;
            }
            Method::Grid => {
                let points = self.grid.points;
                check(points >= 2, "points", "at least 2", points as f64)?;
            }
            Method::Exact => {
                if self.model != ModelKind::Stenman {
                    return Err(EstimateError::ExactNeedsStenman(self.model));
                }
            }
        }
        Ok(())
    }
}

fn positive(x: f64) -> bool {
    x > 0.0 && x.is_finite()
}

/// Check the data an estimation needs: equal lengths, finite values, enough samples, a moving command.
pub fn check_data(op: &[f64], mv: &[f64]) -> Result<(), EstimateError> {
    check_pair(("op", op), ("mv", mv))?;
    if op.len() < MIN_SAMPLES {
        return Err(EstimateError::TooFewSamples {
            samples: op.len(),
            least: MIN_SAMPLES,
        });
    }
    let (lo, hi) = op
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi - lo <= 0.0 {
        return Err(EstimateError::ConstantOp(lo));
    }
    Ok(())
}

/// Two series of the same length holding only finite numbers.
pub fn check_pair(
    (a_name, a): (&'static str, &[f64]),
    (b_name, b): (&'static str, &[f64]),
) -> Result<(), EstimateError> {
    if a.len() != b.len() {
        return Err(EstimateError::Lengths {
            a: a_name,
            a_len: a.len(),
            b: b_name,
            b_len: b.len(),
        });
    }
    for (signal, s) in [(a_name, a), (b_name, b)] {
        if let Some(index) = s.iter().position(|v| !v.is_finite()) {
            return Err(EstimateError::NotFinite {
                signal,
                index,
                value: s[index],
            });
        }
    }
    Ok(())
}

/// Search ranges, one per parameter: finite, not below the parameter's minimum, not reversed.
pub fn check_bounds(model: ModelKind, bounds: &[(f64, f64)]) -> Result<(), EstimateError> {
    let specs = model.params();
    if bounds.len() != specs.len() {
        return Err(EstimateError::BoundsCount {
            model,
            parameters: specs.len(),
            given: bounds.len(),
        });
    }
    for (spec, &(lo, hi)) in specs.iter().zip(bounds) {
        let err = |why| EstimateError::Bounds {
            name: spec.name.to_string(),
            lo,
            hi,
            why,
        };
        if !lo.is_finite() || !hi.is_finite() {
            return Err(err("both ends must be finite numbers"));
        }
        if lo < spec.min {
            return Err(err("the lower end must not be negative"));
        }
        if lo >= hi {
            return Err(err(
                "the lower end must be below the upper end (reversed or empty)",
            ));
        }
    }
    Ok(())
}

/// Fewest samples an estimation accepts.
pub const MIN_SAMPLES: usize = 10;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_names_the_first_setting_out_of_range() {
        let mut r = Request::new(ModelKind::Stenman, Method::Aco);
        r.aco.ants = 0;
        r.aco.rho = 2.0;
        let e = r.check().unwrap_err();
        assert!(matches!(e, EstimateError::Setting { name: "ants", value, .. } if value == 0.0));
        r.aco.ants = 20;
        let e = r.check().unwrap_err();
        assert_eq!(
            e.to_string(),
            "aco rho must be between 0 and 1, exclusive, got 2"
        );
        r.aco.rho = 0.2;
        let checked = r.check().unwrap();
        assert_eq!(*checked, r);
        assert_eq!(checked.into_inner(), r);
    }

    #[test]
    fn check_rejects_exact_for_two_parameter_models_and_wrong_bounds() {
        let r = Request::new(ModelKind::Kano, Method::Exact);
        assert_eq!(
            r.check().unwrap_err(),
            EstimateError::ExactNeedsStenman(ModelKind::Kano)
        );
        let mut r = Request::new(ModelKind::Stenman, Method::Exact);
        r.bounds = Some(vec![(0.0, 1.0), (0.0, 1.0)]);
        assert_eq!(
            r.check().unwrap_err(),
            EstimateError::BoundsCount {
                model: ModelKind::Stenman,
                parameters: 1,
                given: 2
            }
        );
        r.bounds = Some(vec![(2.0, 1.0)]);
        assert!(
            matches!(r.check(), Err(EstimateError::Bounds { lo, hi, .. }) if lo == 2.0 && hi == 1.0)
        );
        r.bounds = None;
        assert_eq!(
            r.check().unwrap().search_range(),
            vec![ModelKind::Stenman.params()[0].search]
        );
    }

    #[test]
    fn data_errors_name_the_signal_and_sample() {
        let op = [0.0, 1.0, f64::NAN];
        let e = check_pair(("op", &op), ("mv", &[0.0; 3])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "op sample 2 is NaN; every value must be a finite number"
        );
        let e = check_pair(("op", &[0.0; 3]), ("mv", &[0.0; 2])).unwrap_err();
        assert_eq!(e.to_string(), "op has 3 samples but mv has 2");
        let e = check_data(&[1.0; 20], &[1.0; 20]).unwrap_err();
        assert_eq!(e, EstimateError::ConstantOp(1.0));
        let e = check_data(&[1.0, 2.0], &[1.0, 2.0]).unwrap_err();
        assert_eq!(
            e,
            EstimateError::TooFewSamples {
                samples: 2,
                least: MIN_SAMPLES
            }
        );
    }
}
