//! The comparison's lag at its bound. The fits compare PV's changes over about one and a half
//! response times of the process, read off a first linear fit of the levels (or off PV's
//! autocorrelation), at most a tenth of the record ([`crate::quantify::max_lag`]). A lag at
//! that bound says the response time was not read: a load's drift or a slow, irregular cycle
//! lengthened it, and over so long a lag a valve's sticks and slips are mostly averaged away
//! (routine-c-0215 of the catalogue, a sticky He valve on a pressure loop at 1 s with a
//! response time of 35 s: at the bound of 200 samples no band fits better than OP, over 66 a
//! slip-jump valve explains 11 % more of PV's changes, test ratio 127). There the fits are also
//! compared over a third of the bound, and the comparison with the higher test ratio is kept:
//! both are the same calibrated test on the same record.
//!
//! A third, set on the catalogue's calibration set (routine windows): it finds more sticky valves
//! than a half, and adds no false alarm where a quarter does.

use super::Levels;
use crate::quantify::{compare_fits, max_lag, off_the_pv_cycle, CompareRequest, FitComparison};

/// Where the lag reaches its bound, the changes are also compared over the bound divided by this.
pub(crate) const BOUND_LAG_DIVISOR: usize = 3;

/// The fits compared as [`compare_fits`] compares them, and again over a third of the lag where
/// it reached its bound (a lag the caller set is kept): the comparison with the higher test
/// ratio, and the bound when the shorter lag's was kept.
pub(crate) fn compared(
    op: &[f64],
    pv: &[f64],
    req: &CompareRequest,
) -> (Option<FitComparison>, Option<usize>) {
    let first = compare_fits(op, pv, req);
    let Some(f) = first
        .as_ref()
        .filter(|f| req.lag.is_none() && f.lag >= max_lag(op.len()))
    else {
        return (first, None);
    };
    // (kept off the PV's regular cycle as the first lag is: over whole periods the cycle
    // cancels, and that comparison has its own, higher threshold)
    let shorter = CompareRequest {
        lag: Some(off_the_pv_cycle(f.lag / BOUND_LAG_DIVISOR, pv)),
        ..req.clone()
    };
    match compare_fits(op, pv, &shorter) {
        Some(s) if Levels::of(&s).significance > Levels::of(f).significance => {
            let bound = f.lag;
            (Some(s), Some(bound))
        }
        _ => (first, None),
    }
}
