//! Gradient-boosted trees, as `stiction-lab/scripts/train_combined.py` writes them (`forest.json`):
//! each node `[feature, threshold, left, right, value]`, a leaf where `left` is 0 (the root is node
//! 0, so no child is). A sample goes left where its statistic is at or below the threshold. Every
//! node carries the mean of the leaves under it (weighted by the training samples that reached
//! them), so a path's steps split the tree's output among the statistics it asked about (Saabas'
//! contributions): the trees' log-odds are the baseline, the roots' means and those steps.

use crate::diagnose::result::Verdict;
use serde::Deserialize;
use std::sync::LazyLock;

/// One node: `[feature, threshold, left, right, value]`.
pub(super) type Node = (usize, f64, usize, usize, f64);

/// A known input and the probability the trainer gave it (checked by the tests).
#[derive(Debug, Deserialize)]
pub struct Check {
    pub x: Vec<f64>,
    pub p: f64,
}

/// The trained trees and how they were trained.
#[derive(Debug, Deserialize)]
pub struct Forest {
    /// The statistics' names, in the order the trees read them.
    pub features: Vec<String>,
    /// The log-odds every tree adds to.
    pub baseline: f64,
    /// The probability from which a `no_stiction` verdict becomes `stiction`.
    pub threshold: f64,
    /// The probability from which an `undetermined` verdict becomes `stiction` (`threshold`
    /// when absent).
    #[serde(default)]
    pub threshold_undetermined: Option<f64>,
    /// How the trees and the threshold were set, in words.
    pub calibration: String,
    pub trees: Vec<Vec<Node>>,
    /// Inputs with the trainer's probabilities.
    #[serde(default)]
    pub checks: Vec<Check>,
}

/// What the trees say of one input.
pub struct Reading {
    /// The probability of a sticky valve.
    pub probability: f64,
    /// Each statistic's share of the log-odds (in the forest's feature order).
    pub contributions: Vec<f64>,
}

static FOREST: LazyLock<Option<Forest>> = LazyLock::new(|| {
    serde_json::from_str::<Forest>(include_str!("forest.json"))
        .ok()
        .filter(|f| !f.trees.is_empty())
});

/// The embedded trees, when trained.
pub fn forest() -> Option<&'static Forest> {
    FOREST.as_ref()
}

impl Forest {
    /// The probability from which the rules' `verdict` becomes `stiction`: where the rules could
    /// not decide, the trees' lower threshold for `undetermined`.
    pub fn threshold_for(&self, verdict: Verdict) -> f64 {
        match verdict {
            Verdict::Undetermined => self.threshold_undetermined.unwrap_or(self.threshold),
            _ => self.threshold,
        }
    }

    /// The trees' probability for `x` (statistics in [`Forest::features`]' order), with each
    /// statistic's contribution to the log-odds. `None` when `x` has the wrong length or a
    /// tree points outside itself.
    pub fn read(&self, x: &[f64]) -> Option<Reading> {
        if x.len() != self.features.len() {
            return None;
        }
        let mut contributions = vec![0.0; x.len()];
        let mut raw = self.baseline;
        for tree in &self.trees {
            let mut node = *tree.first()?;
            raw += node.4;
            while node.2 != 0 {
                let (feature, threshold, left, right, value) = node;
                let next = if *x.get(feature)? <= threshold {
                    left
                } else {
                    right
                };
                node = *tree.get(next)?;
                contributions[feature] += node.4 - value;
                raw += node.4 - value;
            }
        }
        Some(Reading {
            probability: 1.0 / (1.0 + (-raw).exp()),
            contributions,
        })
    }
}
