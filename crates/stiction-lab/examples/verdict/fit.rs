//! The model: each statistic read through hinges at knots set on the simulated training records
//! (quantiles of its values), one weight at or above zero per hinge, fitted by a weighted ridge
//! logistic regression ([`stiction_lab::logistic`]); the real records count with a weight of their
//! own. Out of fold on the real records: every real group (a plant tag's windows together, an ISDB
//! loop) is left out in turn and predicted by the model fitted without it.

use crate::samples::Sample;
use stiction_core::diagnose::{Input, Statistic, Training, VerdictModel};
use stiction_lab::logistic;

/// Quantiles of the simulated training values the knots stand at.
const KNOT_QUANTILES: [f64; 4] = [0.25, 0.5, 0.75, 0.92];

/// How a model is trained.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The statistics read.
    pub statistics: Vec<Statistic>,
    /// A real record's weight against a simulated one (within the balanced halves).
    pub real_weight: f64,
    /// The ridge penalty on the standardised hinges.
    pub ridge: f64,
    /// Simulated sticky valves whose slips move PV less than this many noise standard
    /// deviations are left out (no one can see them; real labels come from what engineers saw).
    pub min_visibility: f64,
    /// The plain healthy class's share of a simulated suite's healthy weight.
    pub plain_share: f64,
    /// The verdict's thresholds.
    pub stiction_from: f64,
    pub no_stiction_below: f64,
}

/// Knots, range and reference of one statistic, from the simulated training records.
#[derive(Debug, Clone)]
pub struct Reading {
    pub statistic: Statistic,
    pub knots: Vec<f64>,
    pub range: [f64; 2],
    pub reference: f64,
}

fn quantile(sorted: &[f64], q: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

fn index(s: Statistic) -> usize {
    Statistic::ALL
        .iter()
        .position(|&t| t == s)
        .expect("every statistic is in ALL")
}

/// The knots of every statistic of `plan`, from `sims`.
pub fn readings(plan: &Plan, sims: &[&Sample]) -> Vec<Reading> {
    plan.statistics
        .iter()
        .map(|&s| {
            let i = index(s);
            let mut v: Vec<f64> = sims.iter().filter_map(|x| x.measured[i]).collect();
            v.sort_by(f64::total_cmp);
            let mut healthy: Vec<f64> = sims
                .iter()
                .filter(|x| !x.sticky)
                .filter_map(|x| x.measured[i])
                .collect();
            healthy.sort_by(f64::total_cmp);
            if v.is_empty() {
                return Reading {
                    statistic: s,
                    knots: vec![0.0],
                    range: [0.0, 0.0],
                    reference: 0.0,
                };
            }
            let mut knots: Vec<f64> = Vec::new();
            let span = v[v.len() - 1] - v[0];
            for k in std::iter::once(v[0]).chain(KNOT_QUANTILES.iter().map(|&q| quantile(&v, q))) {
                if knots.last().is_none_or(|l| k - l > 0.02 * span) && k < v[v.len() - 1] {
                    knots.push(k);
                }
            }
            if knots.is_empty() {
                knots.push(v[0]);
            }
            Reading {
                statistic: s,
                knots,
                range: [v[0], v[v.len() - 1]],
                reference: if healthy.is_empty() {
                    v[0]
                } else {
                    quantile(&healthy, 0.5)
                },
            }
        })
        .collect()
}

/// A sample's hinges under `readings` (a statistic not measured reads its reference).
pub fn hinges(readings: &[Reading], s: &Sample) -> Vec<f64> {
    let mut out = Vec::new();
    for r in readings {
        let x = s.measured[index(r.statistic)]
            .unwrap_or(r.reference)
            .clamp(r.range[0], r.range[1]);
        out.extend(r.knots.iter().map(|k| (x - k).max(0.0)));
    }
    out
}

/// Whether a sample trains the model under `plan`.
pub fn trains(plan: &Plan, s: &Sample) -> bool {
    s.judged && !(s.sticky && s.visibility.is_some_and(|v| v < plan.min_visibility))
}

/// Weights: within the simulated records and within the real ones, the sticky and the healthy
/// halves weigh alike; a real record weighs `real_weight` times a simulated one. Within a
/// simulated suite's healthy half, the plain healthy class weighs `plain_share` and the
/// look-alike classes share the rest equally: the catalogue holds many look-alikes to test the
/// verdict against, more than routine plant records hold.
fn weights(plan: &Plan, samples: &[&Sample]) -> Vec<f64> {
    let count = |real: bool, sticky: bool| {
        samples
            .iter()
            .filter(|s| s.source.real() == real && s.sticky == sticky)
            .count()
            .max(1) as f64
    };
    let n_sim = samples.iter().filter(|s| !s.source.real()).count() as f64;
    let n_real = samples.len() as f64 - n_sim;
    // the healthy classes of each simulated source, and how many records each holds
    let mut classes: std::collections::HashMap<(u8, &str), usize> = Default::default();
    for s in samples.iter().filter(|s| !s.source.real() && !s.sticky) {
        *classes
            .entry((s.source as u8, s.class.as_str()))
            .or_default() += 1;
    }
    let healthy_of = |src: u8| -> (usize, usize) {
        let total: usize = classes
            .iter()
            .filter(|(k, _)| k.0 == src)
            .map(|(_, n)| n)
            .sum();
        let lookalikes = classes
            .keys()
            .filter(|k| k.0 == src && k.1 != "healthy")
            .count();
        (total, lookalikes)
    };
    samples
        .iter()
        .map(|s| {
            if s.source.real() {
                return plan.real_weight * n_real / (2.0 * count(true, s.sticky));
            }
            let base = n_sim / (2.0 * count(false, s.sticky));
            if s.sticky {
                return base;
            }
            let src = s.source as u8;
            let (total, lookalikes) = healthy_of(src);
            let in_class = classes[&(src, s.class.as_str())] as f64;
            let share = if s.class == "healthy" || lookalikes == 0 {
                if lookalikes == 0 {
                    1.0
                } else {
                    plan.plain_share
                }
            } else {
                (1.0 - plan.plain_share) / lookalikes as f64
            };
            // the class's share of its suite's healthy records, over its records
            base * share * total as f64 / in_class
        })
        .collect()
}

/// The model fitted to `samples` (those that train under `plan`).
pub fn fit(plan: &Plan, samples: &[&Sample], how: Training) -> VerdictModel {
    let training: Vec<&Sample> = samples
        .iter()
        .copied()
        .filter(|s| trains(plan, s))
        .collect();
    let sims: Vec<&Sample> = training
        .iter()
        .copied()
        .filter(|s| !s.source.real())
        .collect();
    let rs = readings(plan, &sims);
    let x: Vec<Vec<f64>> = training.iter().map(|s| hinges(&rs, s)).collect();
    // standardise the hinges for the ridge; weights come back on the hinges' own scale
    let k = x.first().map_or(0, Vec::len);
    let sd: Vec<f64> = (0..k)
        .map(|j| {
            let m = x.iter().map(|r| r[j]).sum::<f64>() / x.len() as f64;
            let v = x.iter().map(|r| (r[j] - m).powi(2)).sum::<f64>() / x.len() as f64;
            v.sqrt().max(1e-9)
        })
        .collect();
    let z: Vec<Vec<f64>> = x
        .iter()
        .map(|r| r.iter().zip(&sd).map(|(v, s)| v / s).collect())
        .collect();
    let y: Vec<bool> = training.iter().map(|s| s.sticky).collect();
    let w = weights(plan, &training);
    let f = logistic::fit(&z, &y, &w, plan.ridge);
    let mut at = 0;
    let mut inputs = Vec::new();
    let mut intercept = f.intercept;
    for r in &rs {
        let weights: Vec<f64> = (0..r.knots.len())
            .map(|j| f.weights[at + j] / sd[at + j])
            .collect();
        at += r.knots.len();
        let input = Input {
            statistic: r.statistic,
            range: r.range,
            knots: r.knots.clone(),
            weights,
            reference: r.reference,
        };
        // the file's intercept is the log-odds at the references
        intercept += input.effect(r.reference);
        inputs.push(input);
    }
    VerdictModel {
        intercept,
        inputs,
        stiction_from: plan.stiction_from,
        no_stiction_below: plan.no_stiction_below,
        training: how,
    }
}

/// The probability a model gives a sample.
pub fn probability(m: &VerdictModel, s: &Sample) -> f64 {
    m.read(|t| s.measured[index(t)]).probability
}

/// Out of fold on the real samples: each real group predicted by the model fitted without it
/// (`None` for a record that cannot be judged).
pub fn leave_one_loop_out(plan: &Plan, samples: &[Sample]) -> Vec<(usize, Option<f64>)> {
    use rayon::prelude::*;
    let mut groups: Vec<&str> = samples
        .iter()
        .filter(|s| s.source.real())
        .map(|s| s.group.as_str())
        .collect();
    groups.sort();
    groups.dedup();
    let mut out: Vec<(usize, Option<f64>)> = groups
        .par_iter()
        .flat_map_iter(|g| {
            let rest: Vec<&Sample> = samples.iter().filter(|s| s.group != *g).collect();
            let m = fit(plan, &rest, placeholder());
            samples
                .iter()
                .enumerate()
                .filter(|(_, s)| s.group == *g)
                .map(|(i, s)| (i, s.judged.then(|| probability(&m, s))))
                .collect::<Vec<_>>()
        })
        .collect();
    out.sort_by_key(|p| p.0);
    out
}

/// A training record's text for models that are not written.
pub fn placeholder() -> Training {
    Training {
        command: String::new(),
        records: String::new(),
        real_weight: 0.0,
        ridge: 0.0,
        checked: String::new(),
    }
}
