//! One search of one record, in the stages argmin's executor would name: the gates (can this
//! record be quantified at all), the pilot structures (which linear models to try), the search of
//! the stiction parameters per structure, and the result.

use super::exact::{exact_stenman, merged_top_cells};
use super::heuristic::{axis_intervals, grid_search, polish};
use super::pilots::{first_guesses, pilot_points, MOST_STRUCTURES, STARTING_STRUCTURES};
use super::problem::{range, Hammerstein};
use super::result::CAVEAT;
use super::{
    quantify, FitOutput, FitQuality, LinearFamily, LinearModel, Quantification, QuantifyRequest,
    QuantifyStatus, ValveStartKind,
};
use crate::checked::Checked;
use crate::estimate::solver::{self, Evaluator};
use crate::estimate::{self, aco, acor, EstimateError, IntervalKind, Method};
use crate::identify::{self, Data, Fit, SearchRange, Structure};
use crate::models::ModelKind;
use crate::rng::seeded;
use rayon::prelude::*;
use std::collections::{BTreeMap, VecDeque};
use std::time::Instant;

mod answer;
mod gates;
mod structures;

use answer::result;
use gates::gates;
use structures::{hint_for_whole_record, search_structures, starting_structures};

/// What a staged search carries from the first samples to the whole record.
pub(super) struct Hint {
    /// The structures tried, best first.
    pub(super) structures: Vec<Structure>,
    /// The cells of least cost, merged, in increasing d.
    pub(super) ranges: Vec<(f64, f64)>,
}

/// The answer of one search of the stiction parameters under one linear structure.
pub(super) struct Outcome {
    pub(super) best: Vec<f64>,
    pub(super) interval: BTreeMap<String, [f64; 2]>,
    pub(super) interval_kind: IntervalKind,
    pub(super) evaluations: u64,
    pub(super) cells: Option<usize>,
    /// Stenman exact: the cells of least cost, best first (for a staged search).
    pub(super) top_cells: Vec<(f64, f64)>,
}

/// What the gates leave for the search.
struct Setup<'a> {
    op_range: f64,
    search: SearchRange,
    bounds: Vec<(f64, f64)>,
    data: Data<'a>,
}

/// One searched structure: its outcome and its simulation criterion (least is best).
struct Tried {
    structure: Structure,
    outcome: Outcome,
    criterion: f64,
}

/// The work counted so far.
#[derive(Default)]
struct Work {
    evaluations: u64,
    seed: Option<u64>,
}

pub(super) fn quantify_inner(
    op: &[f64],
    pv: &[f64],
    req: &Checked<QuantifyRequest>,
    hint: Option<&Hint>,
) -> Result<(Quantification, Hint), EstimateError> {
    let started = Instant::now();
    let n = op.len();
    let no_hint = || Hint {
        structures: Vec::new(),
        ranges: Vec::new(),
    };
    let insufficient = |op_range: f64, why: String| {
        Ok((
            Quantification::insufficient(req, n, op_range.max(0.0), why),
            no_hint(),
        ))
    };
    let setup = match gates(op, pv, req)? {
        Ok(setup) => setup,
        Err((op_range, why)) => return insufficient(op_range, why),
    };
    let mut work = Work::default();
    let (mut queue, stenman_d) = starting_structures(op, &setup, req, hint, &mut work)?;
    if queue.is_empty() {
        return insufficient(
            setup.op_range,
            "no linear model could be fitted: the valve trajectory never excites the PV".into(),
        );
    }
    let mut tried = search_structures(op, &setup, req, hint, &mut queue, stenman_d, &mut work);
    tried.sort_by(|a, b| a.criterion.total_cmp(&b.criterion));
    let next = hint_for_whole_record(&tried);
    let best = tried.into_iter().next().expect("at least one search ran");
    match result(op, &setup, req, best, &work, started) {
        Ok(q) => Ok((q, next)),
        Err(why) => insufficient(setup.op_range, why),
    }
}
