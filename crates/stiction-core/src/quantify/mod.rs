//! Quantifying stiction from OP and PV alone: closed-loop Hammerstein identification.
//!
//! ```text
//! mv = stiction_θ(op)                         (the valve position is not measured)
//! A(q) y[t] = B(q) mv[t - nk] + c             (y = pv, or its change for integrating processes)
//! ```
//!
//! Separable: for fixed stiction parameters θ the valve position is simulated from OP and the
//! linear part fitted by least squares; the outer search over θ ranks candidates by how well the
//! fitted model *simulates* the PV (output error), which one-step prediction alone does not
//! discriminate. For Stenman the outer search is exact: the d-range is partitioned into cells with
//! identical valve trajectories and every cell is fitted once. Orders and delay are chosen by BIC.
//!
//! The answer is an *apparent* stiction: inferred without the valve position, from data that an
//! oscillating loop may not make fully identifiable.
//!
//! The stages, one file each: `search` runs them for one record (gates, pilot structures, the
//! search per structure, the result); `exact` is the exact Stenman partition, `heuristic` the
//! grid, ACO and polishing for the other models; `start` estimates where the valve stood at the
//! first sample; this file stages long records (first samples, then the whole record).

mod compare;
pub(crate) mod exact;
mod heuristic;
mod pilots;
pub(crate) mod problem;
mod request;
mod result;
mod search;
mod start;

use crate::checked::Checked;
pub use compare::{
    compare_fits, correlation_span, max_lag, off_the_pv_cycle, CompareRequest, FitComparison,
    ModelFit,
};
pub use problem::OverLag;
pub use request::QuantifyRequest;
pub use result::{
    FitOutput, FitQuality, LinearFamily, LinearModel, Quantification, QuantifyStatus,
    ValveStartKind,
};

use crate::estimate::{EstimateError, Method};
use crate::models::ModelKind;
use search::quantify_inner;
use std::time::Instant;

/// A staged search starts on this many samples ...
const STAGE_SAMPLES: usize = 600;
/// ... or this many oscillation periods of the PV, if more, up to half the record ...
const STAGE_PERIODS: f64 = 8.0;
/// ... when the record has at least this many samples.
const STAGE_FROM: usize = 1500;

/// Check the request and quantify stiction from OP and PV: [`QuantifyRequest::check`], then
/// [`quantify_checked`]. Data that cannot be judged gives `status: insufficient_data` with the
/// reason; requests that are wrong (bounds, settings) give an error.
///
/// A closed loop with a sticky valve, its band estimated from OP and PV alone:
///
/// ```
/// use stiction_core::estimate::Method;
/// use stiction_core::models::{Model, ModelKind, Stenman};
/// use stiction_core::quantify::{quantify, QuantifyRequest, QuantifyStatus};
/// use stiction_core::sim::ClosedLoop;
///
/// let mut sim = ClosedLoop::new(Model::Stenman(Stenman::new(2.0)?));
/// sim.samples = 1200;
/// let data = sim.run()?;
/// let q = quantify(&data.op, &data.pv, &QuantifyRequest::new(ModelKind::Stenman, Method::Exact))?;
/// assert_eq!(q.status, QuantifyStatus::Ok);
/// assert!((q.params["d"] - 2.0).abs() < 0.2);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn quantify(
    op: &[f64],
    pv: &[f64],
    req: &QuantifyRequest,
) -> Result<Quantification, EstimateError> {
    quantify_checked(op, pv, &req.check()?)
}

/// Quantify stiction from OP and PV with a checked request (long Stenman records are staged:
/// the whole d-range on the first samples, then its best cells on the whole record).
pub fn quantify_checked(
    op: &[f64],
    pv: &[f64],
    req: &Checked<QuantifyRequest>,
) -> Result<Quantification, EstimateError> {
    let started = Instant::now();
    let n = op.len();
    if !(req.model == ModelKind::Stenman && req.method == Method::Exact && pv.len() == n) {
        return quantify_inner(op, pv, req, None).map(|r| r.0);
    }
    let estimate_start = req.estimate_start && req.valve_start.is_none();
    // the first samples: at least a few oscillation periods (too short a start ranks the
    // cells by the transient)
    let m = if n >= STAGE_FROM && (req.staged || estimate_start) {
        let period = crate::detect::regularity(pv, 1.0).period.unwrap_or(0.0);
        STAGE_SAMPLES
            .max((STAGE_PERIODS * period) as usize)
            .min(n / 2)
    } else {
        n
    };
    // (a record that starts at rest gives its first samples no band to tell apart: walked whole)
    let staged = req.staged && n >= STAGE_FROM && exact::stage_sees_the_travel(op, m);
    let mut req = req.clone();
    let mut extra = 0;
    let mut at_first_op = None;
    if estimate_start {
        // where the valve stood at the first sample: the candidate whose search of the first
        // samples fits best (the first OP is one of them); it must then also fit the whole
        // record better than the first OP does
        let (best, evaluations) = start::best_start(&op[..m], &pv[..m], &req);
        extra += evaluations;
        if best.is_some_and(|x0| x0 != op[0]) {
            let plain = req.adjust(|r| r.estimate_start = false);
            at_first_op = Some(quantify_checked(op, pv, &plain)?);
        }
        // a candidate position is a finite OP value: the request stays valid
        req = req.adjust(|r| r.valve_start = best);
    }
    let finish = |mut q: Quantification, extra: u64| {
        q.evaluations += extra;
        q.seconds = started.elapsed().as_secs_f64();
        if estimate_start && q.valve_start.is_some() {
            q.valve_start_kind = Some(ValveStartKind::Estimated);
        }
        q
    };
    let mut answer = None;
    if staged {
        // stage 1: the whole d-range on the first samples (same valve start, so every
        // whole-record cell lies inside one of its cells)
        let first = req.adjust(|r| {
            r.staged = false;
            r.full_partition = true;
        });
        if let Ok((q, hint)) = quantify_inner(&op[..m], &pv[..m], &first, None) {
            if q.status == QuantifyStatus::Ok && !hint.ranges.is_empty() {
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
