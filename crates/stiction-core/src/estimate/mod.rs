//! Estimating stiction parameters from the command (op) and the valve position (mv): the paper's
//! problem. A [`Request`] is checked once, when built ([`Request::check`]); [`estimate_checked`]
//! runs the chosen method and returns a serde result that every front end prints its own way.

pub mod aco;
pub mod acor;
pub mod exact;
pub mod grid;
pub mod objective;
mod request;
mod result;
pub mod solver;

use crate::checked::Checked;
use crate::models::ModelKind;
use crate::rng::seeded;
use std::collections::BTreeMap;
use std::time::Instant;

pub use aco::AcoSettings;
pub use acor::AcorSettings;
pub use exact::{ExactSettings, ExactSolution};
pub use grid::GridSettings;
pub use objective::Objective;
pub use request::{
    check_bounds, check_data, check_pair, EstimateError, Method, Request, MIN_SAMPLES,
};
pub use result::{Certificate, Estimate, IntervalKind};
pub use solver::TraceRow;

/// Check the request and run the estimation: [`Request::check`], then [`estimate_checked`].
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
    estimate_checked(op, mv, &req.check()?)
}

/// Run a checked request's estimation (the data are checked here: lengths, finite values, enough
/// samples, a moving command).
pub fn estimate_checked(
    op: &[f64],
    mv: &[f64],
    req: &Checked<Request>,
) -> Result<Estimate, EstimateError> {
    check_data(op, mv)?;
    let bounds = req.search_range();
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
