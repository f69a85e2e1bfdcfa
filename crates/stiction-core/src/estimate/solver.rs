//! The pieces every population solver shares, in the shape of argmin: the problem (an
//! [`Objective`](super::Objective) behind an [`Evaluator`] that counts evaluations and keeps the best), the solver
//! (one `next_iter` at a time), the executor ([`run`]: budget and seed) and observers (the
//! per-iteration trace the paper plots).

use crate::rng::Rng;
use serde::{Deserialize, Serialize};

/// A cost to minimise over a box of parameters, evaluated a whole population at a time (the one
/// place where batching and threads live).
pub trait CostFunction: Sync {
    /// Parameters per candidate.
    fn dim(&self) -> usize;
    /// Costs of `candidates` (flat, `dim` values each) into `costs`.
    fn eval_batch(&self, candidates: &[f64], costs: &mut [f64]);
}

impl CostFunction for super::objective::Objective<'_> {
    fn dim(&self) -> usize {
        self.kind.dim()
    }
    fn eval_batch(&self, candidates: &[f64], costs: &mut [f64]) {
        super::objective::Objective::eval_batch(self, candidates, costs)
    }
}

/// Wraps the cost: solvers hand it whole populations, it counts and remembers the best.
pub struct Evaluator<'a> {
    objective: &'a dyn CostFunction,
    evaluations: u64,
    best: Vec<f64>,
    best_cost: f64,
}

impl<'a> Evaluator<'a> {
    /// Wraps `objective`, with no evaluation and no best yet.
    pub fn new(objective: &'a dyn CostFunction) -> Self {
        Self {
            best: vec![f64::NAN; objective.dim()],
            objective,
            evaluations: 0,
            best_cost: f64::INFINITY,
        }
    }

    /// Parameters per candidate.
    pub fn dim(&self) -> usize {
        self.objective.dim()
    }

    /// Evaluate a population (flat, `dim` values per candidate) into `costs`.
    pub fn eval_batch(&mut self, candidates: &[f64], costs: &mut [f64]) {
        self.objective.eval_batch(candidates, costs);
        self.evaluations += costs.len() as u64;
        let dim = self.dim();
        // first strict improvement wins: ties keep the earlier candidate, so the result is
        // deterministic
        for (i, &c) in costs.iter().enumerate() {
            if c < self.best_cost {
                self.best_cost = c;
                self.best
                    .copy_from_slice(&candidates[i * dim..(i + 1) * dim]);
            }
        }
    }

    /// Candidates evaluated so far.
    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }
    /// The best candidate so far (NaN before the first evaluation).
    pub fn best(&self) -> &[f64] {
        &self.best
    }
    /// The best candidate's cost (infinity before the first evaluation).
    pub fn best_cost(&self) -> f64 {
        self.best_cost
    }
}

/// What one iteration found.
#[derive(Debug, Clone)]
pub struct IterationBest {
    /// The iteration's best parameters.
    pub params: Vec<f64>,
    /// Their cost.
    pub cost: f64,
}

/// A population solver: `init` then repeated `next_iter`.
pub trait Solver {
    /// Set up the first population.
    fn init(&mut self, ev: &mut Evaluator, rng: &mut Rng);
    /// Run one iteration and return its best.
    fn next_iter(&mut self, ev: &mut Evaluator, rng: &mut Rng) -> IterationBest;
}

/// One row of the convergence trace: per iteration, the best so far and the iteration's best.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TraceRow {
    /// Iteration, from 1.
    pub iteration: usize,
    /// The best parameters so far.
    pub best: Vec<f64>,
    /// Their fit error (sum of squares).
    pub best_sse: f64,
    /// The iteration's best parameters.
    pub iteration_best: Vec<f64>,
    /// Their fit error (sum of squares).
    pub iteration_best_sse: f64,
    /// Evaluations so far.
    pub evaluations: u64,
}

/// Run `iterations` steps of a solver, recording the trace when asked.
pub fn run<S: Solver>(
    solver: &mut S,
    ev: &mut Evaluator,
    rng: &mut Rng,
    iterations: usize,
    record: bool,
) -> Vec<TraceRow> {
    solver.init(ev, rng);
    let mut trace = Vec::with_capacity(if record { iterations } else { 0 });
    for iteration in 1..=iterations {
        let it = solver.next_iter(ev, rng);
        if record {
            trace.push(TraceRow {
                iteration,
                best: ev.best().to_vec(),
                best_sse: ev.best_cost(),
                iteration_best: it.params,
                iteration_best_sse: it.cost,
                evaluations: ev.evaluations(),
            });
        }
    }
    trace
}
