//! Brute-force grid search: the baseline every other method is checked against.

use super::objective::Objective;
use serde::{Deserialize, Serialize};

/// Settings of the grid search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GridSettings {
    /// Points per parameter, ends included (a two-parameter model evaluates points^2 candidates).
    pub points: usize,
}

impl Default for GridSettings {
    fn default() -> Self {
        Self { points: 1000 }
    }
}

/// What the grid search found.
pub struct GridResult {
    /// The best grid point, one value per parameter.
    pub best: Vec<f64>,
    /// Its fit error (sum of squares).
    pub sse: f64,
    /// Per parameter, the hull of the grid points whose cost equals the minimum.
    pub minimisers_hull: Vec<(f64, f64)>,
    /// Candidates evaluated.
    pub evaluations: u64,
}

/// Evaluate every point of a grid over `bounds` (one `(lo, hi)` per parameter; two-parameter grids
/// capped at 400 points per axis) and return the best.
pub fn search(obj: &Objective, bounds: &[(f64, f64)], settings: &GridSettings) -> GridResult {
    let dim = bounds.len();
    // two-parameter grids are points^2: cap the default so a plain `--method grid` stays quick
    let per_dim = if dim == 1 {
        settings.points
    } else {
        settings.points.min(400)
    };
    let axes: Vec<Vec<f64>> = bounds
        .iter()
        .map(|&(lo, hi)| {
            (0..per_dim)
                .map(|i| lo + (hi - lo) * i as f64 / (per_dim - 1) as f64)
                .collect()
        })
        .collect();
    let total = axes.iter().map(Vec::len).product::<usize>();
    let mut cands = Vec::with_capacity(total * dim);
    let mut idx = vec![0usize; dim];
    for _ in 0..total {
        let start = cands.len();
        for p in 0..dim {
            cands.push(axes[p][idx[p]]);
        }
        obj.kind.repair(&mut cands[start..]);
        // odometer over the axes, last parameter fastest
        for p in (0..dim).rev() {
            idx[p] += 1;
            if idx[p] < per_dim {
                break;
            }
            idx[p] = 0;
        }
    }
    let mut costs = vec![0.0; total];
    obj.eval_batch(&cands, &mut costs);
    let mut best_i = 0;
    for (i, &c) in costs.iter().enumerate() {
        if c < costs[best_i] {
            best_i = i;
        }
    }
    let sse = costs[best_i];
    let mut hull = vec![(f64::INFINITY, f64::NEG_INFINITY); dim];
    for (i, &c) in costs.iter().enumerate() {
        if c == sse {
            for p in 0..dim {
                let v = cands[i * dim + p];
                hull[p] = (hull[p].0.min(v), hull[p].1.max(v));
            }
        }
    }
    GridResult {
        best: cands[best_i * dim..(best_i + 1) * dim].to_vec(),
        sse,
        minimisers_hull: hull,
        evaluations: total as u64,
    }
}
