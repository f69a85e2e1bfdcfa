//! Quantifying stiction from OP and PV alone: closed-loop Hammerstein identification.
//!
//!   mv = stiction_θ(op)                         (the valve position is not measured)
//!   A(q) y[t] = B(q) mv[t - nk] + c             (y = pv, or its change for integrating processes)
//!
//! Separable: for fixed stiction parameters θ the valve position is simulated from OP and the
//! linear part fitted by least squares; the outer search over θ ranks candidates by how well the
//! fitted model *simulates* the PV (output error), which one-step prediction alone does not
//! discriminate. For Stenman the outer search is exact: the d-range is partitioned into cells with
//! identical valve trajectories and every cell is fitted once. Orders and delay are chosen by BIC.
//!
//! The answer is an *apparent* stiction: inferred without the valve position, from data that an
//! oscillating loop may not make fully identifiable.

use crate::estimate::solver::{self, CostFunction, Evaluator};
use crate::estimate::{
    self, aco, acor, exact, AcoSettings, AcorSettings, EstimateError, GridSettings, Method,
};
use crate::identify::{self, Data, Fit, SearchRange, Structure};
use crate::models::ModelKind;
use crate::rng::seeded;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Instant;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct QuantifyRequest {
    pub model: ModelKind,
    pub method: Method,
    /// Sampling time in seconds (for the time constant and dead time).
    pub ts: f64,
    /// Search range per stiction parameter; `None`: 0 up to the OP's peak-to-peak range.
    pub bounds: Option<Vec<(f64, f64)>>,
    pub seed: u64,
    pub aco: AcoSettings,
    pub acor: AcorSettings,
    pub grid: GridSettings,
    /// Largest delay tried, in samples.
    pub max_delay: usize,
    /// `Some(true)`: integrating process only; `Some(false)`: self-regulating only; `None`: both.
    pub integrating: Option<bool>,
    /// Stenman exact: fit every cell of the whole d-range, not only those around the best scan points.
    pub full_partition: bool,
    /// Stenman exact on long records: search the whole d-range on the first samples, then only
    /// the best cells of that search on the whole record (every whole-record cell lies inside one
    /// cell of the first samples', so this is exact over the cells kept). `false`: every cell of
    /// the whole record.
    pub staged: bool,
    /// The valve position at the first sample (Stenman and He); `None`: where OP starts, as if
    /// the valve had just moved there (unless `estimate_start` chooses one).
    #[serde(default)]
    pub valve_start: Option<f64>,
    /// Stenman exact: choose the valve position at the first sample (a record rarely starts just
    /// as the valve moved) among candidates across the OP's span, by the fit on the first samples.
    /// Off by default: it costs about four more searches of the first samples.
    #[serde(default)]
    pub estimate_start: bool,
}

impl QuantifyRequest {
    pub fn new(model: ModelKind, method: Method) -> Self {
        let grid = GridSettings { points: 40 };
        Self {
            model,
            method,
            ts: 1.0,
            bounds: None,
            seed: 1,
            aco: AcoSettings::default(),
            acor: AcorSettings {
                iterations: 60,
                ..AcorSettings::default()
            },
            grid,
            max_delay: 30,
            integrating: None,
            full_partition: true,
            staged: true,
            valve_start: None,
            estimate_start: false,
        }
    }
}

/// The identified linear part.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LinearModel {
    /// "self_regulating" (output pv) or "integrating" (output: the change of pv per sample).
    pub family: String,
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
    /// The output the R² refer to: "pv" or "delta_pv".
    pub output: String,
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
    /// "ok" or "insufficient_data".
    pub status: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    pub model: ModelKind,
    pub method: Method,
    pub params: BTreeMap<String, f64>,
    /// Per parameter, the values that fit equally well: exact for Stenman with `exact` (the cells of
    /// least simulation error); for other methods, along each axis with the others held at the
    /// estimate.
    pub interval: BTreeMap<String, [f64; 2]>,
    pub interval_kind: String,
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
    pub valve_start_kind: Option<String>,
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

const CAVEAT: &str = "apparent stiction inferred from OP and PV without the valve position; \
oscillating closed-loop data may not identify the valve and the process separately";

impl Quantification {
    fn insufficient(req: &QuantifyRequest, n: usize, op_range: f64, reason: String) -> Self {
        Self {
            status: "insufficient_data".into(),
            reason: Some(reason),
            model: req.model,
            method: req.method,
            params: BTreeMap::new(),
            interval: BTreeMap::new(),
            interval_kind: "none".into(),
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

fn range(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// The closed-loop objective: simulation error of the least-squares linear fit for the valve
/// trajectory of each candidate.
struct Hammerstein<'a> {
    kind: ModelKind,
    op: &'a [f64],
    prepared: identify::Prepared<'a>,
    /// Subtracted from the valve position (the mean OP) to keep the normal equations well scaled.
    offset: f64,
    /// The valve position at the first sample (`None`: the first OP).
    start: Option<f64>,
}

impl<'a> Hammerstein<'a> {
    fn new(
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
        }
    }

    fn valve_into(&self, theta: &[f64], mv: &mut [f64]) {
        let model = self.kind.build(theta).expect("candidates are repaired");
        model.simulate_from_into(self.op, self.start, mv);
        for v in mv.iter_mut() {
            *v -= self.offset;
        }
    }

    fn valve(&self, theta: &[f64]) -> Vec<f64> {
        let mut mv = vec![0.0; self.op.len()];
        self.valve_into(theta, &mut mv);
        mv
    }

    fn fit(&self, theta: &[f64]) -> Option<Fit> {
        self.prepared.fit(&self.valve(theta))
    }

    /// The cost of one candidate, with a caller's buffer for the valve position.
    fn cost_with(&self, theta: &[f64], mv: &mut [f64]) -> f64 {
        self.valve_into(theta, mv);
        self.prepared
            .fit(mv)
            .map_or(f64::INFINITY, |f| f.sse_simulation)
    }

    fn cost(&self, theta: &[f64]) -> f64 {
        self.cost_with(theta, &mut vec![0.0; self.op.len()])
    }

    /// Costs of many one-parameter candidates, in parallel, one buffer per thread.
    fn costs_1d(&self, values: &[f64]) -> Vec<f64> {
        let n = self.op.len();
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
}

impl CostFunction for Hammerstein<'_> {
    fn dim(&self) -> usize {
        self.kind.dim()
    }
    fn eval_batch(&self, candidates: &[f64], costs: &mut [f64]) {
        let dim = self.dim();
        let n = self.op.len();
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

/// Quantify stiction from OP and PV. Data that cannot be judged gives `status: insufficient_data`
/// with the reason; requests that are wrong (bounds, settings) give an error.
pub fn quantify(
    op: &[f64],
    pv: &[f64],
    req: &QuantifyRequest,
) -> Result<Quantification, EstimateError> {
    let started = Instant::now();
    let n = op.len();
    if !(req.model == ModelKind::Stenman && req.method == Method::Exact && pv.len() == n) {
        return quantify_inner(op, pv, req, None).map(|r| r.0);
    }
    let staged = req.staged && n >= STAGE_FROM;
    let estimate_start = req.estimate_start && req.valve_start.is_none();
    // the first samples: at least a few oscillation periods (too short a start ranks the
    // cells by the transient)
    let m = if n >= STAGE_FROM && (staged || estimate_start) {
        let period = crate::detect::regularity(pv, 1.0).period.unwrap_or(0.0);
        STAGE_SAMPLES
            .max((STAGE_PERIODS * period) as usize)
            .min(n / 2)
    } else {
        n
    };
    let mut req = req.clone();
    let mut extra = 0;
    let mut at_first_op = None;
    if estimate_start {
        // where the valve stood at the first sample: the candidate whose search of the first
        // samples fits best (the first OP is one of them); it must then also fit the whole
        // record better than the first OP does
        let (best, evaluations) = best_start(&op[..m], &pv[..m], &req);
        extra += evaluations;
        if best.is_some_and(|x0| x0 != op[0]) {
            let mut plain = req.clone();
            plain.estimate_start = false;
            at_first_op = Some(quantify(op, pv, &plain)?);
        }
        req.valve_start = best;
    }
    let finish = |mut q: Quantification, extra: u64| {
        q.evaluations += extra;
        q.seconds = started.elapsed().as_secs_f64();
        if estimate_start && q.valve_start.is_some() {
            q.valve_start_kind = Some("estimated".into());
        }
        q
    };
    let mut answer = None;
    if staged {
        // stage 1: the whole d-range on the first samples (same valve start, so every
        // whole-record cell lies inside one of its cells)
        let mut first = req.clone();
        first.staged = false;
        first.full_partition = true;
        if let Ok((q, hint)) = quantify_inner(&op[..m], &pv[..m], &first, None) {
            if q.status == "ok" && !hint.ranges.is_empty() {
                let (full, _) = quantify_inner(op, pv, &req, Some(&hint))?;
                extra += q.evaluations;
                answer = Some(full);
            }
        }
    }
    let answer = match answer {
        Some(a) => a,
        None => quantify_inner(op, pv, &req, None)?.0,
    };
    let sse = |q: &Quantification| q.fit.as_ref().map_or(f64::INFINITY, |f| f.sse_simulation);
    Ok(match at_first_op {
        Some(plain) if sse(&plain) <= sse(&answer) => {
            let spent = answer.evaluations;
            finish(plain, extra + spent)
        }
        Some(plain) => {
            let spent = plain.evaluations;
            finish(answer, extra + spent)
        }
        None => finish(answer, extra),
    })
}

/// A record rarely starts just as the valve moved, and a Stenman valve started elsewhere can stay
/// out of step with the real one for good. Each candidate position at the first sample (the first
/// OP and a spread across the span OP covers) gets a search of `op`, `pv` (the exact search
/// around its best grid points); the one that fits best is returned, with the evaluations spent.
fn best_start(op: &[f64], pv: &[f64], req: &QuantifyRequest) -> (Option<f64>, u64) {
    let mut local = req.clone();
    local.staged = false;
    local.full_partition = false;
    let mut evaluations = 0;
    let mut best: Option<(f64, f64)> = None;
    for x0 in start_candidates(op) {
        local.valve_start = Some(x0);
        let Ok((q, _)) = quantify_inner(op, pv, &local, None) else {
            continue;
        };
        evaluations += q.evaluations;
        if let Some(sse) = q.fit.as_ref().map(|f| f.sse_simulation) {
            if q.status == "ok" && best.is_none_or(|b| sse < b.0) {
                best = Some((sse, x0));
            }
        }
    }
    (best.map(|b| b.1), evaluations)
}

/// Candidate valve positions at the first sample: the first OP, and a spread across the span
/// OP covers in `op` (a valve that sticks stands anywhere within its band of the command).
fn start_candidates(op: &[f64]) -> Vec<f64> {
    let Some(&u0) = op.first() else {
        return Vec::new();
    };
    let (lo, hi) = range(op);
    let span = hi - lo;
    let mut out = vec![u0];
    for f in [-0.5, -0.25, 0.25, 0.5] {
        let x = (u0 + f * span).clamp(lo, hi);
        if out.iter().all(|&y| (y - x).abs() > 0.05 * span) {
            out.push(x);
        }
    }
    out
}

/// What a staged search carries from the first samples to the whole record.
struct Hint {
    /// The structures tried, best first.
    structures: Vec<Structure>,
    /// The cells of least cost, merged, in increasing d.
    ranges: Vec<(f64, f64)>,
}

fn quantify_inner(
    op: &[f64],
    pv: &[f64],
    req: &QuantifyRequest,
    hint: Option<&Hint>,
) -> Result<(Quantification, Hint), EstimateError> {
    let started = Instant::now();
    let n = op.len();
    estimate::check_pair(("op", op), ("pv", pv))?;
    if !(req.ts > 0.0 && req.ts.is_finite()) {
        return Err(EstimateError::Settings(format!(
            "the sampling time must be a positive number of seconds, got {}",
            req.ts
        )));
    }
    if req.method == Method::Exact && req.model != ModelKind::Stenman {
        return Err(EstimateError::ExactNeedsStenman(req.model));
    }
    let (op_lo, op_hi) = range(op);
    let (pv_lo, pv_hi) = range(pv);
    let op_range = if n > 0 { op_hi - op_lo } else { 0.0 };
    let mut search = SearchRange::new(req.max_delay.min(n / 20).max(1));
    if let Some(integrating) = req.integrating {
        search.integrating = integrating;
        search.self_regulating = !integrating;
    }
    let needed = search.t0() + 20 * (search.na.len() + search.nb_max + 1);
    let insufficient = |why: String| {
        Ok((
            Quantification::insufficient(req, n, op_range.max(0.0), why),
            Hint {
                structures: Vec::new(),
                ranges: Vec::new(),
            },
        ))
    };
    if n < needed {
        return insufficient(format!(
            "only {n} samples; the linear model search (delays up to {} samples) needs at least {needed}",
            search.nk_max
        ));
    }
    if op_range <= 0.0 {
        return insufficient(format!(
            "OP is constant at {op_lo}: the valve is never moved"
        ));
    }
    if pv_hi - pv_lo <= 0.0 {
        return insufficient(format!(
            "PV is constant at {pv_lo}: nothing responds to the valve"
        ));
    }
    let saturated = op.iter().filter(|&&v| v <= 0.0 || v >= 100.0).count();
    if saturated == n {
        return insufficient("OP is saturated (at or beyond 0 or 100 %) the whole time".into());
    }

    let bounds: Vec<(f64, f64)> = match &req.bounds {
        Some(b) => b.clone(),
        None => vec![(0.0, op_range); req.model.dim()],
    };
    estimate::check_bounds(req.model, &bounds)?;

    let data = Data::new(pv, search.t0());
    let mut evaluations = 0u64;
    // pilot: the process family and a first structure, chosen at a spread of stiction parameters
    // (a staged search runs them again on the whole record: the first samples may be too few
    // to tell the structure)
    let pilots: Vec<Vec<f64>> = if hint.is_some() {
        // the whole record's pilots: a quarter of the spread is enough to add its structures
        pilot_points(req.model, &bounds)
            .into_iter()
            .step_by(4)
            .collect()
    } else {
        pilot_points(req.model, &bounds)
    };
    let choices: Vec<identify::Selection> = pilots
        .par_iter()
        .filter_map(|theta| {
            let model = req.model.build(theta).ok()?;
            identify::select(
                &data,
                &identify::centred(&model.simulate_from(op, req.valve_start)),
                &search,
            )
        })
        .collect();
    evaluations += pilots.len() as u64;
    // the distinct structures the pilots chose, best one-step fit first: the first few are searched
    let mut ranked: Vec<identify::Selection> = choices.clone();
    ranked.sort_by(|a, b| a.one_step_bic.total_cmp(&b.one_step_bic));
    let mut queue: std::collections::VecDeque<Structure> = Default::default();
    // two-parameter models start from the Stenman answer (structure and band), which the exact
    // search finds reliably
    let mut stenman_d = None;
    if req.model.dim() == 2 {
        let mut sreq = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
        sreq.ts = req.ts;
        sreq.max_delay = req.max_delay;
        sreq.integrating = req.integrating;
        sreq.bounds = Some(vec![(bounds[0].0, bounds[0].1.max(bounds[1].1))]);
        let sq = quantify(op, pv, &sreq)?;
        evaluations += sq.evaluations;
        if let (Some(lm), Some(d)) = (&sq.linear_model, sq.params.get("d")) {
            queue.push_back(Structure {
                integrating: lm.family == "integrating",
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
    // the structure of a valve without stiction is always searched: the answer is then never
    // worse than the linear loop it is compared with
    let lows: Vec<f64> = bounds.iter().map(|b| b.0).collect();
    if let Some(sel) = req.model.build(&lows).ok().and_then(|m| {
        identify::select(
            &data,
            &identify::centred(&m.simulate_from(op, req.valve_start)),
            &search,
        )
    }) {
        if !queue.contains(&sel.structure) {
            queue.push_back(sel.structure);
        }
    }
    if queue.is_empty() {
        return insufficient(
            "no linear model could be fitted: the valve trajectory never excites the PV".into(),
        );
    }

    // search the stiction parameters for each structure; confirm the structure at each answer and
    // search again with a new one if it differs; keep the answer whose simulation BIC is least
    let mut seed = None;
    let mut tried: Vec<(Structure, Outcome, f64)> = Vec::new();
    while !queue.is_empty() && tried.len() < MOST_STRUCTURES {
        // the structures of this round: for Stenman exact all queued ones share one walk
        let mut round: Vec<Structure> = Vec::new();
        while let Some(s) = queue.pop_front() {
            if !tried.iter().any(|t| t.0 == s)
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
            .map(|&s| Hammerstein::new(req.model, op, &data, s, req.valve_start))
            .collect();
        let outcomes = match req.method {
            Method::Exact => exact_stenman(
                &problems,
                bounds[0],
                req.full_partition,
                hint.map(|h| h.ranges.as_slice()),
            ),
            Method::Grid => vec![grid_search(&problems[0], &bounds, &req.grid)],
            Method::Aco | Method::AcoR => {
                let problem = &problems[0];
                seed = Some(req.seed);
                let mut rng = seeded(req.seed);
                let mut ev = Evaluator::new(problem);
                if req.method == Method::Aco {
                    let mut s = aco::PaperAco::new(req.aco.clone(), req.model, &bounds);
                    solver::run(&mut s, &mut ev, &mut rng, req.aco.iterations, false);
                } else {
                    // the Stenman band is a good first guess for the two-parameter models:
                    // Kano and Choudhury with J = S, He with fd = 0 behave alike
                    let seeds = stenman_d
                        .map(|d| first_guesses(req.model, d))
                        .unwrap_or_default();
                    let mut s =
                        acor::Acor::new(req.acor.clone(), req.model, &bounds).with_seeds(seeds);
                    solver::run(&mut s, &mut ev, &mut rng, req.acor.iterations, false);
                }
                let (best, cost, polish_evals) =
                    polish(problem, ev.best(), ev.best_cost(), &bounds);
                let (interval, extra) = axis_intervals(problem, &best, &bounds, cost);
                vec![Outcome {
                    best,
                    interval,
                    interval_kind: "axis",
                    evaluations: ev.evaluations() + extra + polish_evals,
                    cells: None,
                    top_cells: Vec::new(),
                }]
            }
        };
        // a walk shared by several structures counts once
        evaluations += outcomes.iter().map(|o| o.evaluations).max().unwrap_or(0);
        for (problem, outcome) in problems.iter().zip(outcomes) {
            let mv_c = problem.valve(&outcome.best);
            let criterion = problem.fit(&outcome.best).map_or(f64::INFINITY, |f| {
                identify::level_simulation_bic(&data, &mv_c, &f)
            });
            tried.push((problem.prepared.structure(), outcome, criterion));
            evaluations += 1;
            // confirm the structure at this answer; a different one is searched next, first
            if let Some(next) = identify::select(&data, &mv_c, &search) {
                if !tried.iter().any(|t| t.0 == next.structure) && !queue.contains(&next.structure)
                {
                    queue.push_front(next.structure);
                }
            }
        }
    }
    tried.sort_by(|a, b| a.2.total_cmp(&b.2));
    // for a staged search: the structures best first, and the best cells of the two best
    let mut ranges: Vec<(f64, f64)> = tried
        .iter()
        .take(2)
        .flat_map(|t| t.1.top_cells.iter().copied())
        .collect();
    ranges.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for r in ranges {
        match merged.last_mut() {
            Some(last) if last.1 >= r.0 => last.1 = last.1.max(r.1),
            _ => merged.push(r),
        }
    }
    let next = Hint {
        structures: tried.iter().map(|t| t.0).collect(),
        ranges: merged,
    };
    let (structure, outcome, _) = tried.into_iter().next().expect("at least one search ran");

    let problem = Hammerstein::new(req.model, op, &data, structure, req.valve_start);
    let Some(fit) = problem.fit(&outcome.best) else {
        return insufficient("the best valve trajectory leaves the linear fit singular".into());
    };
    if !fit.sse_simulation.is_finite() {
        return insufficient("no candidate gives a stable simulation of the PV".into());
    }
    let model = req.model.build(&outcome.best).expect("repaired");
    let mv = model.simulate_from(op, req.valve_start);
    let pv_simulated = identify::simulate_pv(&data, &problem.valve(&outcome.best), &fit);
    let phys = identify::physical(&fit, req.ts);
    let names = req.model.param_names();
    // the same data through a valve without stiction: the chosen structure, and the structure
    // of the same family the search picks for it
    let r2_without = {
        let mv0 = problem.valve(&vec![0.0; req.model.dim()]);
        let mut same = search.clone();
        same.integrating = structure.integrating;
        same.self_regulating = !structure.integrating;
        // an unstable fit's simulation runs away: no answer rather than an R² of -1e50
        let chosen = problem
            .prepared
            .fit(&mv0)
            .filter(Fit::stable)
            .map(|f| f.r2_simulation());
        let reselected = identify::select(&data, &mv0, &same)
            .and_then(|sel| identify::fit(&data, &mv0, sel.structure))
            .filter(Fit::stable)
            .map(|f| f.r2_simulation());
        match (chosen, reselected) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
        .filter(|v| v.is_finite())
    };
    let band = match req.model {
        ModelKind::Stenman => outcome.best[0],
        ModelKind::He => outcome.best[0] + outcome.best[1],
        ModelKind::Kano | ModelKind::Choudhury => outcome.best[0],
    };
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
    let s = fit.structure;
    Ok((
        Quantification {
            status: "ok".into(),
            reason: None,
            model: req.model,
            method: req.method,
            params: names
                .iter()
                .zip(&outcome.best)
                .map(|(n, &v)| (n.to_string(), v))
                .collect(),
            interval: outcome.interval,
            interval_kind: outcome.interval_kind.into(),
            linear_model: Some(LinearModel {
                family: if s.integrating {
                    "integrating"
                } else {
                    "self_regulating"
                }
                .into(),
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
                output: if s.integrating { "delta_pv" } else { "pv" }.into(),
                r2_simulation: fit.r2_simulation(),
                r2_one_step: fit.r2_one_step(),
                sse_simulation: fit.sse_simulation,
                r2_simulation_without_stiction: r2_without,
            }),
            apparent_stiction: Some(band),
            apparent_stiction_pct_of_op_range: Some(100.0 * band / op_range),
            op_range,
            evaluations,
            cells: outcome.cells,
            valve_start: matches!(req.model, ModelKind::Stenman | ModelKind::He)
                .then(|| req.valve_start.unwrap_or(op[0])),
            valve_start_kind: matches!(req.model, ModelKind::Stenman | ModelKind::He).then(|| {
                if req.valve_start.is_some() {
                    "given"
                } else {
                    "first_op"
                }
                .to_string()
            }),
            seconds: started.elapsed().as_secs_f64(),
            samples: n,
            ts: req.ts,
            seed,
            warnings,
            caveat: CAVEAT.into(),
            mv,
            pv_simulated,
        },
        next,
    ))
}

/// Starting points for a two-parameter search from the Stenman band d.
fn first_guesses(kind: ModelKind, d: f64) -> Vec<Vec<f64>> {
    let mut out = match kind {
        ModelKind::He => vec![
            vec![d, 0.0],
            vec![d, 0.25 * d],
            vec![d, 0.5 * d],
            vec![1.5 * d, 0.5 * d],
        ],
        _ => vec![
            vec![d, d],
            vec![d, 0.5 * d],
            vec![d, 0.25 * d],
            vec![1.5 * d, 0.5 * d],
            vec![1.5 * d, d],
            vec![2.0 * d, d],
            vec![0.75 * d, 0.75 * d],
        ],
    };
    for g in &mut out {
        kind.repair(g);
    }
    out
}

/// Polish a two-parameter answer by coordinate scans: each parameter in turn over a fine grid
/// around its value (the objective is a step function, so gradients cannot do this), narrowing
/// three times.
fn polish(
    problem: &Hammerstein,
    start: &[f64],
    cost: f64,
    bounds: &[(f64, f64)],
) -> (Vec<f64>, f64, u64) {
    const POINTS: usize = 161;
    let mut best = start.to_vec();
    let mut best_cost = cost;
    let mut evals = 0u64;
    let dim = best.len();
    for round in 0..3 {
        for p in 0..dim {
            let (lo, hi) = bounds[p];
            let width = 0.5f64.powi(round) * 0.5 * best[p].abs().max(0.05 * (hi - lo));
            let (a, b) = ((best[p] - width).max(lo), (best[p] + width).min(hi));
            let mut cands = Vec::with_capacity(POINTS * dim);
            for i in 0..POINTS {
                let mut theta = best.clone();
                theta[p] = a + (b - a) * i as f64 / (POINTS - 1) as f64;
                problem.kind.repair(&mut theta);
                cands.extend_from_slice(&theta);
            }
            let mut costs = vec![0.0; POINTS];
            problem.eval_batch(&cands, &mut costs);
            evals += POINTS as u64;
            for (i, &c) in costs.iter().enumerate() {
                if c < best_cost {
                    best_cost = c;
                    best.copy_from_slice(&cands[i * dim..(i + 1) * dim]);
                }
            }
        }
    }
    (best, best_cost, evals)
}

/// Structures from the pilots that are searched first, and the most searched in all.
const STARTING_STRUCTURES: usize = 4;
const MOST_STRUCTURES: usize = 8;

struct Outcome {
    best: Vec<f64>,
    interval: BTreeMap<String, [f64; 2]>,
    interval_kind: &'static str,
    evaluations: u64,
    cells: Option<usize>,
    /// Stenman exact: the cells of least cost, best first (for a staged search).
    top_cells: Vec<(f64, f64)>,
}

/// Parameter sets at which the linear structure is chosen before the main search.
fn pilot_points(kind: ModelKind, bounds: &[(f64, f64)]) -> Vec<Vec<f64>> {
    // geometric spread: stiction bands are usually a small share of the OP range
    let axis = |(lo, hi): (f64, f64), k: usize| -> Vec<f64> {
        let first = (hi - lo) * 0.005;
        (0..k)
            .map(|i| lo + first * ((hi - lo) / first).powf(i as f64 / (k - 1) as f64))
            .collect()
    };
    if kind.dim() == 1 {
        let (lo, hi) = bounds[0];
        let mut v: Vec<Vec<f64>> = axis(bounds[0], 24).into_iter().map(|d| vec![d]).collect();
        v.extend((0..8).map(|i| vec![lo + (hi - lo) * (i as f64 + 0.5) / 8.0]));
        v.push(vec![lo]);
        v
    } else {
        let mut out = Vec::new();
        for a in axis(bounds[0], 5) {
            for b in axis(bounds[1], 4) {
                let mut p = vec![a, b];
                kind.repair(&mut p);
                out.push(p);
            }
        }
        out
    }
}

/// Cells of the first samples carried into the whole-record search of a staged search.
const TOP_CELLS: usize = 24;
/// A staged search starts on this many samples ...
const STAGE_SAMPLES: usize = 600;
/// ... or this many oscillation periods of the PV, if more, up to half the record ...
const STAGE_PERIODS: f64 = 8.0;
/// ... when the record has at least this many samples.
const STAGE_FROM: usize = 1500;

/// A cell of the d-partition with its cost under each structure.
type CellCosts = ((f64, f64), Vec<f64>);

/// Stenman, exact: every distinct valve trajectory (cell of the partition of the d-range) is
/// simulated once and fitted with each of the given linear structures. The range is cut into fixed
/// chunks walked in parallel, so the work spreads over threads and the result does not depend on
/// their number. Without `full`, only the chunks around the best points of a coarse scan are walked
/// (faster, exact only there). One outcome per structure, in order.
fn exact_stenman(
    problems: &[Hammerstein],
    (lo, hi): (f64, f64),
    full: bool,
    only: Option<&[(f64, f64)]>,
) -> Vec<Outcome> {
    const CHUNKS: usize = 64;
    let mut chunks: Vec<(f64, f64)> = match only {
        // a staged search: the given ranges, each cut in a few chunks for the threads
        Some(ranges) => ranges
            .iter()
            .flat_map(|&(a, b)| {
                let k = 4;
                (0..k).map(move |i| {
                    (
                        a + (b - a) * i as f64 / k as f64,
                        a + (b - a) * (i + 1) as f64 / k as f64,
                    )
                })
            })
            .filter(|c| c.1 > c.0)
            .collect(),
        None => {
            let first = (hi - lo) * 1e-4;
            let mut edges: Vec<f64> = (0..CHUNKS)
                .map(|i| lo + first * ((hi - lo) / first).powf(i as f64 / (CHUNKS - 1) as f64))
                .collect();
            edges[0] = lo;
            edges.push(hi);
            edges.dedup();
            edges.windows(2).map(|w| (w[0], w[1])).collect()
        }
    };
    let full = full || only.is_some();
    let scan: Vec<f64> = chunks.iter().map(|c| 0.5 * (c.0 + c.1)).collect();
    let scan_costs: Vec<Vec<f64>> = problems.iter().map(|p| p.costs_1d(&scan)).collect();
    if !full {
        let mut keep = Vec::new();
        for costs in &scan_costs {
            let mut order: Vec<usize> = (0..chunks.len()).collect();
            order.sort_by(|&i, &j| costs[i].total_cmp(&costs[j]));
            keep.extend(
                order
                    .iter()
                    .take(3)
                    .flat_map(|&i| [i.saturating_sub(1), i, (i + 1).min(chunks.len() - 1)]),
            );
        }
        chunks = chunks
            .iter()
            .enumerate()
            .filter(|(i, _)| keep.contains(i))
            .map(|(_, &c)| c)
            .collect();
    }
    // achievable costs to start from: simulations that exceed them stop early (such a cell can
    // never be optimal, so the optimal set is the same whatever the order of the work)
    let start_bounds: Vec<f64> = scan_costs
        .iter()
        .map(|c| c.iter().copied().fold(f64::INFINITY, f64::min))
        .collect();
    let n = problems[0].op.len();
    let offset = problems[0].offset;
    // Consecutive cells' trajectories differ only on short stretches (they join again at the next
    // slip both make), so each walk keeps the least-squares sums of its previous cell and updates
    // only the rows that see a changed sample; a full recomputation now and then bounds rounding.
    const FULL_EVERY: usize = 256;
    let per_chunk: Vec<Vec<CellCosts>> = chunks
        .par_iter()
        .map_init(
            || (vec![0.0f64; n], vec![0.0f64; n], Vec::new(), Vec::new()),
            |(mv, prev, changed, rows), &chunk| {
                let mut out = Vec::new();
                let mut bounds = start_bounds.clone();
                let mut sums: Vec<identify::ValveSums> = Vec::new();
                let x0 = problems[0].start.unwrap_or(problems[0].op[0]);
                exact::stenman_walk(problems[0].op, x0, chunk, (lo, hi), mv, |cell, mv| {
                    for v in mv.iter_mut() {
                        *v -= offset;
                    }
                    changed.clear();
                    if !sums.is_empty() && out.len() % FULL_EVERY != 0 {
                        // compare blocks of samples bit for bit; most blocks are unchanged
                        for (blk, (m, p)) in mv.chunks(16).zip(prev.chunks(16)).enumerate() {
                            let differs = m
                                .iter()
                                .zip(p)
                                .fold(0u64, |acc, (x, y)| acc | (x.to_bits() ^ y.to_bits()));
                            if differs != 0 {
                                let base = blk * 16;
                                changed.extend(
                                    (0..m.len())
                                        .filter(|&i| m[i].to_bits() != p[i].to_bits())
                                        .map(|i| base + i),
                                );
                            }
                        }
                    }
                    let incremental =
                        !sums.is_empty() && out.len() % FULL_EVERY != 0 && changed.len() < n / 8;
                    if incremental {
                        for (p, s) in problems.iter().zip(sums.iter_mut()) {
                            p.prepared.update_sums(s, prev, mv, changed, rows);
                        }
                    } else {
                        sums = problems.iter().map(|p| p.prepared.sums(mv)).collect();
                    }
                    let costs: Vec<f64> = problems
                        .iter()
                        .zip(&sums)
                        .zip(bounds.iter_mut())
                        .map(|((p, s), bound)| {
                            let c = p
                                .prepared
                                .fit_from_sums(s, mv, *bound)
                                .map_or(f64::INFINITY, |f| f.sse_simulation);
                            *bound = bound.min(c);
                            c
                        })
                        .collect();
                    prev.copy_from_slice(mv);
                    out.push((cell, costs));
                });
                out
            },
        )
        .collect();
    let cells: Vec<CellCosts> = per_chunk.into_iter().flatten().collect();
    (0..problems.len())
        .map(|s| {
            let best = cells.iter().map(|c| c.1[s]).fold(f64::INFINITY, f64::min);
            // sums updated step by step round differently from fresh ones: a hair of tolerance
            // keeps the pieces of one trajectory together
            let tolerance = 1e-9 * best.abs();
            let mut optimal: Vec<(f64, f64)> = Vec::new();
            for (cell, costs) in &cells {
                if costs[s] <= best + tolerance {
                    match optimal.last_mut() {
                        // pieces of one cell split at a chunk edge join again
                        Some(last) if last.1 >= cell.0 => last.1 = last.1.max(cell.1),
                        _ => optimal.push(*cell),
                    }
                }
            }
            // the widest optimal piece's midpoint is the point estimate; the interval their hull
            let (a, b) = optimal
                .iter()
                .copied()
                .max_by(|x, y| (x.1 - x.0).total_cmp(&(y.1 - y.0)))
                .unwrap_or((lo, hi));
            let hull = [
                optimal.first().map_or(lo, |c| c.0),
                optimal.last().map_or(hi, |c| c.1),
            ];
            let mut ranked: Vec<&CellCosts> = cells.iter().collect();
            ranked.sort_by(|x, y| x.1[s].total_cmp(&y.1[s]).then(x.0 .0.total_cmp(&y.0 .0)));
            Outcome {
                best: vec![0.5 * (a + b)],
                interval: BTreeMap::from([("d".to_string(), hull)]),
                interval_kind: match (only.is_some(), full) {
                    (true, _) => "exact_staged",
                    (false, true) => "exact",
                    (false, false) => "exact_local",
                },
                evaluations: (cells.len() + scan.len()) as u64,
                cells: Some(cells.len()),
                // the best cells, and the lowest (a valve without stiction is always a candidate)
                top_cells: ranked
                    .iter()
                    .take(TOP_CELLS)
                    .map(|c| c.0)
                    .chain(cells.first().map(|c| c.0))
                    .collect(),
            }
        })
        .collect()
}

fn grid_search(problem: &Hammerstein, bounds: &[(f64, f64)], settings: &GridSettings) -> Outcome {
    let dim = bounds.len();
    let per = settings.points.max(2);
    let axes: Vec<Vec<f64>> = bounds
        .iter()
        .map(|&(lo, hi)| {
            (0..per)
                .map(|i| lo + (hi - lo) * i as f64 / (per - 1) as f64)
                .collect()
        })
        .collect();
    let total = per.pow(dim as u32);
    let mut cands = Vec::with_capacity(total * dim);
    for i in 0..total {
        let start = cands.len();
        let mut rest = i;
        for axis in axes.iter().rev() {
            cands.push(axis[rest % per]);
            rest /= per;
        }
        cands[start..].reverse();
        problem.kind.repair(&mut cands[start..]);
    }
    let mut costs = vec![0.0; total];
    problem.eval_batch(&cands, &mut costs);
    let best_i = (0..total).fold(0, |m, i| if costs[i] < costs[m] { i } else { m });
    let best = cands[best_i * dim..(best_i + 1) * dim].to_vec();
    let mut interval = BTreeMap::new();
    for (p, name) in problem.kind.param_names().iter().enumerate() {
        let vals: Vec<f64> = (0..total)
            .filter(|&i| costs[i] == costs[best_i])
            .map(|i| cands[i * dim + p])
            .collect();
        let (a, b) = range(&vals);
        interval.insert(name.to_string(), [a, b]);
    }
    Outcome {
        best,
        interval,
        interval_kind: "grid",
        evaluations: total as u64,
        cells: None,
        top_cells: Vec::new(),
    }
}

/// Along each axis from the estimate, the stretch over which the cost stays at the optimum
/// (the objective is a step function of the stiction parameters): doubling steps out, then bisection.
fn axis_intervals(
    problem: &Hammerstein,
    best: &[f64],
    bounds: &[(f64, f64)],
    best_cost: f64,
) -> (BTreeMap<String, [f64; 2]>, u64) {
    let mut out = BTreeMap::new();
    let mut evals = 0u64;
    let names = problem.kind.param_names();
    for (p, &(lo, hi)) in bounds.iter().enumerate() {
        let mut ends = [best[p]; 2];
        for (side, end) in ends.iter_mut().enumerate() {
            let limit = if side == 0 { lo } else { hi };
            let at = |v: f64| {
                let mut theta = best.to_vec();
                theta[p] = v;
                problem.kind.repair(&mut theta);
                // a repair that moves another parameter leaves this axis
                (theta[p] == v).then(|| problem.cost(&theta))
            };
            let same = |c: Option<f64>| c.is_some_and(|c| c <= best_cost);
            // step out until the cost changes or the bound is reached
            let mut inside = best[p];
            let mut step = 1e-4 * (hi - lo);
            let mut outside = None;
            for _ in 0..40 {
                let v = if side == 0 {
                    (inside - step).max(limit)
                } else {
                    (inside + step).min(limit)
                };
                evals += 1;
                if same(at(v)) {
                    inside = v;
                    if v == limit {
                        break;
                    }
                    step *= 2.0;
                } else {
                    outside = Some(v);
                    break;
                }
            }
            if let Some(mut out_v) = outside {
                for _ in 0..30 {
                    let mid = 0.5 * (inside + out_v);
                    evals += 1;
                    if same(at(mid)) {
                        inside = mid;
                    } else {
                        out_v = mid;
                    }
                }
            }
            *end = inside;
        }
        out.insert(names[p].to_string(), ends);
    }
    (out, evals)
}
