//! The exact Stenman band of the comparison, and where the valve stood at the first sample.

use crate::identify::{Data, Structure};
use crate::models::ModelKind;
use crate::quantify::exact::{exact_stenman, merged_top_cells, stage_sees_the_travel};
use crate::quantify::problem::{min_costs_1d, Hammerstein, OverLag};

/// A staged walk starts on this many samples, or this many oscillation periods of the PV if
/// more, up to half the record, when the record has at least `STAGE_FROM` samples.
const STAGE_SAMPLES: usize = 600;
const STAGE_PERIODS: f64 = 8.0;
const STAGE_FROM: usize = 1500;
/// Candidate valve positions at the first sample, as shares of the span OP covers on the first
/// samples, either side of the first OP.
const START_SHARES: [f64; 5] = [0.0, -0.12, 0.12, -0.3, 0.3];
/// The valve start is judged on this many samples, or this many oscillation periods if more (at
/// most the first samples of a staged walk): the start matters until the valve has slipped a few
/// times.
const START_SAMPLES: usize = 300;
const START_PERIODS: f64 = 3.0;
/// Another start replaces the first OP only when its error on the first samples is below this
/// share of the first OP's.
const START_GAIN: f64 = 0.7;
/// Points of the band scan that judges each start.
const START_GRID: usize = 32;

/// The record the band is walked on: OP, the PV's changes over the lag (`y`, from sample `t0`
/// on), what the linear part sees of the valve over the lag, and the period of the changes'
/// cycle (0 without one), measured once for every stage.
pub(super) struct Record<'a> {
    pub op: &'a [f64],
    pub y: &'a [f64],
    pub t0: usize,
    pub lag: usize,
    pub over: OverLag,
    pub period: f64,
}

impl<'a> Record<'a> {
    pub fn new(op: &'a [f64], y: &'a [f64], t0: usize, lag: usize, over: OverLag) -> Self {
        let period = crate::detect::regularity(y, 1.0).period.unwrap_or(0.0);
        Self {
            op,
            y,
            t0,
            lag,
            over,
            period,
        }
    }

    /// The first samples a staged walk (and the choice of the valve start) judges.
    fn first_samples(&self) -> usize {
        let n = self.y.len() + self.lag;
        if n >= STAGE_FROM {
            STAGE_SAMPLES
                .max((STAGE_PERIODS * self.period) as usize)
                .min(n / 2)
        } else {
            n / 2
        }
    }
}

fn problems<'a>(
    op: &'a [f64],
    data: &'a Data<'a>,
    structures: &[Structure],
    (lag, over): (usize, OverLag),
    x0: f64,
) -> Vec<Hammerstein<'a>> {
    structures
        .iter()
        .map(|&s| Hammerstein::new(ModelKind::Stenman, op, data, s, Some(x0)).with_lag(lag, over))
        .collect()
}

/// Where the valve stood at the first sample: of candidates around the first OP, the one whose
/// scan of the band on the first samples fits best (under any of the structures). Returns it and the
/// cells walked.
pub(super) fn valve_start(r: &Record, structures: &[Structure], op_range: f64) -> (f64, u64) {
    let Record { op, y, t0, lag, .. } = *r;
    let m = r
        .first_samples()
        .min(START_SAMPLES.max((START_PERIODS * r.period) as usize) + lag)
        .max(lag + 4 * t0);
    let (op_m, y_m) = (&op[..m], &y[..m - lag]);
    let data = Data::new(y_m, t0);
    let (lo, hi) = op_m
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = hi - lo;
    let mut walked = 0;
    let mut best = (op[0], f64::INFINITY);
    let mut at_first_op = f64::INFINITY;
    // a geometric scan of the band (the exact walk is for the chosen start)
    let grid: Vec<f64> = (0..START_GRID)
        .map(|i| {
            let first = 1e-3 * op_range;
            first * (0.5 * op_range / first).powf(i as f64 / (START_GRID - 1) as f64)
        })
        .collect();
    for f in START_SHARES {
        let x0 = op[0] + f * span;
        let ps = problems(op_m, &data, structures, (lag, r.over), x0);
        let cost = min_costs_1d(&ps, &grid)
            .into_iter()
            .fold(f64::INFINITY, f64::min);
        walked += (grid.len() * ps.len()) as u64;
        if f == 0.0 {
            at_first_op = cost;
        }
        if cost < best.1 {
            best = (x0, cost);
        }
    }
    // the first OP unless another start fits clearly better (a record that starts at rest has its
    // valve there; a few samples cannot tell small differences from noise)
    if best.1 < START_GAIN * at_first_op {
        (best.0, walked)
    } else {
        (op[0], walked)
    }
}

/// The exact Stenman walk under each structure from valve start `x0` (staged on long records:
/// the whole range on the first samples, then their best cells on the whole record): each
/// structure's best band (least-squares fits ranked by simulation error; the caller compares
/// structures after moving each fit to its output-error optimum), and the cells walked.
pub(super) fn exact_band(
    r: &Record,
    data: &Data,
    structures: &[Structure],
    op_range: f64,
    x0: f64,
) -> (Vec<(f64, Structure)>, u64) {
    let Record { op, y, lag, .. } = *r;
    let n = op.len();
    let whole = problems(op, data, structures, (lag, r.over), x0);
    let mut walked = 0;
    let outcomes = if n >= STAGE_FROM
        && r.first_samples() > lag
        && stage_sees_the_travel(op, r.first_samples())
    {
        let m = r.first_samples();
        let first = Data::new(&y[..m - lag], data.t0);
        let staged = problems(&op[..m], &first, structures, (lag, r.over), x0);
        let stage = exact_stenman(&staged, (0.0, op_range), true, None);
        walked += stage.iter().map(|o| o.evaluations).max().unwrap_or(0);
        let merged = merged_top_cells(stage.iter());
        exact_stenman(&whole, (0.0, op_range), true, Some(&merged))
    } else {
        exact_stenman(&whole, (0.0, op_range), true, None)
    };
    walked += outcomes.iter().map(|o| o.evaluations).max().unwrap_or(0);
    let best = whole
        .iter()
        .zip(&outcomes)
        .map(|(h, o)| (o.best[0], h.prepared.structure()))
        .collect();
    (best, walked)
}
