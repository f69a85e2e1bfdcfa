//! Ant colony optimisation for continuous domains (ACO_R; Socha and Dorigo 2008).
//!
//! An archive of the `archive` best solutions sorted by fit error; member l (rank from 1) is chosen
//! with weight `exp(-(l-1)^2 / (2 q^2 k^2))`; each ant samples every coordinate from a Gaussian
//! centred on the chosen member with `sigma_i = xi * mean_e |s_e,i - s_l,i|`; the new solutions join
//! the archive and the worst are dropped. Samples outside the bounds are reflected back in.

use super::solver::{Evaluator, IterationBest, Solver};
use crate::models::ModelKind;
use crate::rng::{gaussian, Rng};
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// Settings of ACO_R.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AcorSettings {
    /// Archive size k.
    pub archive: usize,
    /// New solutions per iteration m.
    pub ants: usize,
    /// Iterations.
    pub iterations: usize,
    /// Locality of the search q (small: greedy around the best).
    pub q: f64,
    /// Speed of convergence xi (spread of the Gaussian kernels).
    pub xi: f64,
}

impl Default for AcorSettings {
    /// k = 50 and xi = 0.85 as published; q = 0.1 and 20 ants as in common ports (the published
    /// q = 1e-4 with m = 2 is tuned for smooth benchmark functions, not for our stepped objectives).
    fn default() -> Self {
        Self {
            archive: 50,
            ants: 20,
            iterations: 100,
            q: 0.1,
            xi: 0.85,
        }
    }
}

/// ACO_R as a [`Solver`]: an archive of the best solutions and Gaussian kernels around them.
pub struct Acor {
    settings: AcorSettings,
    kind: ModelKind,
    bounds: Vec<(f64, f64)>,
    /// archive solutions, flat, sorted by cost
    archive: Vec<f64>,
    archive_cost: Vec<f64>,
    weights_cumulative: Vec<f64>,
    new: Vec<f64>,
    new_cost: Vec<f64>,
    order: Vec<usize>,
    /// Known good solutions placed in the initial archive.
    seeds: Vec<Vec<f64>>,
}

impl Acor {
    /// A solver over `bounds` (one `(lo, hi)` per parameter of `kind`, in the model's parameter
    /// order); an archive below 2 is raised to 2.
    pub fn new(settings: AcorSettings, kind: ModelKind, bounds: &[(f64, f64)]) -> Self {
        let k = settings.archive.max(2);
        let q = settings.q;
        let mut acc = 0.0;
        let weights_cumulative = (0..k)
            .map(|l| {
                let l = l as f64;
                acc += (-(l * l) / (2.0 * q * q * (k * k) as f64)).exp();
                acc
            })
            .collect();
        let dim = bounds.len();
        Self {
            kind,
            bounds: bounds.to_vec(),
            archive: Vec::with_capacity((k + settings.ants) * dim),
            archive_cost: Vec::with_capacity(k + settings.ants),
            weights_cumulative,
            new: vec![0.0; settings.ants * dim],
            new_cost: vec![0.0; settings.ants],
            order: Vec::new(),
            seeds: Vec::new(),
            settings: AcorSettings {
                archive: k,
                ..settings
            },
        }
    }

    /// Start the archive from these solutions (and random ones for the rest).
    pub fn with_seeds(mut self, seeds: Vec<Vec<f64>>) -> Self {
        self.seeds = seeds;
        self
    }

    fn reflect(&self, p: usize, mut v: f64) -> f64 {
        let (lo, hi) = self.bounds[p];
        let width = hi - lo;
        if width <= 0.0 {
            return lo;
        }
        // fold into [lo, hi] by reflection
        let mut r = (v - lo).rem_euclid(2.0 * width);
        if r > width {
            r = 2.0 * width - r;
        }
        v = lo + r;
        v.clamp(lo, hi)
    }

    /// Merge new solutions into the archive and keep the k best (stable: ties keep older members).
    fn merge(&mut self, dim: usize) {
        let total = self.archive_cost.len();
        self.order.clear();
        self.order.extend(0..total);
        let costs = &self.archive_cost;
        self.order.sort_by(|&a, &b| costs[a].total_cmp(&costs[b]));
        let keep = self.settings.archive.min(total);
        let mut archive = Vec::with_capacity(keep * dim);
        let mut cost = Vec::with_capacity(keep);
        for &i in &self.order[..keep] {
            archive.extend_from_slice(&self.archive[i * dim..(i + 1) * dim]);
            cost.push(self.archive_cost[i]);
        }
        self.archive = archive;
        self.archive_cost = cost;
    }
}

impl Solver for Acor {
    fn init(&mut self, ev: &mut Evaluator, rng: &mut Rng) {
        let dim = self.bounds.len();
        let k = self.settings.archive;
        let mut init = vec![0.0; k * dim];
        for i in 0..k {
            for (p, &(lo, hi)) in self.bounds.iter().enumerate() {
                init[i * dim + p] = match self.seeds.get(i) {
                    Some(seed) => seed[p].clamp(lo, hi),
                    None => lo + (hi - lo) * rng.random::<f64>(),
                };
            }
            self.kind.repair(&mut init[i * dim..(i + 1) * dim]);
        }
        let mut cost = vec![0.0; k];
        ev.eval_batch(&init, &mut cost);
        self.archive = init;
        self.archive_cost = cost;
        self.merge(dim);
    }

    fn next_iter(&mut self, ev: &mut Evaluator, rng: &mut Rng) -> IterationBest {
        let dim = self.bounds.len();
        let k = self.archive_cost.len();
        let total_w = self.weights_cumulative[k - 1];
        for a in 0..self.settings.ants {
            let r = rng.random::<f64>() * total_w;
            let l = self.weights_cumulative[..k]
                .partition_point(|&c| c <= r)
                .min(k - 1);
            for p in 0..dim {
                let centre = self.archive[l * dim + p];
                let spread: f64 = (0..k)
                    .map(|e| (self.archive[e * dim + p] - centre).abs())
                    .sum::<f64>()
                    / (k - 1) as f64;
                let v = centre + self.settings.xi * spread * gaussian(rng);
                self.new[a * dim + p] = self.reflect(p, v);
            }
            self.kind.repair(&mut self.new[a * dim..(a + 1) * dim]);
        }
        ev.eval_batch(&self.new, &mut self.new_cost);
        let mut it_best = 0;
        for a in 1..self.settings.ants {
            if self.new_cost[a] < self.new_cost[it_best] {
                it_best = a;
            }
        }
        let out = IterationBest {
            params: self.new[it_best * dim..(it_best + 1) * dim].to_vec(),
            cost: self.new_cost[it_best],
        };
        self.archive.extend_from_slice(&self.new);
        self.archive_cost.extend_from_slice(&self.new_cost);
        self.merge(dim);
        out
    }
}
