//! Estimating stiction parameters from the command (op) and the valve position (mv): the paper's
//! problem. `estimate` validates a request, runs the chosen method and returns a serde result that
//! every front end prints its own way.

pub mod aco;
pub mod acor;
pub mod exact;
pub mod grid;
pub mod objective;
pub mod solver;

use crate::models::{ModelError, ModelKind};
use crate::rng::seeded;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Instant;

pub use aco::AcoSettings;
pub use acor::AcorSettings;
pub use exact::{ExactSettings, ExactSolution};
pub use grid::GridSettings;
pub use objective::Objective;
pub use solver::TraceRow;

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
    /// Settings that do not fit the model (bounds for another number of parameters) or the data
    /// (a sampling time that is not positive).
    #[error("{0}")]
    Settings(String),
    /// Data that cannot be estimated from (lengths, non-finite values, too few samples, a constant
    /// command).
    #[error("{0}")]
    Data(String),
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

    /// The search range in use, checked.
    pub fn resolved_bounds(&self) -> Result<Vec<(f64, f64)>, EstimateError> {
        let specs = self.model.params();
        let bounds: Vec<(f64, f64)> = match &self.bounds {
            Some(b) => b.clone(),
            None => specs.iter().map(|p| p.search).collect(),
        };
        if bounds.len() != specs.len() {
            return Err(EstimateError::Settings(format!(
                "model {} has {} parameters but {} bounds were given",
                self.model,
                specs.len(),
                bounds.len()
            )));
        }
        check_bounds(self.model, &bounds)?;
        Ok(bounds)
    }

    /// Check the chosen method's settings (the first one out of range is the error) and that the
    /// exact method is asked for Stenman only. [`estimate`] checks them too; a front end may check
    /// them before it reads any data.
    pub fn check_settings(&self) -> Result<(), EstimateError> {
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
        match method {
            Method::Aco => {
                let s = &self.aco;
                check(s.ants >= 1, "ants", AT_LEAST_1, s.ants as f64)?;
                check(
                    s.iterations >= 1,
                    "iterations",
                    AT_LEAST_1,
                    s.iterations as f64,
                )?;
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
                check(s.ants >= 1, "ants", AT_LEAST_1, s.ants as f64)?;
                check(
                    s.iterations >= 1,
                    "iterations",
                    AT_LEAST_1,
                    s.iterations as f64,
                )?;
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

/// How the interval of equally good parameter values was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntervalKind {
    /// Proven: every value in it reaches the least error (the exact Stenman solver).
    Exact,
    /// Exact near the best points of a scan, not over the whole range.
    ExactLocal,
    /// Exact on the staged search's short list of structures.
    ExactStaged,
    /// The hull of the grid points at the minimum.
    Grid,
    /// Along each parameter's axis with the others held at the estimate.
    Axis,
    /// No interval (random searches).
    None,
}

/// The result of an estimation, shared by every front end.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The model fitted.
    pub model: ModelKind,
    /// The method used.
    pub method: Method,
    /// Point estimate per parameter.
    pub params: BTreeMap<String, f64>,
    /// Per parameter, the set of equally optimal values `[lo, hi]`, where the method can know it
    /// (exact: proven; grid: the hull of the grid points that reach the minimum). Empty otherwise.
    pub interval: BTreeMap<String, [f64; 2]>,
    /// How `interval` was obtained: exact, grid or none.
    pub interval_kind: IntervalKind,
    /// Exact method: the optimal set as disjoint half-open pieces [lo, hi) when it is not one piece.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pieces: Option<Vec<[f64; 2]>>,
    /// Sum of squared errors between measured and modelled valve position.
    pub sse: f64,
    /// Root mean square error, same units as mv.
    pub rmse: f64,
    /// Fit quality 1 - SSE / sum (mv - mean)^2.
    pub r2: f64,
    /// Objective evaluations (for the exact method, those of its initial bound).
    pub evaluations: u64,
    /// Iterations run (population methods), cells created (exact), 1 (grid).
    pub iterations: u64,
    /// Time spent estimating, excluding reading the data.
    pub seconds: f64,
    /// Samples fitted.
    pub samples: usize,
    /// Search range per parameter.
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// The seed used (random searches only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Stenman with a non-exact method: the proven optimal set, and whether the estimate is in it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub certificate: Option<Certificate>,
    /// Caveats: a wide optimal set, an estimate outside the proven optimum, a parameter on its
    /// bound.
    pub warnings: Vec<String>,
    /// The per-iteration trace, when requested (population methods).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub trace: Vec<TraceRow>,
}

/// A check of a heuristic's answer against the exact optimum (Stenman only).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Certificate {
    /// The hull of the proven optimal set of d, `[lo, hi]`.
    pub optimal_interval: [f64; 2],
    /// The least fit error (sum of squares).
    pub optimal_sse: f64,
    /// Whether the heuristic's d lies in the optimal set.
    pub estimate_is_optimal: bool,
}

/// Check the data an estimation needs: equal lengths, finite values, enough samples, a moving command.
pub fn check_data(op: &[f64], mv: &[f64]) -> Result<(), EstimateError> {
    check_pair(("op", op), ("mv", mv))?;
    if op.len() < MIN_SAMPLES {
        return Err(EstimateError::Data(format!(
            "only {} samples; at least {MIN_SAMPLES} are needed",
            op.len()
        )));
    }
    let (lo, hi) = op
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi - lo <= 0.0 {
        return Err(EstimateError::Data(format!(
            "the command op is constant ({lo}); a valve that is never moved shows no stiction"
        )));
    }
    Ok(())
}

/// Two series of the same length holding only finite numbers.
pub fn check_pair(
    (a_name, a): (&str, &[f64]),
    (b_name, b): (&str, &[f64]),
) -> Result<(), EstimateError> {
    if a.len() != b.len() {
        return Err(EstimateError::Data(format!(
            "{a_name} has {} samples but {b_name} has {}",
            a.len(),
            b.len()
        )));
    }
    for (name, s) in [(a_name, a), (b_name, b)] {
        if let Some(i) = s.iter().position(|v| !v.is_finite()) {
            return Err(EstimateError::Data(format!(
                "{name} sample {i} is {}; every value must be a finite number",
                s[i]
            )));
        }
    }
    Ok(())
}

/// Search ranges, one per parameter: finite, not below the parameter's minimum, not reversed.
pub fn check_bounds(model: ModelKind, bounds: &[(f64, f64)]) -> Result<(), EstimateError> {
    let specs = model.params();
    if bounds.len() != specs.len() {
        return Err(EstimateError::Settings(format!(
            "model {model} has {} parameters but {} bounds were given",
            specs.len(),
            bounds.len()
        )));
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

/// Run an estimation.
///
/// The paper's case: a Stenman valve of band d = 0.5 driven by a sine, its band recovered by the
/// exact solver, which proves the optimum:
///
/// ```
/// use stiction_core::{estimate, Method, ModelKind, Request};
/// use stiction_core::models::{Model, Stenman};
///
/// let op: Vec<f64> = (0..500).map(|k| 3.0 * (k as f64 * 0.05).sin()).collect();
/// let mv = Model::Stenman(Stenman::new(0.5)?).simulate(&op);
/// let e = estimate(&op, &mv, &Request::new(ModelKind::Stenman, Method::Exact))?;
/// let [lo, hi] = e.interval["d"];
/// assert!(lo <= 0.5 && 0.5 <= hi && e.sse == 0.0);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn estimate(op: &[f64], mv: &[f64], req: &Request) -> Result<Estimate, EstimateError> {
    check_data(op, mv)?;
    req.check_settings()?;
    let bounds = req.resolved_bounds()?;
    let names = req.model.param_names();
    let started = Instant::now();
    let found = search(op, mv, req, &bounds);
    let certificate = certify(op, mv, req, &bounds, &found.best);
    let seconds = started.elapsed().as_secs_f64();

    let n = mv.len() as f64;
    let mean = mv.iter().sum::<f64>() / n;
    let sst: f64 = mv.iter().map(|v| (v - mean) * (v - mean)).sum();
    let warnings = warnings(req, &bounds, &found, certificate.as_ref());
    let sse = found.sse;
    Ok(Estimate {
        model: req.model,
        method: req.method,
        params: names
            .iter()
            .zip(&found.best)
            .map(|(n, &v)| (n.to_string(), v))
            .collect(),
        interval: found.interval,
        interval_kind: found.interval_kind,
        pieces: found.pieces,
        sse,
        rmse: (sse / n).sqrt(),
        r2: if sst > 0.0 { 1.0 - sse / sst } else { f64::NAN },
        evaluations: found.evaluations,
        iterations: found.iterations,
        seconds,
        samples: op.len(),
        bounds: names
            .iter()
            .zip(&bounds)
            .map(|(n, &(lo, hi))| (n.to_string(), [lo, hi]))
            .collect(),
        seed: found.seed,
        certificate,
        warnings,
        trace: found.trace,
    })
}

/// What one method found: the best parameters, their error, and what the method knows of the
/// values that fit equally well.
struct Found {
    best: Vec<f64>,
    sse: f64,
    evaluations: u64,
    iterations: u64,
    interval: BTreeMap<String, [f64; 2]>,
    interval_kind: IntervalKind,
    pieces: Option<Vec<[f64; 2]>>,
    seed: Option<u64>,
    trace: Vec<TraceRow>,
}

/// Run the requested method over the resolved bounds.
fn search(op: &[f64], mv: &[f64], req: &Request, bounds: &[(f64, f64)]) -> Found {
    let names = req.model.param_names();
    let objective = Objective::new(req.model, op, mv);
    let mut found = Found {
        best: Vec::new(),
        sse: f64::INFINITY,
        evaluations: 0,
        iterations: 0,
        interval: BTreeMap::new(),
        interval_kind: IntervalKind::None,
        pieces: None,
        seed: None,
        trace: Vec::new(),
    };
    match req.method {
        Method::Exact => {
            let (lo, hi) = bounds[0];
            let sol = exact::solve_stenman(op, mv, lo, hi, &req.exact);
            let (a, b) = sol.hull();
            found.interval.insert(names[0].to_string(), [a, b]);
            found.interval_kind = IntervalKind::Exact;
            if sol.pieces.len() > 1 {
                found.pieces = Some(sol.pieces.iter().map(|&(a, b)| [a, b]).collect());
            }
            found.best = vec![sol.point()];
            found.sse = sol.sse;
            found.evaluations = sol.bound_evaluations;
            found.iterations = sol.cells_created;
        }
        Method::Grid => {
            let g = grid::search(&objective, bounds, &req.grid);
            for (p, name) in names.iter().enumerate() {
                found.interval.insert(
                    name.to_string(),
                    [g.minimisers_hull[p].0, g.minimisers_hull[p].1],
                );
            }
            found.interval_kind = IntervalKind::Grid;
            (found.best, found.sse, found.evaluations) = (g.best, g.sse, g.evaluations);
            found.iterations = 1;
        }
        Method::Aco | Method::AcoR => {
            found.seed = Some(req.seed);
            let mut rng = seeded(req.seed);
            let mut ev = solver::Evaluator::new(&objective);
            let iters = if req.method == Method::Aco {
                let mut s = aco::PaperAco::new(req.aco.clone(), req.model, bounds);
                found.trace = solver::run(&mut s, &mut ev, &mut rng, req.aco.iterations, req.trace);
                req.aco.iterations
            } else {
                let mut s = acor::Acor::new(req.acor.clone(), req.model, bounds);
                found.trace =
                    solver::run(&mut s, &mut ev, &mut rng, req.acor.iterations, req.trace);
                req.acor.iterations
            };
            found.best = ev.best().to_vec();
            found.sse = ev.best_cost();
            found.evaluations = ev.evaluations();
            found.iterations = iters as u64;
        }
    }
    found
}

/// A search method's Stenman estimate held against the exact solver's proven optimum, when asked.
fn certify(
    op: &[f64],
    mv: &[f64],
    req: &Request,
    bounds: &[(f64, f64)],
    best: &[f64],
) -> Option<Certificate> {
    if !(req.certify && req.model == ModelKind::Stenman && req.method != Method::Exact) {
        return None;
    }
    let (lo, hi) = bounds[0];
    let sol = exact::solve_stenman(op, mv, lo, hi, &req.exact);
    Some(Certificate {
        optimal_interval: [sol.hull().0, sol.hull().1],
        optimal_sse: sol.sse,
        estimate_is_optimal: sol.contains(best[0]),
    })
}

/// A wide optimal set, an estimate outside the proven optimum, a parameter on its bound.
fn warnings(
    req: &Request,
    bounds: &[(f64, f64)],
    found: &Found,
    certificate: Option<&Certificate>,
) -> Vec<String> {
    let names = req.model.param_names();
    let mut warnings = Vec::new();
    if req.method == Method::Exact {
        let [a, b] = found.interval[names[0]];
        let mid = 0.5 * (a + b);
        if mid > 0.0 && (b - a) > 0.2 * mid {
            warnings.push(format!(
                "the optimal set [{a:.4}, {b:.4}] is wide relative to d: the command does not \
                 excite the valve enough to pin d down"
            ));
        }
    }
    if let Some(c) = certificate {
        if !c.estimate_is_optimal {
            warnings.push(format!(
                "the estimate is not in the proven optimal set [{:.4}, {:.4}] (SSE {:.6} vs {:.6})",
                c.optimal_interval[0], c.optimal_interval[1], found.sse, c.optimal_sse
            ));
        }
    }
    let edge_tol = |lo: f64, hi: f64| match req.method {
        Method::Aco => 0.5 * req.aco.resolution,
        _ => 1e-9 * (hi - lo),
    };
    for (p, &(lo, hi)) in bounds.iter().enumerate() {
        let v = found.best[p];
        let at_lower = lo > 0.0 && v - lo <= edge_tol(lo, hi);
        let at_upper = hi - v <= edge_tol(lo, hi);
        if at_lower || at_upper {
            warnings.push(format!(
                "{} = {v} is at the edge of its search range [{lo}, {hi}]: widen the bounds",
                names[p]
            ));
        }
    }
    warnings
}
