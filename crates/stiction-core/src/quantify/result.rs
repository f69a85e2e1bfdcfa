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
    pub na: usize,
    pub nb: usize,
    /// Delay in samples from valve position to output (1 = the next sample).
    pub nk: usize,
    /// y[t] = sum a_i y[t-i] + sum b_j mv[t-nk-j] + c, y and mv centred.
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub c: f64,
    pub gain: Option<f64>,
    /// Seconds.
    pub time_constant: Option<f64>,
    /// Seconds.
    pub dead_time: f64,
    /// The criterion the orders and delay were chosen by.
    pub criterion: String,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitQuality {
    /// The output the R² refer to: pv or its change per sample.
    pub output: FitOutput,
    pub r2_simulation: f64,
    pub r2_one_step: f64,
    pub sse_simulation: f64,
    /// R² in simulation of the best linear model of the same family with a valve that follows
    /// OP exactly (no stiction): how much of the fit the stiction model itself earns. `None` when
    /// no stable linear model fits that valve (its simulation would run away).
    pub r2_simulation_without_stiction: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Quantification {
    /// Whether parameters were estimated.
    pub status: QuantifyStatus,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    pub model: ModelKind,
    pub method: Method,
    pub params: BTreeMap<String, f64>,
    /// Per parameter, the values that fit equally well: exact for Stenman with `exact` (the cells of
    /// least simulation error); for other methods, along each axis with the others held at the
    /// estimate.
    pub interval: BTreeMap<String, [f64; 2]>,
    pub interval_kind: IntervalKind,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear_model: Option<LinearModel>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<FitQuality>,
    /// The stiction band in OP units (% of valve span when OP is in %): Stenman d; He fs + fd;
    /// Kano and Choudhury S.
    pub apparent_stiction: Option<f64>,
    /// The same band as a percentage of the OP's peak-to-peak range in the data.
    pub apparent_stiction_pct_of_op_range: Option<f64>,
    pub op_range: f64,
    pub evaluations: u64,
    /// Stenman with `exact`: the number of distinct valve trajectories.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cells: Option<usize>,
    /// Stenman and He: the valve position the model starts from at the first sample, and how it
    /// was chosen ("first_op": where OP starts; "estimated": the best of the candidates on the
    /// first samples; "given").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valve_start: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valve_start_kind: Option<ValveStartKind>,
    pub seconds: f64,
    pub samples: usize,
    pub ts: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    pub warnings: Vec<String>,
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
