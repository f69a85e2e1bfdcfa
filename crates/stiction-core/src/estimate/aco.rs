//! The paper's ant colony optimisation: the classic Ant System over a discretised parameter range.
//!
//! - each parameter's range `[lo, hi]` is a grid of nodes spaced `resolution` apart (the paper:
//!   d from 0.01 up to 10, so 1000 nodes at 0.01); one pheromone vector per parameter;
//! - every iteration each of the `ants` picks one node per parameter with probability proportional
//!   to its pheromone (the first iteration, with uniform pheromone `tau0`, is a uniform random start);
//! - then `tau <- (1 - rho) tau + sum_k Q / (L_k + epsilon)` on the node of each ant k (eq. 3-4),
//!   and the best-so-far solution gets the extra elitist deposit `D / (T_op + epsilon)` (eq. 6);
//! - before the update the iteration's best ant does a local search ("after performing local
//!   searching, the pheromone table is updated", section 4.2.3): it moves to a neighbouring node
//!   while that strictly lowers its fit error, at most `local_search` moves per iteration. A flat
//!   grid has no notion of neighbourhood otherwise, and without it the colony stagnates on the first
//!   good nodes it visits; `local_search = 0` is the plain Ant System;
//! - after `iterations`, the best solution found is returned.
//!
//! `epsilon` guards the division: the fit error L is exactly zero at a perfect fit.

use super::solver::{Evaluator, IterationBest, Solver};
use crate::models::ModelKind;
use crate::rng::Rng;
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// Settings of the paper's ACO (Ant System on a grid of nodes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcoSettings {
    /// Ants per iteration.
    pub ants: usize,
    /// Iterations.
    pub iterations: usize,
    /// Evaporation rate rho.
    pub rho: f64,
    /// Pheromone quantity Q.
    pub q: f64,
    /// Encouragement coefficient D of the elitist deposit on the best-so-far solution.
    pub elitist: f64,
    /// Spacing of the nodes of each parameter's grid.
    pub resolution: f64,
    /// Initial pheromone on every node. Large against the deposits Q / L, so the colony keeps
    /// exploring the whole range for its first few dozen iterations before it settles.
    pub tau0: f64,
    /// Guard added to the fit error before dividing.
    pub epsilon: f64,
    /// Most neighbour moves of the iteration's best ant per iteration (0: none).
    pub local_search: usize,
}

impl Default for AcoSettings {
    /// The paper's settings (20 ants, 100 iterations, rho 0.2, Q 100); D, tau0, epsilon and the
    /// 0.01 node spacing are ours: the paper does not state them, nor the extent of its local search.
    fn default() -> Self {
        Self {
            ants: 20,
            iterations: 100,
            rho: 0.2,
            q: 100.0,
            elitist: 100.0,
            resolution: 0.01,
            tau0: 1e4,
            epsilon: 1e-9,
            local_search: 10,
        }
    }
}

/// The paper's ACO as a [`Solver`]: a pheromone vector over each parameter's grid of nodes.
pub struct PaperAco {
    settings: AcoSettings,
    kind: ModelKind,
    /// node values per parameter
    nodes: Vec<Vec<f64>>,
    pheromone: Vec<Vec<f64>>,
    /// best-so-far node index per parameter
    best_nodes: Vec<usize>,
    best_cost: f64,
    // scratch buffers, reused every iteration
    cumulative: Vec<f64>,
    picks: Vec<usize>,
    candidates: Vec<f64>,
    costs: Vec<f64>,
    neighbours: Vec<f64>,
    /// Nodes a local search already started from: searching them again finds nothing new.
    searched: std::collections::HashSet<Vec<usize>>,
}

impl PaperAco {
    /// A colony over `bounds` (one `(lo, hi)` per parameter of `kind`, in the model's parameter
    /// order), with uniform pheromone `tau0` on every node.
    pub fn new(settings: AcoSettings, kind: ModelKind, bounds: &[(f64, f64)]) -> Self {
        let nodes: Vec<Vec<f64>> = bounds
            .iter()
            .map(|&(lo, hi)| {
                let count = ((hi - lo) / settings.resolution + 1e-9).floor() as usize + 1;
                (0..count)
                    .map(|i| (lo + i as f64 * settings.resolution).min(hi))
                    .collect()
            })
            .collect();
        let pheromone = nodes.iter().map(|n| vec![settings.tau0; n.len()]).collect();
        let dim = bounds.len();
        Self {
            kind,
            nodes,
            pheromone,
            best_nodes: vec![0; dim],
            best_cost: f64::INFINITY,
            cumulative: Vec::new(),
            picks: vec![0; settings.ants * dim],
            candidates: vec![0.0; settings.ants * dim],
            costs: vec![0.0; settings.ants],
            neighbours: Vec::new(),
            searched: Default::default(),
            settings,
        }
    }

    /// Number of nodes of each parameter's grid.
    pub fn node_counts(&self) -> Vec<usize> {
        self.nodes.iter().map(Vec::len).collect()
    }
}

impl PaperAco {
    /// Local search of ant `a`: for each parameter, walk node by node in both directions while the
    /// fit error does not rise (the objective is a step function: walking across flat stretches is
    /// what finds the next step down), at most `local_search` nodes each way; the ant moves to the
    /// best node seen if it is strictly better.
    fn local_search(&mut self, a: usize, ev: &mut Evaluator) {
        let dim = self.nodes.len();
        let max_steps = self.settings.local_search;
        if max_steps == 0
            || !self
                .searched
                .insert(self.picks[a * dim..(a + 1) * dim].to_vec())
        {
            return;
        }
        for p in 0..dim {
            let start = self.picks[a * dim + p];
            let last = self.nodes[p].len() - 1;
            // per direction: (current node, its cost, still walking)
            let mut walk = [
                (start, self.costs[a], start > 0),
                (start, self.costs[a], start < last),
            ];
            let mut best: Option<(usize, f64)> = None;
            let mut best_params = [0.0; 8];
            for _ in 0..max_steps {
                self.neighbours.clear();
                let mut which = [0usize; 2];
                let mut count = 0;
                for (w, &(i, _, alive)) in walk.iter().enumerate() {
                    if alive {
                        let next = if w == 0 { i - 1 } else { i + 1 };
                        let at = self.neighbours.len();
                        self.neighbours
                            .extend_from_slice(&self.candidates[a * dim..(a + 1) * dim]);
                        self.neighbours[at + p] = self.nodes[p][next];
                        self.kind.repair(&mut self.neighbours[at..at + dim]);
                        which[count] = w;
                        count += 1;
                    }
                }
                if count == 0 {
                    break;
                }
                let mut costs = [0.0; 2];
                ev.eval_batch(&self.neighbours, &mut costs[..count]);
                for (k, &w) in which[..count].iter().enumerate() {
                    let (i, cost, _) = walk[w];
                    let next = if w == 0 { i - 1 } else { i + 1 };
                    let c = costs[k];
                    if c <= cost {
                        let bound = if w == 0 { next > 0 } else { next < last };
                        walk[w] = (next, c, bound);
                        if c < best.map_or(self.costs[a], |b| b.1) {
                            best = Some((next, c));
                            best_params[..dim]
                                .copy_from_slice(&self.neighbours[k * dim..(k + 1) * dim]);
                        }
                    } else {
                        walk[w].2 = false;
                    }
                }
            }
            if let Some((node, cost)) = best {
                self.picks[a * dim + p] = node;
                self.candidates[a * dim..(a + 1) * dim].copy_from_slice(&best_params[..dim]);
                self.costs[a] = cost;
            }
        }
    }
}

impl Solver for PaperAco {
    fn init(&mut self, _ev: &mut Evaluator, _rng: &mut Rng) {}

    fn next_iter(&mut self, ev: &mut Evaluator, rng: &mut Rng) -> IterationBest {
        let dim = self.nodes.len();
        let ants = self.settings.ants;
        // construct: each ant picks a node per parameter, proportional to pheromone
        for (p, tau) in self.pheromone.iter().enumerate() {
            self.cumulative.clear();
            let mut total = 0.0;
            for &t in tau {
                total += t;
                self.cumulative.push(total);
            }
            for a in 0..ants {
                let r = rng.random::<f64>() * total;
                let i = self.cumulative.partition_point(|&c| c <= r);
                let i = i.min(tau.len() - 1);
                self.picks[a * dim + p] = i;
                self.candidates[a * dim + p] = self.nodes[p][i];
            }
        }
        for a in 0..ants {
            self.kind
                .repair(&mut self.candidates[a * dim..(a + 1) * dim]);
        }
        ev.eval_batch(&self.candidates, &mut self.costs);

        // iteration best and best so far (first strict improvement wins)
        let mut it_best = 0;
        for a in 1..ants {
            if self.costs[a] < self.costs[it_best] {
                it_best = a;
            }
        }
        self.local_search(it_best, ev);
        if self.costs[it_best] < self.best_cost {
            self.best_cost = self.costs[it_best];
            self.best_nodes
                .copy_from_slice(&self.picks[it_best * dim..(it_best + 1) * dim]);
        }

        // pheromone update, eq. 4 with the deposits of eq. 3 and the elitist deposit of eq. 6
        let s = &self.settings;
        for (p, tau) in self.pheromone.iter_mut().enumerate() {
            for t in tau.iter_mut() {
                *t *= 1.0 - s.rho;
            }
            for a in 0..ants {
                tau[self.picks[a * dim + p]] += s.q / (self.costs[a] + s.epsilon);
            }
            tau[self.best_nodes[p]] += s.elitist / (self.best_cost + s.epsilon);
        }
        IterationBest {
            params: self.candidates[it_best * dim..(it_best + 1) * dim].to_vec(),
            cost: self.costs[it_best],
        }
    }
}
