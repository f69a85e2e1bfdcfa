//! The searches for models without an exact solver: a grid, and polishing an ACO answer; and the
//! stretch along each axis over which the (step-function) objective stays at its optimum.

use super::problem::{range, Hammerstein};
use super::search::Outcome;
use crate::estimate::solver::CostFunction;
use crate::estimate::{GridSettings, IntervalKind};
use std::collections::BTreeMap;

/// Polish a two-parameter answer by coordinate scans: each parameter in turn over a fine grid
/// around its value (the objective is a step function, so gradients cannot do this), narrowing
/// three times.
pub(super) fn polish(
    problem: &Hammerstein,
    start: &[f64],
    cost: f64,
    bounds: &[(f64, f64)],
) -> (Vec<f64>, f64, u64) {
    const POINTS: usize = 161;
    let mut best = start.to_vec();
    let mut best_cost = cost;
    let mut evals = 0u64;
    let dim = best.len();
    for round in 0..3 {
        for p in 0..dim {
            let (lo, hi) = bounds[p];
            let width = 0.5f64.powi(round) * 0.5 * best[p].abs().max(0.05 * (hi - lo));
            let (a, b) = ((best[p] - width).max(lo), (best[p] + width).min(hi));
            let mut cands = Vec::with_capacity(POINTS * dim);
            for i in 0..POINTS {
                let mut theta = best.clone();
                theta[p] = a + (b - a) * i as f64 / (POINTS - 1) as f64;
                problem.kind.repair(&mut theta);
                cands.extend_from_slice(&theta);
            }
            let mut costs = vec![0.0; POINTS];
            problem.eval_batch(&cands, &mut costs);
            evals += POINTS as u64;
            for (i, &c) in costs.iter().enumerate() {
                if c < best_cost {
                    best_cost = c;
                    best.copy_from_slice(&cands[i * dim..(i + 1) * dim]);
                }
            }
        }
    }
    (best, best_cost, evals)
}

pub(super) fn grid_search(
    problem: &Hammerstein,
    bounds: &[(f64, f64)],
    settings: &GridSettings,
) -> Outcome {
    let dim = bounds.len();
    let per = settings.points.max(2);
    let axes: Vec<Vec<f64>> = bounds
        .iter()
        .map(|&(lo, hi)| {
            (0..per)
                .map(|i| lo + (hi - lo) * i as f64 / (per - 1) as f64)
                .collect()
        })
        .collect();
    let total = per.pow(dim as u32);
    let mut cands = Vec::with_capacity(total * dim);
    for i in 0..total {
        let start = cands.len();
        let mut rest = i;
        for axis in axes.iter().rev() {
            cands.push(axis[rest % per]);
            rest /= per;
        }
        cands[start..].reverse();
        problem.kind.repair(&mut cands[start..]);
    }
    let mut costs = vec![0.0; total];
    problem.eval_batch(&cands, &mut costs);
    let best_i = (0..total).fold(0, |m, i| if costs[i] < costs[m] { i } else { m });
    let best = cands[best_i * dim..(best_i + 1) * dim].to_vec();
    let mut interval = BTreeMap::new();
    for (p, name) in problem.kind.param_names().iter().enumerate() {
        let vals: Vec<f64> = (0..total)
            .filter(|&i| costs[i] == costs[best_i])
            .map(|i| cands[i * dim + p])
            .collect();
        let (a, b) = range(&vals);
        interval.insert(name.to_string(), [a, b]);
    }
    Outcome {
        best,
        interval,
        interval_kind: IntervalKind::Grid,
        evaluations: total as u64,
        cells: None,
        top_cells: Vec::new(),
    }
}

/// Along each axis from the estimate, the stretch over which the cost stays at the optimum
/// (the objective is a step function of the stiction parameters): doubling steps out, then bisection.
pub(super) fn axis_intervals(
    problem: &Hammerstein,
    best: &[f64],
    bounds: &[(f64, f64)],
    best_cost: f64,
) -> (BTreeMap<String, [f64; 2]>, u64) {
    let mut out = BTreeMap::new();
    let mut evals = 0u64;
    let names = problem.kind.param_names();
    for (p, &(lo, hi)) in bounds.iter().enumerate() {
        let mut ends = [best[p]; 2];
        for (side, end) in ends.iter_mut().enumerate() {
            let limit = if side == 0 { lo } else { hi };
            let at = |v: f64| {
                let mut theta = best.to_vec();
                theta[p] = v;
                problem.kind.repair(&mut theta);
                // a repair that moves another parameter leaves this axis
                (theta[p] == v).then(|| problem.cost(&theta))
            };
            let same = |c: Option<f64>| c.is_some_and(|c| c <= best_cost);
            // step out until the cost changes or the bound is reached
            let mut inside = best[p];
            let mut step = 1e-4 * (hi - lo);
            let mut outside = None;
            for _ in 0..40 {
                let v = if side == 0 {
                    (inside - step).max(limit)
                } else {
                    (inside + step).min(limit)
                };
                evals += 1;
                if same(at(v)) {
                    inside = v;
                    if v == limit {
                        break;
                    }
                    step *= 2.0;
                } else {
                    outside = Some(v);
                    break;
                }
            }
            if let Some(mut out_v) = outside {
                for _ in 0..30 {
                    let mid = 0.5 * (inside + out_v);
                    evals += 1;
                    if same(at(mid)) {
                        inside = mid;
                    } else {
                        out_v = mid;
                    }
                }
            }
            *end = inside;
        }
        out.insert(names[p].to_string(), ends);
    }
    (out, evals)
}
