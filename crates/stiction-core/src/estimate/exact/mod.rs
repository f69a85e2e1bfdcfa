//! The exact solver for Stenman's model: a partition of the d-range into cells on which the whole
//! simulated valve trajectory is identical, with branch and bound.
//!
//! The Stenman valve at step t slips iff `d < |u[t] - x[t-1]|`, so the trajectory depends on d only
//! through such comparisons. Starting from one cell `[lo, hi)` with state `x[0] = u[0]`, each step
//! either moves a whole cell (all stick, or all slip) or splits it at `delta = |u[t] - x|` into a
//! slipping part `[lo, delta)` and a sticking part `[delta, hi)`. Each cell carries its fit error so
//! far; costs only grow, so a cell whose cost exceeds an achievable cost (the best of a coarse grid)
//! can never be optimal and is dropped. At the end the cells of least cost are exactly the set of
//! optimal d, reported as half-open pieces `[lo, hi)`.
//!
//! A cell's cost is summed in the same order as [`super::objective`] sums a single d, so the two
//! agree to the last bit and the bound can be compared exactly.

mod walk;

pub use walk::{stenman_cell_into, stenman_walk, stenman_walk_changes};

use super::objective::Objective;
use crate::models::ModelKind;
use serde::{Deserialize, Serialize};

/// Settings of the exact Stenman solver's initial bound.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExactSettings {
    /// Points of the grid whose best cost is the initial bound.
    pub bound_grid: usize,
    /// Rounds of that grid, each zoomed around the previous round's best point.
    pub bound_rounds: usize,
}

impl Default for ExactSettings {
    fn default() -> Self {
        Self {
            bound_grid: 256,
            bound_rounds: 3,
        }
    }
}

/// The whole optimal set of d and its fit error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExactSolution {
    /// Disjoint half-open pieces `[lo, hi)` whose union is the optimal set, sorted.
    pub pieces: Vec<(f64, f64)>,
    /// Fit error (sum of squares) of every d in the optimal set.
    pub sse: f64,
    /// Largest number of live cells at any step.
    pub cells_peak: usize,
    /// Cells created over the run (splits + 1).
    pub cells_created: u64,
    /// Objective evaluations spent on the initial bound.
    pub bound_evaluations: u64,
}

impl ExactSolution {
    /// Smallest and largest optimal d.
    pub fn hull(&self) -> (f64, f64) {
        (self.pieces[0].0, self.pieces[self.pieces.len() - 1].1)
    }

    /// A point estimate: the midpoint of the widest piece.
    pub fn point(&self) -> f64 {
        let (lo, hi) = self
            .pieces
            .iter()
            .copied()
            .max_by(|a, b| (a.1 - a.0).total_cmp(&(b.1 - b.0)))
            .expect("an exact solution has at least one piece");
        0.5 * (lo + hi)
    }

    /// Is `d` in the optimal set?
    pub fn contains(&self, d: f64) -> bool {
        self.pieces.iter().any(|&(lo, hi)| lo <= d && d < hi)
    }
}

/// Solve `min_d sum (mv - stenman_d(op))^2` over `d in [lo, hi)` exactly.
pub fn solve_stenman(
    op: &[f64],
    mv: &[f64],
    lo: f64,
    hi: f64,
    settings: &ExactSettings,
) -> ExactSolution {
    assert!(!op.is_empty() && op.len() == mv.len());
    assert!(lo < hi);

    // An achievable cost as tight as we can get it cheaply: a coarse grid, then zoom in around
    // its best point a few times (many candidates per pass over the data). Any achievable cost is
    // a valid bound; the tighter it is, the sooner wrong cells are dropped.
    let g = settings.bound_grid.max(2);
    let objective = Objective::new(ModelKind::Stenman, op, mv);
    let mut grid = vec![0.0; g];
    let mut costs = vec![0.0; g];
    let (mut a, mut b) = (lo, hi);
    let mut bound = f64::INFINITY;
    let mut evaluations = 0u64;
    for _ in 0..settings.bound_rounds.max(1) {
        for (i, v) in grid.iter_mut().enumerate() {
            *v = a + (b - a) * (i as f64 + 0.5) / g as f64;
        }
        objective.eval_batch(&grid, &mut costs);
        evaluations += g as u64;
        let best = (0..g).fold(0, |m, i| if costs[i] < costs[m] { i } else { m });
        bound = bound.min(costs[best]);
        let step = (b - a) / g as f64;
        (a, b) = ((grid[best] - step).max(lo), (grid[best] + step).min(hi));
    }
    // a hair above, for safety; identical summation order makes the costs agree exactly anyway
    let bound = bound + bound.abs() * 1e-12;

    let e0 = mv[0] - op[0];
    let mut cells = Cells::default();
    cells.push(lo, hi, op[0], e0 * e0);
    let mut peak = 1;
    let mut created = 1u64;
    let mut born = Cells::default();

    for (&u, &y) in op[1..].iter().zip(&mv[1..]) {
        let n = cells.len();
        let mut w = 0;
        for i in 0..n {
            let (clo, chi, x, cost) = (cells.lo[i], cells.hi[i], cells.x[i], cells.cost[i]);
            let delta = (u - x).abs();
            let stuck = y - x;
            let slip = y - u;
            let (new_hi, new_x, new_cost) = if delta <= clo {
                (chi, x, cost + stuck * stuck)
            } else if delta >= chi {
                (chi, u, cost + slip * slip)
            } else {
                // split: [delta, hi) sticks, [lo, delta) slips
                let stick_cost = cost + stuck * stuck;
                if stick_cost <= bound {
                    born.push(delta, chi, x, stick_cost);
                }
                created += 1;
                (delta, u, cost + slip * slip)
            };
            if new_cost <= bound {
                cells.lo[w] = clo;
                cells.hi[w] = new_hi;
                cells.x[w] = new_x;
                cells.cost[w] = new_cost;
                w += 1;
            }
        }
        cells.truncate(w);
        cells.append(&mut born);
        peak = peak.max(cells.len());
    }

    let best = cells.cost.iter().copied().fold(f64::INFINITY, f64::min);
    let mut optimal: Vec<(f64, f64)> = (0..cells.len())
        .filter(|&i| cells.cost[i] == best)
        .map(|i| (cells.lo[i], cells.hi[i]))
        .collect();
    optimal.sort_by(|a, b| a.0.total_cmp(&b.0));
    // merge touching pieces
    let mut pieces: Vec<(f64, f64)> = Vec::with_capacity(optimal.len());
    for (a, b) in optimal {
        match pieces.last_mut() {
            Some(last) if last.1 >= a => last.1 = last.1.max(b),
            _ => pieces.push((a, b)),
        }
    }
    ExactSolution {
        pieces,
        sse: best,
        cells_peak: peak,
        cells_created: created,
        bound_evaluations: evaluations,
    }
}

/// Cells as a structure of arrays (the hot loop touches every field of every cell each step).
#[derive(Default)]
struct Cells {
    lo: Vec<f64>,
    hi: Vec<f64>,
    x: Vec<f64>,
    cost: Vec<f64>,
}

impl Cells {
    fn len(&self) -> usize {
        self.lo.len()
    }
    fn push(&mut self, lo: f64, hi: f64, x: f64, cost: f64) {
        self.lo.push(lo);
        self.hi.push(hi);
        self.x.push(x);
        self.cost.push(cost);
    }
    fn truncate(&mut self, n: usize) {
        self.lo.truncate(n);
        self.hi.truncate(n);
        self.x.truncate(n);
        self.cost.truncate(n);
    }
    fn append(&mut self, other: &mut Cells) {
        self.lo.append(&mut other.lo);
        self.hi.append(&mut other.hi);
        self.x.append(&mut other.x);
        self.cost.append(&mut other.cost);
    }
}
