//! The result of `quantify`, shared by every front end.

use super::request::QuantifyRequest;
use crate::estimate::{IntervalKind, Method};
use crate::models::ModelKind;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Whether a quantification reached an answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum QuantifyStatus {
    /// Parameters estimated.
    Ok,
    /// Too little usable data; `reason` says why.
    InsufficientData,
}

/// The family of the identified linear process.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LinearFamily {
    /// PV settles after a valve step (flow, pressure, temperature); the model's output is PV.
    SelfRegulating,
    /// PV ramps after a valve step (level); the model's output is PV's change per sample.
    Integrating,
}

impl std::fmt::Display for LinearFamily {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LinearFamily::SelfRegulating => "self-regulating",
            LinearFamily::Integrating => "integrating",
        })
    }
}

/// The output the R² of a fit refer to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitOutput {
    /// The PV itself.
    Pv,
    /// The PV's change per sample (integrating processes).
    DeltaPv,
}

/// Where the valve model starts at the first sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ValveStartKind {
    /// Where OP starts.
    FirstOp,
    /// The best of the candidates across the OP's span, fitted on the first samples.
    Estimated,
    /// Given by the caller.
    Given,
}

/// The identified linear part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearModel {
    /// Self-regulating (output pv) or integrating (output: the change of pv per sample).
    pub family: LinearFamily,
    /// Output lags na.
    pub na: usize,
    /// Input terms nb.
    pub nb: usize,
    /// Delay in samples from valve position to output (1 = the next sample).
    pub nk: usize,
    /// Output coefficients a_i of `y[t] = sum a_i y[t-i] + sum b_j mv[t-nk-j] + c`, y and mv
    /// centred.
    pub a: Vec<f64>,
    /// Input coefficients b_j.
    pub b: Vec<f64>,
    /// Constant c, in the units of the centred output.
    pub c: f64,
    /// Gain (PV units per OP unit; per second for an integrating process), when the coefficients
    /// give one.
    pub gain: Option<f64>,
    /// Seconds.
    pub time_constant: Option<f64>,
    /// Seconds.
    pub dead_time: f64,
    /// The criterion the orders and delay were chosen by.
    pub criterion: String,
}

/// How well the fitted loop (stiction model and linear part) reproduces the output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitQuality {
    /// The output the R² refer to: pv or its change per sample.
    pub output: FitOutput,
    /// R² of the simulated output.
    pub r2_simulation: f64,
    /// R² of the one-step prediction.
    pub r2_one_step: f64,
    /// Sum of squares of the simulation error.
    pub sse_simulation: f64,
    /// R² in simulation of the best linear model of the same family with a valve that follows
    /// OP exactly (no stiction): how much of the fit the stiction model itself earns. `None` when
    /// no stable linear model fits that valve (its simulation would run away).
    pub r2_simulation_without_stiction: Option<f64>,
}

/// The result of a closed-loop quantification (`quantify`): the stiction model's parameters
/// estimated from OP and PV, with the linear process fitted with them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quantification {
    /// Whether parameters were estimated.
    pub status: QuantifyStatus,
    /// Why no parameters were estimated (`insufficient_data` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The stiction model fitted.
    pub model: ModelKind,
    /// The search method used.
    pub method: Method,
    /// Point estimate per parameter, in op's units.
    pub params: BTreeMap<String, f64>,
    /// Per parameter, the values that fit equally well: exact for Stenman with `exact` (the cells of
    /// least simulation error); for other methods, along each axis with the others held at the
    /// estimate.
    pub interval: BTreeMap<String, [f64; 2]>,
    /// How `interval` was obtained.
    pub interval_kind: IntervalKind,
    /// The identified linear part (absent without an answer).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear_model: Option<LinearModel>,
    /// How well the fit reproduces the output (absent without an answer).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitQuality>,
    /// The stiction band in OP units (% of valve span when OP is in %): Stenman d; He fs + fd;
    /// Kano and Choudhury S.
    pub apparent_stiction: Option<f64>,
    /// The same band as a percentage of the OP's peak-to-peak range in the data.
    pub apparent_stiction_pct_of_op_range: Option<f64>,
    /// The OP's peak-to-peak range in the data, OP units.
    pub op_range: f64,
    /// Candidates fitted.
    pub evaluations: u64,
    /// Stenman with `exact`: the number of distinct valve trajectories.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells: Option<usize>,
    /// Stenman and He: the valve position the model starts from at the first sample, and how it
    /// was chosen ("first_op": where OP starts; "estimated": the best of the candidates on the
    /// first samples; "given").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valve_start: Option<f64>,
    /// How `valve_start` was chosen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valve_start_kind: Option<ValveStartKind>,
    /// Time the quantification took, seconds.
    pub seconds: f64,
    /// Samples in the record.
    pub samples: usize,
    /// Sampling time, seconds.
    pub ts: f64,
    /// The seed used (random searches only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Caveats: a poor fit, a parameter at the top of its search range, a valve that hardly moves.
    pub warnings: Vec<String>,
    /// What closed-loop data can and cannot tell (the same for every result).
    pub caveat: String,
    /// The estimated valve position (not serialised: for plots).
    #[serde(skip)]
    pub mv: Vec<f64>,
    /// The fitted model's simulated PV (not serialised: for plots).
    #[serde(skip)]
    pub pv_simulated: Vec<f64>,
}

pub(super) const CAVEAT: &str =
    "apparent stiction inferred from OP and PV without the valve position; \
oscillating closed-loop data may not identify the valve and the process separately";

impl Quantification {
    pub(super) fn insufficient(
        req: &QuantifyRequest,
        n: usize,
        op_range: f64,
        reason: String,
    ) -> Self {
        Self {
            status: QuantifyStatus::InsufficientData,
            reason: Some(reason),
            model: req.model,
            method: req.method,
            params: BTreeMap::new(),
            interval: BTreeMap::new(),
            interval_kind: IntervalKind::None,
            linear_model: None,
            fit: None,
            apparent_stiction: None,
            apparent_stiction_pct_of_op_range: None,
            op_range,
            evaluations: 0,
            cells: None,
            valve_start: None,
            valve_start_kind: None,
            seconds: 0.0,
            samples: n,
            ts: req.ts,
            seed: None,
            warnings: Vec::new(),
            caveat: CAVEAT.into(),
            mv: Vec::new(),
            pv_simulated: Vec::new(),
        }
    }
}
