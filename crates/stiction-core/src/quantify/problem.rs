//! The closed-loop objective (argmin's "problem"): for stiction parameters θ, simulate the valve
//! from OP, fit the linear part by least squares and score the fit by its simulation error.

use crate::estimate::solver::CostFunction;
use crate::identify::{self, Data, Fit, Structure};
use crate::models::ModelKind;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

pub(super) fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// `out[t] = x[t + lag] - x[t]`, for `t` in `0..x.len() - lag`.
pub(super) fn difference(x: &[f64], lag: usize, out: &mut [f64]) {
    for (t, o) in out.iter_mut().enumerate() {
        *o = x[t + lag] - x[t];
    }
}

/// What the linear part sees of the valve when the PV's changes over a lag are compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OverLag {
    /// The valve's change over the lag, `x[t + lag] - x[t]`: a self-regulating process's PV
    /// changes by its response to it.
    #[default]
    Change,
    /// The valve's position summed over the lag, `x[t] + ... + x[t + lag - 1]` (each less an
    /// offset): a level's change over the lag is its inflow, the sum of the valve's positions.
    /// Its least-squares fits with no output lag are output-error fits already, so the exact
    /// walk ranks the bands by what they explain; the changes of a level against the valve's
    /// changes need an output lag at the unit circle, whose least-squares fits simulate at
    /// random (routine-c-0014 of the catalogue: R² 0.00 to 0.14 in simulation for every band,
    /// the walk's choice 4.9 % for a true 3.7 %, which fits 0.909 after its output-error polish).
    Sum,
}

/// The valve trajectory `x` as the linear part sees it over `lag` samples (see [`OverLag`]),
/// `out` being `x.len() - lag` long.
pub(super) fn over_lag(x: &[f64], lag: usize, over: OverLag, offset: f64, out: &mut [f64]) {
    match over {
        OverLag::Change => difference(x, lag, out),
        OverLag::Sum => {
            // a running sum, summed afresh now and then to bound rounding
            for t in 0..out.len() {
                out[t] = if t % 256 == 0 {
                    x[t..t + lag].iter().map(|v| v - offset).sum()
                } else {
                    out[t - 1] + x[t + lag - 1] - x[t - 1]
                };
            }
        }
    }
}

/// The closed-loop objective: simulation error of the least-squares linear fit for the valve
/// trajectory of each candidate.
pub(super) struct Hammerstein<'a> {
    pub(super) kind: ModelKind,
    pub(super) op: &'a [f64],
    pub(super) prepared: identify::Prepared<'a>,
    /// Subtracted from the valve position (the mean OP) to keep the normal equations well scaled.
    pub(super) offset: f64,
    /// The valve position at the first sample (`None`: the first OP).
    pub(super) start: Option<f64>,
    /// Compare changes over this many samples instead of levels (0: levels): the data hold
    /// `pv[t + lag] - pv[t]` and the valve position is differenced the same way, which keeps the
    /// linear part and removes slow load drifts that OP alone cannot explain.
    pub(super) lag: usize,
    /// What the linear part sees of the valve over the lag.
    pub(super) over: OverLag,
}

impl<'a> Hammerstein<'a> {
    pub(super) fn new(
        kind: ModelKind,
        op: &'a [f64],
        data: &'a Data<'a>,
        structure: Structure,
        start: Option<f64>,
    ) -> Self {
        Self {
            kind,
            op,
            prepared: identify::Prepared::new(data, structure),
            offset: op.iter().sum::<f64>() / op.len() as f64,
            start,
            lag: 0,
            over: OverLag::Change,
        }
    }

    /// The same problem on data differenced over `lag` samples (see [`Hammerstein::lag`]), the
    /// valve seen over it as `over` says.
    pub(super) fn with_lag(mut self, lag: usize, over: OverLag) -> Self {
        self.lag = lag;
        self.over = over;
        self
    }

    /// Samples of the valve trajectory the linear part sees.
    pub(super) fn len(&self) -> usize {
        self.op.len() - self.lag
    }

    /// The valve trajectory of `theta` as the linear part sees it, into `mv` (`self.len()` long).
    pub(super) fn valve_into(&self, theta: &[f64], mv: &mut [f64]) {
        self.valve_into_with(theta, mv, &mut Vec::new());
    }

    /// As [`Hammerstein::valve_into`], with a caller's buffer for the whole trajectory when the
    /// problem compares changes over a lag.
    fn valve_into_with(&self, theta: &[f64], mv: &mut [f64], full: &mut Vec<f64>) {
        let model = self.kind.build(theta).expect("candidates are repaired");
        if self.lag == 0 {
            model.simulate_from_into(self.op, self.start, mv);
            for v in mv.iter_mut() {
                *v -= self.offset;
            }
        } else {
            full.resize(self.op.len(), 0.0);
            model.simulate_from_into(self.op, self.start, full);
            over_lag(full, self.lag, self.over, self.offset, mv);
        }
    }

    /// Whether `other` simulates the same valve trajectories (it differs at most in the linear
    /// structure).
    fn same_valve(&self, other: &Self) -> bool {
        self.kind == other.kind
            && std::ptr::eq(self.op, other.op)
            && self.start.map(f64::to_bits) == other.start.map(f64::to_bits)
            && self.lag == other.lag
            && self.over == other.over
            && self.offset.to_bits() == other.offset.to_bits()
    }

    pub(super) fn valve(&self, theta: &[f64]) -> Vec<f64> {
        let mut mv = vec![0.0; self.len()];
        self.valve_into(theta, &mut mv);
        mv
    }

    pub(super) fn fit(&self, theta: &[f64]) -> Option<Fit> {
        self.prepared.fit(&self.valve(theta))
    }

    /// The cost of one candidate, with a caller's buffer for the valve position.
    pub(super) fn cost_with(&self, theta: &[f64], mv: &mut [f64]) -> f64 {
        self.valve_into(theta, mv);
        self.prepared
            .fit(mv)
            .map_or(f64::INFINITY, |f| f.sse_simulation)
    }

    pub(super) fn cost(&self, theta: &[f64]) -> f64 {
        self.cost_with(theta, &mut vec![0.0; self.len()])
    }

    /// Costs of many one-parameter candidates, in parallel, one buffer per thread.
    pub(super) fn costs_1d(&self, values: &[f64]) -> Vec<f64> {
        let n = self.len();
        let mut out = vec![0.0; values.len()];
        out.par_iter_mut()
            .zip(values.par_iter())
            .with_min_len(8)
            .for_each_init(
                || vec![0.0; n],
                |buf, (c, &v)| *c = self.cost_with(&[v], buf),
            );
        out
    }

    /// The least of the costs of many one-parameter candidates, as `costs_1d` would give it: in
    /// fixed groups in parallel, each group's simulations stopped once they exceed the group's
    /// best so far (the least cost is always simulated to its end, so it is the same).
    pub(super) fn min_cost_1d(&self, values: &[f64]) -> f64 {
        let n = self.len();
        values
            .par_chunks(8)
            .map_init(
                || vec![0.0; n],
                |mv, group| {
                    group.iter().fold(f64::INFINITY, |best, &v| {
                        self.valve_into(&[v], mv);
                        let cost = self
                            .prepared
                            .fit_bounded(mv, best)
                            .map_or(f64::INFINITY, |f| f.sse_simulation);
                        best.min(cost)
                    })
                },
            )
            .reduce(|| f64::INFINITY, f64::min)
    }
}

/// [`Hammerstein::min_cost_1d`] of each of several problems that differ only in the linear
/// structure: each candidate's valve is simulated once for all of them (the same groups, and in
/// each group the same bound per problem, so the same least costs).
pub(super) fn min_costs_1d(problems: &[Hammerstein], values: &[f64]) -> Vec<f64> {
    let Some(first) = problems.first() else {
        return Vec::new();
    };
    if !problems.iter().all(|p| first.same_valve(p)) {
        return problems.iter().map(|p| p.min_cost_1d(values)).collect();
    }
    let n = first.len();
    let worst = || vec![f64::INFINITY; problems.len()];
    values
        .par_chunks(8)
        .map_init(
            || (vec![0.0; n], Vec::new()),
            |(mv, full), group| {
                let mut best = worst();
                for &v in group {
                    first.valve_into_with(&[v], mv, full);
                    for (p, b) in problems.iter().zip(best.iter_mut()) {
                        let cost = p
                            .prepared
                            .fit_bounded(mv, *b)
                            .map_or(f64::INFINITY, |f| f.sse_simulation);
                        *b = b.min(cost);
                    }
                }
                best
            },
        )
        .reduce(worst, |a, b| {
            a.iter().zip(&b).map(|(x, y)| x.min(*y)).collect()
        })
}

impl CostFunction for Hammerstein<'_> {
    fn dim(&self) -> usize {
        self.kind.dim()
    }
    fn eval_batch(&self, candidates: &[f64], costs: &mut [f64]) {
        let dim = self.dim();
        let n = self.len();
        costs
            .par_iter_mut()
            .enumerate()
            .with_min_len(4)
            .for_each_init(
                || vec![0.0; n],
                |buf, (i, c)| *c = self.cost_with(&candidates[i * dim..(i + 1) * dim], buf),
            );
    }
}

#[cfg(test)]
mod tests {
    use super::{over_lag, OverLag};

    /// The valve summed over the lag, by its running sum (summed afresh every 256 samples),
    /// equals each window summed directly; its change over the lag is the difference.
    #[test]
    fn the_valve_over_a_lag_is_its_change_or_its_window_sum() {
        let x: Vec<f64> = (0..900)
            .map(|i| 50.0 + 10.0 * ((i * 37 % 101) as f64 / 101.0) + (i as f64 * 0.01).sin())
            .collect();
        for lag in [1, 7, 80, 300] {
            let mut sum = vec![0.0; x.len() - lag];
            over_lag(&x, lag, OverLag::Sum, 50.0, &mut sum);
            let mut change = vec![0.0; x.len() - lag];
            over_lag(&x, lag, OverLag::Change, 50.0, &mut change);
            for t in 0..x.len() - lag {
                let direct: f64 = x[t..t + lag].iter().map(|v| v - 50.0).sum();
                assert!((sum[t] - direct).abs() < 1e-9, "lag {lag}, t {t}");
                assert_eq!(change[t], x[t + lag] - x[t]);
            }
        }
    }
}
