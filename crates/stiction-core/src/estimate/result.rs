//! What `estimate` returns.

use super::{Method, TraceRow};
use crate::models::ModelKind;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// How the interval of equally good parameter values was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum IntervalKind {
    /// Proven: every value in it reaches the least error (the exact Stenman solver).
    Exact,
    /// Exact near the best points of a scan, not over the whole range.
    ExactLocal,
    /// Exact on the staged search's short list of structures.
    ExactStaged,
    /// The hull of the grid points at the minimum.
    Grid,
    /// Along each parameter's axis with the others held at the estimate.
    Axis,
    /// No interval (random searches).
    None,
}

/// The result of an estimation, shared by every front end.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The model fitted.
    pub model: ModelKind,
    /// The method used.
    pub method: Method,
    /// Point estimate per parameter.
    pub params: BTreeMap<String, f64>,
    /// Per parameter, the set of equally optimal values `[lo, hi]`, where the method can know it
    /// (exact: proven; grid: the hull of the grid points that reach the minimum). Empty otherwise.
    pub interval: BTreeMap<String, [f64; 2]>,
    /// How `interval` was obtained: exact, grid or none.
    pub interval_kind: IntervalKind,
    /// Exact method: the optimal set as disjoint half-open pieces [lo, hi) when it is not one piece.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pieces: Option<Vec<[f64; 2]>>,
    /// Sum of squared errors between measured and modelled valve position.
    pub sse: f64,
    /// Root mean square error, same units as mv.
    pub rmse: f64,
    /// Fit quality 1 - SSE / sum (mv - mean)^2.
    pub r2: f64,
    /// Objective evaluations (for the exact method, those of its initial bound).
    pub evaluations: u64,
    /// Iterations run (population methods), cells created (exact), 1 (grid).
    pub iterations: u64,
    /// Time spent estimating, excluding reading the data.
    pub seconds: f64,
    /// Samples fitted.
    pub samples: usize,
    /// Search range per parameter.
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// The seed used (random searches only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Stenman with a non-exact method: the proven optimal set, and whether the estimate is in it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub certificate: Option<Certificate>,
    /// Caveats: a wide optimal set, an estimate outside the proven optimum, a parameter on its
    /// bound.
    pub warnings: Vec<String>,
    /// The per-iteration trace, when requested (population methods).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub trace: Vec<TraceRow>,
}

/// A check of a heuristic's answer against the exact optimum (Stenman only).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Certificate {
    /// The hull of the proven optimal set of d, `[lo, hi]`.
    pub optimal_interval: [f64; 2],
    /// The least fit error (sum of squares).
    pub optimal_sse: f64,
    /// Whether the heuristic's d lies in the optimal set.
    pub estimate_is_optimal: bool,
}
