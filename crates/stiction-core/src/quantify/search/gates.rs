//! The gates: can this record be quantified at all, and what they leave for the search.

use super::*;

/// Can this record be quantified? `Ok(Err((op range, reason)))` when not (data that cannot be
/// judged); `Err` for a wrong request.
#[allow(clippy::type_complexity)]
pub(super) fn gates<'a>(
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
