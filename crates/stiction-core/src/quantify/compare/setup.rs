//! The compared output and the search every fit shares: the lag of the changes compared (about
//! the process's response time, off the PV's cycle), the changes themselves, and the structure
//! search, whose delays stop short of the lag.

use super::lag::{detrended, half_correlation, off_the_cycle_of};
use super::{CompareRequest, CYCLE_REGULARITY, INTEGRATING_LAG_SHARE, LAG_RESPONSES, MIN_LAG};
use crate::identify::{self, Data, SearchRange, Structure};
use crate::quantify::problem::{difference, over_lag, OverLag};

/// The compared output and the search every fit shares.
pub(super) struct Setup {
    pub(super) search: SearchRange,
    pub(super) t0: usize,
    pub(super) lag: usize,
    /// The mean OP, taken from the valve position before fitting levels.
    pub(super) offset: f64,
    pub(super) op_centred: Vec<f64>,
    /// PV's changes over the lag, and OP as the linear part sees it over the lag.
    pub(super) y: Vec<f64>,
    pub(super) linear_mv: Vec<f64>,
    /// Where the PV limit-cycles: the search stopped short of the lag, tried beside the whole one.
    pub(super) short_search: Option<SearchRange>,
    /// What the linear part sees of the valve over the lag: its change, or for an integrating
    /// process its sum (the level's inflow).
    pub(super) over: OverLag,
}

impl Setup {
    pub(super) fn new(op: &[f64], pv: &[f64], req: &CompareRequest) -> Option<Self> {
        let n = op.len();
        let mut search = SearchRange::new(req.max_delay.min(n / 20).max(1));
        if let Some(integrating) = req.integrating {
            search.integrating = integrating;
            search.self_regulating = !integrating;
        }
        let t0 = search.t0();
        let offset = op.iter().sum::<f64>() / n as f64;
        let op_centred: Vec<f64> = op.iter().map(|v| v - offset).collect();
        // the lag: the response time of a first linear fit on levels
        let levels = Data::new(pv, t0);
        let first = identify::select(&levels, &op_centred, &search)?.structure;
        let first_fit = identify::fit(&levels, &op_centred, first)?;
        let phys = identify::physical(&first_fit, req.ts);
        let response = phys.time_constant.unwrap_or(0.0) + phys.dead_time;
        // (an oscillating sticky loop's linear fit on levels is poor: its response time is read
        // off the PV's autocorrelation too, whichever is longer)
        let trendless = detrended(pv);
        let reg = crate::detect::regularity(&trendless, 1.0);
        let mut lag = ((LAG_RESPONSES * response / req.ts).round() as usize)
            .max(half_correlation(&trendless));
        if first.integrating {
            // a level's change grows with the lag while its noise does not: a long lag
            lag = lag.max(n / INTEGRATING_LAG_SHARE);
        }
        let max_lag = super::max_lag(n);
        let lag = match req.lag {
            Some(l) => l.clamp(MIN_LAG, max_lag),
            None => off_the_cycle_of(lag.clamp(MIN_LAG, max_lag), &reg, max_lag),
        };
        if n < lag + t0 + 20 * (search.na.len() + search.nb_max + 1) {
            return None;
        }
        // changes over the lag are bounded even for an integrating process (over the lag its
        // level changes by the sum of its inflow): compared with self-regulating structures,
        // whose simulation errors are those of the PV's changes, not of its noisy rate, against
        // the valve summed over the lag ([`OverLag::Sum`]), with structures without output lags
        // as well
        let over = if req.integrating == Some(true) || first.integrating {
            search.na = vec![0, 1, 2];
            OverLag::Sum
        } else {
            OverLag::Change
        };
        search.integrating = false;
        search.self_regulating = true;
        // the valve's changes should stop short of the sample where PV's change starts. OP's
        // change delayed by the lag, `op[t] - op[t - lag]`, ends at `pv[t]`; under feedback it is
        // about minus the controller's gain times PV's change before: PV's own past in disguise,
        // which the one-step selection prefers to the process (routine-c-0033 of the catalogue: a
        // delay of the lag itself was chosen, gain 0.08 for 1.16, R² 0.27 with and without
        // stiction; short of the lag, 0.44 without and 0.78 with the true band found). Where the
        // PV does not limit-cycle, the lag is at least half again the response time, the delay
        // lies well within it, and the search stops short of it. A limit cycle's lag is read off
        // the cycle's autocorrelation and can fall short of the delay (issue 14's example: a lag
        // of 20 s, a delay of 30 s); there the whole search stays and the short one is tried
        // beside it.
        let short = SearchRange {
            nk_max: search.nk_max.min(lag.saturating_sub(search.nb_max)).max(1),
            ..search.clone()
        };
        let limit_cycles = reg.oscillating && reg.regularity >= CYCLE_REGULARITY;
        let short_search = if limit_cycles {
            Some(short)
        } else {
            search = short;
            None
        };
        let mut y = vec![0.0; n - lag];
        difference(pv, lag, &mut y);
        let mut linear_mv = vec![0.0; n - lag];
        over_lag(op, lag, over, offset, &mut linear_mv);
        Some(Self {
            search,
            t0,
            lag,
            offset,
            op_centred,
            y,
            linear_mv,
            short_search,
            over,
        })
    }
}

/// Whether a structure's input terms reach back to the lag: to the valve change that ends where
/// the compared change of PV starts.
pub(super) fn reaches_the_lag(s: Structure, lag: usize) -> bool {
    s.nk + s.nb > lag
}
