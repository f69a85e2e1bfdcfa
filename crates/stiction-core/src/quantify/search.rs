//! One search of one record, in the stages argmin's executor would name: the gates (can this
//! record be quantified at all), the pilot structures (which linear models to try), the search of
//! the stiction parameters per structure, and the result.

use super::exact::exact_stenman;
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

/// Can this record be quantified? `Ok(Err((op range, reason)))` when not (data that cannot be
/// judged); `Err` for a wrong request.
#[allow(clippy::type_complexity)]
fn gates<'a>(
    op: &[f64],
    pv: &'a [f64],
    req: &QuantifyRequest,
) -> Result<Result<Setup<'a>, (f64, String)>, EstimateError> {
    let n = op.len();
    estimate::check_pair(("op", op), ("pv", pv))?;
    let (op_lo, op_hi) = range(op);
    let (pv_lo, pv_hi) = range(pv);
    let op_range = if n > 0 { op_hi - op_lo } else { 0.0 };
    let mut search = SearchRange::new(req.max_delay.min(n / 20).max(1));
    if let Some(integrating) = req.integrating {
        search.integrating = integrating;
        search.self_regulating = !integrating;
    }
    let needed = search.t0() + 20 * (search.na.len() + search.nb_max + 1);
    let why = if n < needed {
        Some(format!(
            "only {n} samples; the linear model search (delays up to {} samples) needs at least {needed}",
            search.nk_max
        ))
    } else if op_range <= 0.0 {
        Some(format!(
            "OP is constant at {op_lo}: the valve is never moved"
        ))
    } else if pv_hi - pv_lo <= 0.0 {
        Some(format!(
            "PV is constant at {pv_lo}: nothing responds to the valve"
        ))
    } else if op.iter().all(|&v| v <= 0.0 || v >= 100.0) {
        Some(format!(
            "OP is at or beyond 0 or 100 % the whole time (it runs from {} to {}): saturated, or recorded in other units than % (rescale it to 0-100 % of the valve's span)",
            crate::quality::readable(op_lo),
            crate::quality::readable(op_hi)
        ))
    } else {
        None
    };
    if let Some(why) = why {
        return Ok(Err((op_range, why)));
    }
    // bounds given were checked with the request; the default range comes from the data
    let bounds: Vec<(f64, f64)> = match &req.bounds {
        Some(b) => b.clone(),
        None => {
            let range = vec![(0.0, op_range); req.model.dim()];
            estimate::check_bounds(req.model, &range)?;
            range
        }
    };
    Ok(Ok(Setup {
        op_range,
        search: search.clone(),
        bounds,
        data: Data::new(pv, search.t0()),
    }))
}

/// The structures searched first: for two-parameter models the Stenman answer's; a staged
/// search's best of the first samples; the distinct structures the pilots choose, best one-step
/// fit first; and always the structure of a valve without stiction, so the answer is never worse
/// than the linear loop it is compared with. Also returns the Stenman band for two-parameter
/// models (their first guesses).
fn starting_structures(
    op: &[f64],
    setup: &Setup,
    req: &QuantifyRequest,
    hint: Option<&Hint>,
    work: &mut Work,
) -> Result<(VecDeque<Structure>, Option<f64>), EstimateError> {
    let Setup {
        search,
        bounds,
        data,
        ..
    } = setup;
    // pilot: the process family and a first structure, chosen at a spread of stiction parameters
    // (a staged search runs them again on the whole record: the first samples may be too few
    // to tell the structure); a quarter of the spread is enough to add the whole record's
    let step = if hint.is_some() { 4 } else { 1 };
    let pilots: Vec<Vec<f64>> = pilot_points(req.model, bounds)
        .into_iter()
        .step_by(step)
        .collect();
    let mut ranked: Vec<identify::Selection> = pilots
        .par_iter()
        .filter_map(|theta| {
            let model = req.model.build(theta).ok()?;
            identify::select(
                data,
                &identify::centred(&model.simulate_from(op, req.valve_start)),
                search,
            )
        })
        .collect();
    work.evaluations += pilots.len() as u64;
    ranked.sort_by(|a, b| a.one_step_bic.total_cmp(&b.one_step_bic));
    let mut queue: VecDeque<Structure> = VecDeque::new();
    // two-parameter models start from the Stenman answer (structure and band), which the exact
    // search finds reliably
    let mut stenman_d = None;
    if req.model.dim() == 2 {
        let mut sreq = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
        sreq.ts = req.ts;
        sreq.max_delay = req.max_delay;
        sreq.integrating = req.integrating;
        sreq.bounds = Some(vec![(bounds[0].0, bounds[0].1.max(bounds[1].1))]);
        let sq = quantify(op, data.pv, &sreq)?;
        work.evaluations += sq.evaluations;
        if let (Some(lm), Some(d)) = (&sq.linear_model, sq.params.get("d")) {
            queue.push_back(Structure {
                integrating: lm.family == LinearFamily::Integrating,
                na: lm.na,
                nb: lm.nb,
                nk: lm.nk,
            });
            stenman_d = Some(*d);
        }
    }
    if let Some(h) = hint {
        queue.extend(h.structures.iter().take(STARTING_STRUCTURES / 2));
    }
    for c in &ranked {
        if !queue.contains(&c.structure) && queue.len() < STARTING_STRUCTURES {
            queue.push_back(c.structure);
        }
    }
    let lows: Vec<f64> = bounds.iter().map(|b| b.0).collect();
    if let Some(sel) = req.model.build(&lows).ok().and_then(|m| {
        identify::select(
            data,
            &identify::centred(&m.simulate_from(op, req.valve_start)),
            search,
        )
    }) {
        if !queue.contains(&sel.structure) {
            queue.push_back(sel.structure);
        }
    }
    Ok((queue, stenman_d))
}

/// Search the stiction parameters for each structure; confirm the structure at each answer and
/// search again with a new one if it differs. Returns every searched structure with its
/// simulation criterion.
fn search_structures(
    op: &[f64],
    setup: &Setup,
    req: &QuantifyRequest,
    hint: Option<&Hint>,
    queue: &mut VecDeque<Structure>,
    stenman_d: Option<f64>,
    work: &mut Work,
) -> Vec<Tried> {
    let mut tried: Vec<Tried> = Vec::new();
    while !queue.is_empty() && tried.len() < MOST_STRUCTURES {
        // the structures of this round: for Stenman exact all queued ones share one walk
        let mut round: Vec<Structure> = Vec::new();
        while let Some(s) = queue.pop_front() {
            if !tried.iter().any(|t| t.structure == s)
                && !round.contains(&s)
                && tried.len() + round.len() < MOST_STRUCTURES
            {
                round.push(s);
            }
            if req.method != Method::Exact && !round.is_empty() {
                break;
            }
        }
        if round.is_empty() {
            break;
        }
        let problems: Vec<Hammerstein> = round
            .iter()
            .map(|&s| Hammerstein::new(req.model, op, &setup.data, s, req.valve_start))
            .collect();
        let outcomes = search_round(&problems, setup, req, hint, stenman_d, work);
        // a walk shared by several structures counts once
        work.evaluations += outcomes.iter().map(|o| o.evaluations).max().unwrap_or(0);
        for (problem, outcome) in problems.iter().zip(outcomes) {
            let mv_c = problem.valve(&outcome.best);
            let criterion = problem.fit(&outcome.best).map_or(f64::INFINITY, |f| {
                identify::level_simulation_bic(&setup.data, &mv_c, &f)
            });
            tried.push(Tried {
                structure: problem.prepared.structure(),
                outcome,
                criterion,
            });
            work.evaluations += 1;
            // confirm the structure at this answer; a different one is searched next, first
            if let Some(next) = identify::select(&setup.data, &mv_c, &setup.search) {
                if !tried.iter().any(|t| t.structure == next.structure)
                    && !queue.contains(&next.structure)
                {
                    queue.push_front(next.structure);
                }
            }
        }
    }
    tried
}

/// One round's searches: the exact walk shared by all its structures, or one heuristic search.
fn search_round(
    problems: &[Hammerstein],
    setup: &Setup,
    req: &QuantifyRequest,
    hint: Option<&Hint>,
    stenman_d: Option<f64>,
    work: &mut Work,
) -> Vec<Outcome> {
    let bounds = &setup.bounds;
    match req.method {
        Method::Exact => exact_stenman(
            problems,
            bounds[0],
            req.full_partition,
            hint.map(|h| h.ranges.as_slice()),
        ),
        Method::Grid => vec![grid_search(&problems[0], bounds, &req.grid)],
        Method::Aco | Method::AcoR => {
            let problem = &problems[0];
            work.seed = Some(req.seed);
            let mut rng = seeded(req.seed);
            let mut ev = Evaluator::new(problem);
            if req.method == Method::Aco {
                let mut s = aco::PaperAco::new(req.aco.clone(), req.model, bounds);
                solver::run(&mut s, &mut ev, &mut rng, req.aco.iterations, false);
            } else {
                // the Stenman band is a good first guess for the two-parameter models:
                // Kano and Choudhury with J = S, He with fd = 0 behave alike
                let seeds = stenman_d
                    .map(|d| first_guesses(req.model, d))
                    .unwrap_or_default();
                let mut s = acor::Acor::new(req.acor.clone(), req.model, bounds).with_seeds(seeds);
                solver::run(&mut s, &mut ev, &mut rng, req.acor.iterations, false);
            }
            let (best, cost, polish_evals) = polish(problem, ev.best(), ev.best_cost(), bounds);
            let (interval, extra) = axis_intervals(problem, &best, bounds, cost);
            vec![Outcome {
                best,
                interval,
                interval_kind: IntervalKind::Axis,
                evaluations: ev.evaluations() + extra + polish_evals,
                cells: None,
                top_cells: Vec::new(),
            }]
        }
    }
}

/// For a staged search: the structures best first, and the best cells of the two best, merged.
fn hint_for_whole_record(tried: &[Tried]) -> Hint {
    let mut ranges: Vec<(f64, f64)> = tried
        .iter()
        .take(2)
        .flat_map(|t| t.outcome.top_cells.iter().copied())
        .collect();
    ranges.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for r in ranges {
        match merged.last_mut() {
            Some(last) if last.1 >= r.0 => last.1 = last.1.max(r.1),
            _ => merged.push(r),
        }
    }
    Hint {
        structures: tried.iter().map(|t| t.structure).collect(),
        ranges: merged,
    }
}

/// The R² in simulation of the best linear model of the structure's family with a valve that
/// follows OP exactly: the chosen structure, and the structure of the same family the search
/// picks for it. An unstable fit's simulation runs away: no answer rather than an R² of -1e50.
fn r2_without_stiction(problem: &Hammerstein, setup: &Setup, structure: Structure) -> Option<f64> {
    let mv0 = problem.valve(&vec![0.0; problem.kind.dim()]);
    let mut same = setup.search.clone();
    same.integrating = structure.integrating;
    same.self_regulating = !structure.integrating;
    let chosen = problem
        .prepared
        .fit(&mv0)
        .filter(Fit::stable)
        .map(|f| f.r2_simulation());
    let reselected = identify::select(&setup.data, &mv0, &same)
        .and_then(|sel| identify::fit(&setup.data, &mv0, sel.structure))
        .filter(Fit::stable)
        .map(|f| f.r2_simulation());
    match (chosen, reselected) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    }
    .filter(|v| v.is_finite())
}

/// Warnings about the answer: a poor fit, a parameter at the top of its range, too few moves.
fn answer_warnings(
    fit: &Fit,
    outcome: &Outcome,
    bounds: &[(f64, f64)],
    names: &[&str],
    mv: &[f64],
) -> Vec<String> {
    let mut warnings = Vec::new();
    if fit.r2_simulation() < 0.5 {
        warnings.push(format!(
            "the simulated PV explains only {:.0} % of its variance: the stiction model and a linear process \
             do not describe this loop well; treat the estimate with care",
            100.0 * fit.r2_simulation().max(0.0)
        ));
    }
    for (p, &(lo, hi)) in bounds.iter().enumerate() {
        if let Some([a, b]) = outcome.interval.get(names[p]) {
            if *b >= hi && outcome.best[p] > lo + 0.5 * (hi - lo) {
                warnings.push(format!(
                    "{} reaches the top of its search range [{lo}, {hi}] ({a:.4} to {b:.4} fit equally): widen --bounds",
                    names[p]
                ));
            }
        }
    }
    let moves = mv.windows(2).filter(|w| w[1] != w[0]).count();
    if moves < 4 {
        warnings.push(format!(
            "the estimated valve moves only {moves} times: too few to identify the process"
        ));
    }
    warnings
}

/// The quantification from the best structure's outcome; `Err(reason)` when its fit is unusable.
fn result(
    op: &[f64],
    setup: &Setup,
    req: &QuantifyRequest,
    best: Tried,
    work: &Work,
    started: Instant,
) -> Result<Quantification, String> {
    let Tried {
        structure, outcome, ..
    } = best;
    let problem = Hammerstein::new(req.model, op, &setup.data, structure, req.valve_start);
    let Some(fit) = problem.fit(&outcome.best) else {
        return Err("the best valve trajectory leaves the linear fit singular".into());
    };
    if !fit.sse_simulation.is_finite() {
        return Err("no candidate gives a stable simulation of the PV".into());
    }
    let model = req.model.build(&outcome.best).expect("repaired");
    let mv = model.simulate_from(op, req.valve_start);
    let pv_simulated = identify::simulate_pv(&setup.data, &problem.valve(&outcome.best), &fit);
    let phys = identify::physical(&fit, req.ts);
    let names = req.model.param_names();
    let r2_without = r2_without_stiction(&problem, setup, structure);
    let band = match req.model {
        ModelKind::Stenman => outcome.best[0],
        ModelKind::He => outcome.best[0] + outcome.best[1],
        ModelKind::Kano | ModelKind::Choudhury => outcome.best[0],
    };
    let warnings = answer_warnings(&fit, &outcome, &setup.bounds, &names, &mv);
    let search = &setup.search;
    let s = fit.structure;
    let with_start = matches!(req.model, ModelKind::Stenman | ModelKind::He);
    Ok(Quantification {
        status: QuantifyStatus::Ok,
        reason: None,
        model: req.model,
        method: req.method,
        params: names
            .iter()
            .zip(&outcome.best)
            .map(|(n, &v)| (n.to_string(), v))
            .collect(),
        interval: outcome.interval,
        interval_kind: outcome.interval_kind,
        linear_model: Some(LinearModel {
            family: if s.integrating {
                LinearFamily::Integrating
            } else {
                LinearFamily::SelfRegulating
            },
            na: s.na,
            nb: s.nb,
            nk: s.nk,
            a: fit.a.clone(),
            b: fit.b.clone(),
            c: fit.c,
            gain: phys.gain,
            time_constant: phys.time_constant,
            dead_time: phys.dead_time,
            criterion: format!(
                "BIC of one-step prediction over na in {:?}, nb 1..={}, delay 1..={} samples, {}",
                search.na,
                search.nb_max,
                search.nk_max,
                match (search.self_regulating, search.integrating) {
                    (true, true) => "self-regulating and integrating",
                    (true, false) => "self-regulating",
                    _ => "integrating",
                }
            ),
        }),
        fit: Some(FitQuality {
            output: if s.integrating {
                FitOutput::DeltaPv
            } else {
                FitOutput::Pv
            },
            r2_simulation: fit.r2_simulation(),
            r2_one_step: fit.r2_one_step(),
            sse_simulation: fit.sse_simulation,
            r2_simulation_without_stiction: r2_without,
        }),
        apparent_stiction: Some(band),
        apparent_stiction_pct_of_op_range: Some(100.0 * band / setup.op_range),
        op_range: setup.op_range,
        evaluations: work.evaluations,
        cells: outcome.cells,
        valve_start: with_start.then(|| req.valve_start.unwrap_or(op[0])),
        valve_start_kind: with_start.then(|| {
            if req.valve_start.is_some() {
                ValveStartKind::Given
            } else {
                ValveStartKind::FirstOp
            }
        }),
        seconds: started.elapsed().as_secs_f64(),
        samples: op.len(),
        ts: req.ts,
        seed: work.seed,
        warnings,
        caveat: CAVEAT.into(),
        mv,
        pv_simulated,
    })
}
