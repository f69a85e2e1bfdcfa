//! Detection by fit (Srinivasan, Rengaswamy and Miller 2005, "A Hammerstein model approach for
//! stiction diagnosis"): the closed-loop Hammerstein model with and without stiction, on the same
//! samples and linear structures. Where `quantify` proves the optimal band, this asks a question
//! cheap enough to ask of every loop: how much better does any band explain the PV than a valve
//! that follows OP?
//!
//! Routine records carry load changes that OP does not explain: a load that drifts enters the
//! process beside the valve, the controller moves the valve against it, and PV stays put while the
//! valve moves. Fitted on levels, even the true valve position then explains PV worse than OP
//! does. So both fits compare *changes over a lag* of about the process's response time,
//! `pv[t + L] - pv[t]` against the valve's `mv[t + L] - mv[t]`: the linear part is the same, and
//! drifts slower than the lag fall away. A level's change over the lag is its inflow, so for an
//! integrating process the valve is summed over the lag instead ([`OverLag::Sum`]), and the fits'
//! models of the PV are the integrating structures that implies.
//!
//! The stages: the lag (from a first linear fit), where the valve stood at the first sample (a
//! Stenman valve started elsewhere stays out of step with the real one for good: candidates are
//! judged on the first samples), the exact Stenman band (every distinct valve trajectory; staged
//! on long records), Kano's band and slip jump around it, and all fits moved to their output-error
//! optimum before they are compared, each also started from the other's dynamics (a search from
//! one start can stop short: on fast-c-0024 of the catalogue the stiction fit's own stopped at R²
//! 0.416, under the linear loop's 0.430, and from the linear loop's dynamics reaches 0.449).

mod band;
mod dependence;
mod fits;
mod lag;
mod setup;
pub use dependence::correlation_span;
pub use lag::off_the_pv_cycle;

use super::problem::{over_lag, range, OverLag};
use crate::identify::{self, Data, Fit, SearchRange, Structure};
use crate::models::{Kano, Model, Stenman};
use band::{exact_band, valve_start, Record};
use fits::Fits;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use setup::{reaches_the_lag, Setup};

/// What the comparison needs besides OP and PV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompareRequest {
    /// Sampling time, seconds.
    pub ts: f64,
    /// Largest delay tried, in samples.
    pub max_delay: usize,
    /// `Some(true)`: integrating process only; `Some(false)`: self-regulating only; `None`: both.
    pub integrating: Option<bool>,
    /// The lag of the changes compared, samples, when the caller sets it (within the bounds the
    /// record allows); `None`: from the process's response time, off the PV's cycle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lag: Option<usize>,
}

impl Default for CompareRequest {
    fn default() -> Self {
        Self {
            ts: 1.0,
            max_delay: 30,
            integrating: None,
            lag: None,
        }
    }
}

/// One model's fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelFit {
    /// Stiction parameters in OP units: none for the linear loop, `[d]` for Stenman, `[S, J]` for
    /// Kano.
    pub params: Vec<f64>,
    /// Simulation (output-error) sum of squares of the compared output.
    pub sse: f64,
    /// R² in simulation of the compared output.
    pub r2: f64,
}

/// The fits with and without stiction on one record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitComparison {
    /// The linear structure the stiction fits use, as a model of the PV (see
    /// [`FitComparison::stiction_model`]).
    pub structure: Structure,
    /// What the fits see of the valve over the lag: its change, or for an integrating process
    /// its sum (the level's inflow).
    #[serde(default)]
    pub over_lag: OverLag,
    /// The lag (samples) of the changes compared: `pv[t + lag] - pv[t]`.
    pub lag: usize,
    /// Samples the sums run over.
    pub samples_used: usize,
    /// Sum of squares of the centred compared output.
    pub sst: f64,
    /// The variance of the measurement noise in the compared output, per sample.
    pub noise_var: f64,
    /// The valve position at the first sample the stiction fits start from.
    pub valve_start: f64,
    /// The valve follows OP.
    pub linear: ModelFit,
    /// Stenman's valve: one band d.
    pub stenman: ModelFit,
    /// Kano (S, J): a band and a slip jump of their own.
    pub slip_jump: ModelFit,
    /// Gain (PV units per OP unit; per second for an integrating process), time constant and
    /// dead time (seconds) of the linear part fitted with the best stiction model.
    pub gain: Option<f64>,
    /// Time constant of the linear part, seconds (`None` without a real pole between 0 and 1).
    pub time_constant: Option<f64>,
    /// Dead time of the linear part, seconds.
    pub dead_time: f64,
    /// Candidates fitted.
    pub evaluations: u64,
    /// The PV a valve that follows OP would give, through the linear loop's model, on the PV's
    /// level (without the loads OP does not explain: compare its changes, not its level).
    #[serde(skip)]
    pub pv_linear: Vec<f64>,
    /// The PV the best stiction model gives, on the PV's level (as `pv_linear`).
    #[serde(skip)]
    pub pv_stiction: Vec<f64>,
    /// The valve position of the best stiction model.
    #[serde(skip)]
    pub mv_stiction: Vec<f64>,
    /// The linear loop's fitted model (a valve that follows OP) and the best stiction model's
    /// linear part, as models of the PV: ARX coefficients of the compared (differenced) output,
    /// the same dynamics as the PV's, or for the valve summed over the lag the integrating
    /// structure they imply.
    #[serde(skip)]
    pub linear_model: Option<Fit>,
    /// The best stiction model's linear part, as `linear_model`.
    #[serde(skip)]
    pub stiction_model: Option<Fit>,
    /// The mean OP subtracted from the valve position before fitting levels.
    pub op_offset: f64,
    /// The samples one independent change spans in the test of the two fits: the long-run
    /// overlap of the stiction fit's residual with the change the band makes to the fit
    /// (autocorrelations multiplied, Bartlett-weighted over four lags); about the lag for noise,
    /// many more where residual and band share a cycle OP does not drive.
    pub correlation_span: f64,
}

/// Bands (shares of the OP range) at which the linear structure is chosen again.
const PILOT_BANDS: [f64; 2] = [0.02, 0.1];
/// Thornhill's regularity of the PV (trend removed) from which it limit-cycles: its lag is then
/// read off the cycle and may fall short of the process's delay (see `Setup::new`).
const CYCLE_REGULARITY: f64 = 5.0;
/// Structures refined towards the output-error optimum per compared fit.
const REFINED_STRUCTURES: usize = 3;
/// Steiglitz-McBride iterations towards each compared fit's output-error optimum.
const OE_ITERATIONS: usize = 4;
/// The lag is this many times the process's response time (time constant and dead time) ...
const LAG_RESPONSES: f64 = 1.5;
/// ... at least `MIN_LAG` samples and at most this share of the record.
const MIN_LAG: usize = 2;
const MAX_LAG_SHARE: usize = 10;

/// The longest lag of the changes compared on a record of `n` samples (`MAX_LAG_SHARE`, a tenth).
pub fn max_lag(n: usize) -> usize {
    (n / MAX_LAG_SHARE).max(MIN_LAG)
}

/// An integrating process's changes are compared over at least this share of the record.
const INTEGRATING_LAG_SHARE: usize = 25;

/// Compare the closed-loop fits with and without stiction. `None` when no linear model can be
/// fitted (too few samples, OP or PV constant).
pub fn compare_fits(op: &[f64], pv: &[f64], req: &CompareRequest) -> Option<FitComparison> {
    let (lo, hi) = range(op);
    let op_range = hi - lo;
    if op.len() != pv.len() || op_range.is_nan() || op_range <= 0.0 || range(pv).1 <= range(pv).0 {
        return None;
    }
    let setup = Setup::new(op, pv, req)?;
    let data = Data::new(&setup.y, setup.t0);
    let problem = Problem {
        op,
        data: &data,
        lag: setup.lag,
        over: setup.over,
        offset: setup.offset,
        start: None,
    };
    let mut evaluations = 3;
    // the structures: the linear loop's, and those chosen at a few bands across the OP range
    let s0 = identify::select(&data, &setup.linear_mv, &setup.search)?.structure;
    let mut structures = pilot_structures(&problem, &setup.search, s0, op_range, &mut evaluations)?;
    // (a limit cycle's search reaches the lag: the structure chosen short of it is tried too)
    if let Some(short) = &setup.short_search {
        if structures.iter().any(|s| reaches_the_lag(*s, setup.lag)) {
            if let Some(sel) = identify::select(&data, &setup.linear_mv, short) {
                if !structures.contains(&sel.structure) {
                    structures.push(sel.structure);
                }
            }
            evaluations += 1;
        }
    }
    let record = Record::new(op, &setup.y, setup.t0, setup.lag, setup.over);
    let (x0, walked) = valve_start(&record, &structures, op_range);
    evaluations += walked;
    let problem = Problem {
        start: Some(x0),
        ..problem
    };
    // the Stenman band, exactly: every distinct valve trajectory, under each structure
    let (bands, walked) = exact_band(&record, &data, &structures, op_range, x0);
    evaluations += walked;
    // the linear loop and each structure's stiction fit, over the structures and their
    // neighbours, each moved to its output-error optimum: the comparison is fair only at both
    // optima
    let mut tried: Vec<Structure> = Vec::new();
    for s in structures.iter().flat_map(|&s| neighbours(s)) {
        if !tried.contains(&s) {
            tried.push(s);
        }
    }
    // (the optima are independent: found side by side, compared in order)
    let (linear_fit, band_fits) = rayon::join(
        || optimum(&data, &setup.linear_mv, &tried),
        || {
            bands
                .par_iter()
                .map(|&(d, s)| {
                    let m = Stenman::new(d).map(Model::Stenman).ok()?;
                    optimum(&data, &problem.valve(&m), &neighbours(s)).map(|f| (m, f))
                })
                .collect::<Vec<_>>()
        },
    );
    evaluations += tried.len() as u64;
    let (best_model, fit_stenman) = band_fits.into_iter().flatten().fold(
        None,
        |best: Option<(Model, Fit)>, (m, f)| match best {
            Some(b) if b.1.sse_simulation <= f.sse_simulation => Some(b),
            _ => Some((m, f)),
        },
    )?;
    let best = (best_model, fit_stenman.sse_simulation);
    let (slip, fit_slip) = slip_jump(&problem, &best, &fit_stenman, op_range, &mut evaluations);
    let (stiction_model, fit_s) = if slip.1 < best.1 {
        (slip.0, fit_slip)
    } else {
        (best.0, fit_stenman)
    };
    // a comparison of fits is fair only when neither optimisation stopped short
    let (linear_fit, polished) = cross_polish(
        &data,
        (&setup.linear_mv, &problem.valve(&stiction_model)),
        linear_fit,
        &fit_s,
    );
    let (mut best, mut slip, mut fit_s) = (best, slip, fit_s);
    if let Some(f) = polished {
        let sse = f.sse_simulation;
        fit_s = f;
        // the better stiction model's error (Kano's is never above Stenman's)
        if slip.1 < best.1 {
            slip.1 = sse;
        } else {
            best.1 = sse;
            slip.1 = slip.1.min(sse);
        }
    }
    let fits = Fits {
        linear: linear_fit,
        stenman: best,
        slip_jump: slip,
        stiction: stiction_model,
        stiction_fit: fit_s,
        x0,
        samples_used: data.used(),
        evaluations,
    };
    Some(fits.into_comparison(op, pv, &setup, req))
}

/// The linear loop's structure and those chosen again with Stenman valves of a few bands.
fn pilot_structures(
    problem: &Problem,
    search: &SearchRange,
    s0: Structure,
    op_range: f64,
    evaluations: &mut u64,
) -> Option<Vec<Structure>> {
    let mut structures = vec![s0];
    for f in PILOT_BANDS {
        let m = Model::Stenman(Stenman::new(f * op_range).ok()?);
        if let Some(sel) = identify::select(problem.data, &problem.valve(&m), search) {
            if !structures.contains(&sel.structure) {
                structures.push(sel.structure);
            }
        }
        *evaluations += 1;
    }
    Some(structures)
}

/// The fit at its output-error optimum of the few structures among `among` whose least-squares
/// fits simulate best.
fn optimum(data: &Data, mv: &[f64], among: &[Structure]) -> Option<Fit> {
    let mut fits: Vec<Fit> = among
        .iter()
        .filter_map(|&s| identify::fit(data, mv, s).filter(Fit::stable))
        .collect();
    fits.sort_by(|x, y| x.sse_simulation.total_cmp(&y.sse_simulation));
    fits.truncate(REFINED_STRUCTURES);
    let refined: Vec<Fit> = fits
        .par_iter()
        .map(|f| identify::refine_output_error(data, mv, f, OE_ITERATIONS))
        .collect();
    refined
        .into_iter()
        .min_by(|x, y| x.sse_simulation.total_cmp(&y.sse_simulation))
        .and_then(|f| identify::polish_output_error(data, mv, &f))
}

/// Each fit polished again from the other's dynamics (a search from one start can stop short):
/// the linear loop's fit (on `mv.0`, OP's changes), the better of it and its polish; and the
/// stiction fit's polish (on `mv.1`, its valve's changes) when that is better than `stiction`.
fn cross_polish(
    data: &Data,
    mv: (&[f64], &[f64]),
    linear: Option<Fit>,
    stiction: &Fit,
) -> (Option<Fit>, Option<Fit>) {
    let linear = match (linear, identify::polish_output_error(data, mv.0, stiction)) {
        (Some(a), Some(b)) => Some(if b.sse_simulation < a.sse_simulation {
            b
        } else {
            a
        }),
        (a, b) => a.or(b),
    };
    let polished = linear
        .as_ref()
        .and_then(|l| identify::polish_output_error(data, mv.1, l))
        .filter(|f| f.sse_simulation < stiction.sse_simulation);
    (linear, polished)
}

/// Kano's band S and slip jump J around the Stenman band `best` (J = S is close to Stenman's
/// valve), never worse than Stenman's valve (which is a slip-jump valve too).
fn slip_jump(
    problem: &Problem,
    best: &(Model, f64),
    fit_stenman: &Fit,
    op_range: f64,
    evaluations: &mut u64,
) -> ((Model, f64), Fit) {
    let d = best.0.values()[0];
    let structure = fit_stenman.structure;
    let mut kano: Vec<Model> = Vec::new();
    for fs in [0.5, 0.75, 1.0, 1.25, 1.5, 2.0] {
        for fj in [0.0, 0.25, 0.5, 0.75, 1.0] {
            let s = (fs * d).min(op_range);
            if let Ok(k) = Kano::new(s, fj * s) {
                kano.push(Model::Kano(k));
            }
        }
    }
    let mut slip = problem.best_of(structure, &kano);
    *evaluations += kano.len() as u64;
    let fit_slip = optimum(
        problem.data,
        &problem.valve(&slip.0),
        &neighbours(structure),
    )
    .unwrap_or_else(|| fit_stenman.clone());
    slip.1 = slip.1.min(fit_slip.sse_simulation);
    if best.1 < slip.1 {
        slip = *best;
    }
    (slip, fit_slip)
}

/// A structure, then the same delay and family with the other orders: an equation-error fit of a
/// disturbed loop can put a pole on or outside the unit circle, and its simulation runs away.
fn neighbours(s: Structure) -> Vec<Structure> {
    let mut out = vec![s];
    for (na, nb) in [(1, 1), (1, 2), (2, 1), (2, 2), (0, 2), (0, 1)] {
        let t = Structure { na, nb, ..s };
        if !out.contains(&t) {
            out.push(t);
        }
    }
    out
}

/// The candidates' shared data.
#[derive(Clone, Copy)]
struct Problem<'a> {
    op: &'a [f64],
    data: &'a Data<'a>,
    lag: usize,
    over: OverLag,
    /// Subtracted from each valve position a sum over the lag adds (the mean OP).
    offset: f64,
    start: Option<f64>,
}

impl Problem<'_> {
    /// A valve trajectory over the lag (see [`OverLag`]).
    fn valve(&self, m: &Model) -> Vec<f64> {
        let full = m.simulate_from(self.op, self.start);
        let mut mv = vec![0.0; self.op.len() - self.lag];
        over_lag(&full, self.lag, self.over, self.offset, &mut mv);
        mv
    }

    /// The candidate of least simulation error under one structure (ties: the first).
    fn best_of(&self, s: Structure, candidates: &[Model]) -> (Model, f64) {
        let prepared = identify::Prepared::new(self.data, s);
        let n = self.op.len();
        let costs: Vec<f64> = candidates
            .par_iter()
            .with_min_len(4)
            .map_init(
                || (vec![0.0; n], vec![0.0; n - self.lag]),
                |(full, mv), m| {
                    m.simulate_from_into(self.op, self.start, full);
                    over_lag(full, self.lag, self.over, self.offset, mv);
                    prepared
                        .fit(mv)
                        .filter(Fit::stable)
                        .map_or(f64::INFINITY, |f| f.sse_simulation)
                },
            )
            .collect();
        let i = (0..costs.len()).fold(0, |b, i| if costs[i] < costs[b] { i } else { b });
        (candidates[i], costs[i])
    }
}
