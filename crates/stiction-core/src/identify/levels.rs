//! The levels test: does a valve trajectory explain PV's *levels* better than OP does?
//!
//! PV is regressed by least squares on a bank of first-order filters of the valve position (each
//! delayed a sample) and two pure delays, for a level loop also the valve's running sum, beside a
//! piecewise-linear drift (a knot every [`KNOT_EVERY`] samples). The regressors hold only valve
//! positions from before each PV sample and the drift is smooth, so PV's measurement noise, which
//! the controller feeds back into OP at once, cannot favour OP, and the fit has no PV past among
//! its regressors (an ARX fit's bias towards the valve that follows OP).
//!
//! The residual is not white (load drift between the knots, an external cycle), so the fit is a
//! generalised least squares: an AR noise model of order [`AR_ORDER`], estimated on the residual
//! with OP, whitens PV and every column. The log-likelihood ratio
//! `n/2 ln(SSE with OP / SSE with the valve)` then counts a coloured residual as fewer independent
//! samples, and an external cycle or a slow drift no longer passes for the valve.
//!
//! [`levels_walk`] scores every distinct Stenman valve trajectory from OP (the exact partition of
//! the band's range) and keeps the best; then He's valve (a slip that lands short of OP, as
//! Kano's slip jump below the band) at a few bands and landings around it. On the calibration
//! set the He valves found 15 more of the 240 sticky routine loops and 12 more of the 90 fast
//! ones, and one more of 159 healthy routine loops and one of 136 fast ones reached 50. It costs a fit per trajectory (a few thousand on 2,000
//! samples; the walk runs in fixed chunks in parallel, and its result is the walk in order's, on
//! any number of threads), so `diagnose` runs it only when asked (`thorough`).

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

use crate::estimate::exact::stenman_walk;
use crate::models::{He, Model};

/// Time constants of the filter bank, samples.
pub const TAUS: [f64; 6] = [0.5, 2.0, 6.0, 18.0, 54.0, 160.0];
/// Pure delays of the bank, samples.
pub const DELAYS: [usize; 2] = [3, 8];
/// Samples between the drift's knots.
pub const KNOT_EVERY: usize = 150;
/// A filter bank: first-order filters (time constants, samples) and pure delays (samples).
#[derive(Debug, Clone, Copy)]
pub struct Bank<'a> {
    /// Time constants of the first-order filters, samples.
    pub taus: &'a [f64],
    /// Pure delays, samples.
    pub delays: &'a [usize],
}

/// The bank the levels test uses.
pub const BANK: Bank<'static> = Bank {
    taus: &TAUS,
    delays: &DELAYS,
};
/// Order of the AR noise model.
pub const AR_ORDER: usize = 4;
/// The smallest residual a fit reports, share of PV's sum of squares (the arithmetic's
/// resolution: below it two fits are alike).
const SSE_FLOOR: f64 = 1e-9;
/// Fewest samples the test runs on.
pub const MIN_SAMPLES: usize = 200;

/// One record's PV, whitened, with its drift projected out.
pub struct LevelsFit {
    integrating: bool,
    taus: Vec<f64>,
    delays: Vec<usize>,
    /// The whitening filter `A(q)`: coefficients of lags 1.. (empty: white noise).
    ar: Vec<f64>,
    /// Orthonormal basis of the (whitened) drift: a constant and hinges at the knots.
    drift: Vec<Vec<f64>>,
    /// PV, whitened, with the drift projected out, and its sum of squares.
    y: Vec<f64>,
    yy: f64,
}

/// Buffers reused from one valve trajectory to the next.
pub struct Scratch {
    cols: Vec<Vec<f64>>,
    u: Vec<f64>,
}

impl LevelsFit {
    /// The fit on `pv`, its noise model estimated on the residual with `op` as the valve.
    pub fn new(pv: &[f64], op: &[f64], integrating: bool) -> Self {
        let plain = Self::plain(pv, integrating, BANK);
        let mut scratch = plain.scratch();
        let r = plain.residual(op, &mut scratch);
        let ar = ar_fit(&r, AR_ORDER);
        Self::with_noise(pv, integrating, BANK, ar)
    }

    /// The fit with white noise (no AR model) on a bank of one's own: the plain output-error
    /// test of the model-family studies (`model_ceiling`, `clean_walk`, `sampled_valve`).
    pub fn plain(pv: &[f64], integrating: bool, bank: Bank) -> Self {
        Self::with_noise(pv, integrating, bank, Vec::new())
    }

    fn with_noise(pv: &[f64], integrating: bool, bank: Bank, ar: Vec<f64>) -> Self {
        let n = pv.len();
        let knots = (n / KNOT_EVERY).max(2);
        let mut cols = vec![vec![1.0; n]];
        for k in 0..knots {
            let at = k * n / knots;
            cols.push(
                (0..n)
                    .map(|t| t.saturating_sub(at) as f64 / n as f64)
                    .collect(),
            );
        }
        for c in cols.iter_mut() {
            whiten(&ar, c);
        }
        let drift = orthonormal(cols);
        let mut y = pv.to_vec();
        whiten(&ar, &mut y);
        project_out(&drift, &mut y);
        let yy = dot(&y, &y);
        Self {
            integrating,
            taus: bank.taus.to_vec(),
            delays: bank.delays.to_vec(),
            ar,
            drift,
            y,
            yy,
        }
    }

    /// Buffers for [`Self::sse`].
    pub fn scratch(&self) -> Scratch {
        let n = self.y.len();
        let p = self.taus.len() + self.delays.len() + usize::from(self.integrating);
        Scratch {
            cols: vec![vec![0.0; n]; p],
            u: vec![0.0; n],
        }
    }

    /// Residual sum of squares of PV explained by `valve` (beside the drift).
    pub fn sse(&self, valve: &[f64], s: &mut Scratch) -> f64 {
        self.columns(valve, s);
        for c in s.cols.iter_mut() {
            project_out(&self.drift, c);
        }
        let (a, b) = gram(&s.cols, &self.y);
        // a fit cannot explain PV past the arithmetic's resolution (a level loop's running
        // sum is large beside what is left of PV)
        (self.yy - explained(a, &b)).max(SSE_FLOOR * self.yy)
    }

    /// The log-likelihood ratio `n/2 ln(sse_op / sse)`.
    pub fn ratio(&self, sse_op: f64, sse: f64) -> f64 {
        self.y.len() as f64 / 2.0 * (sse_op / sse.max(f64::MIN_POSITIVE)).ln()
    }

    /// PV's residual after the least-squares fit on `valve`'s columns.
    fn residual(&self, valve: &[f64], s: &mut Scratch) -> Vec<f64> {
        self.columns(valve, s);
        for c in s.cols.iter_mut() {
            project_out(&self.drift, c);
        }
        let (a, b) = gram(&s.cols, &self.y);
        let beta = solve(a, &b);
        let mut r = self.y.clone();
        for (c, w) in s.cols.iter().zip(&beta) {
            for (x, v) in r.iter_mut().zip(c) {
                *x -= w * v;
            }
        }
        r
    }

    /// The bank's columns of `valve` (centred), whitened, into `s.cols`.
    fn columns(&self, valve: &[f64], s: &mut Scratch) {
        let n = valve.len();
        let mean = valve.iter().sum::<f64>() / n as f64;
        for (u, v) in s.u.iter_mut().zip(valve) {
            *u = v - mean;
        }
        let u = &s.u;
        let mut k = 0;
        for &tau in &self.taus {
            let a = (-1.0f64 / tau).exp();
            let c = &mut s.cols[k];
            let mut state = u[0];
            c[0] = 0.0;
            for t in 1..n {
                c[t] = state;
                state = a * state + (1.0 - a) * u[t];
            }
            k += 1;
        }
        for &d in &self.delays {
            let c = &mut s.cols[k];
            for t in 0..n {
                c[t] = if t >= d { u[t - d] } else { 0.0 };
            }
            k += 1;
        }
        if self.integrating {
            let c = &mut s.cols[k];
            let mut sum = 0.0;
            for t in 0..n {
                c[t] = sum;
                sum += u[t];
            }
        }
        for c in s.cols.iter_mut() {
            whiten(&self.ar, c);
        }
    }
}

/// The best Stenman valve of the levels test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LevelsWalk {
    /// The log-likelihood ratio of the best trajectory against OP.
    pub ratio: f64,
    /// The best valve's band, OP units (the middle of its Stenman cell, or He's fs).
    pub band: f64,
    /// How far short of OP the best valve's slips land (He's fd), OP units; 0 for Stenman's.
    pub slip_short: f64,
    /// Distinct trajectories scored.
    pub trajectories: usize,
}

/// Score every distinct Stenman valve trajectory from `op` (the valve at the first OP, bands from
/// 10⁻⁴ of OP's range to its range) by the levels test on `pv`; `None` for a record too short or
/// an OP that does not move.
pub fn levels_walk(op: &[f64], pv: &[f64], integrating: bool) -> Option<LevelsWalk> {
    let n = op.len();
    if n < MIN_SAMPLES || pv.len() != n || op.iter().chain(pv).any(|v| !v.is_finite()) {
        return None;
    }
    let (lo, hi) = op
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let range = hi - lo;
    if range <= 0.0 {
        return None;
    }
    let fit = LevelsFit::new(pv, op, integrating);
    let mut scratch = fit.scratch();
    let with_op = fit.sse(op, &mut scratch);
    let (best_walk, trajectories) = walk_chunks(&fit, op, range);
    let (mut best, mut band) = match best_walk {
        Some((s, cell)) if s < with_op => (s, 0.5 * (cell.0 + cell.1)),
        _ => (with_op, 0.0),
    };
    let mut valve = vec![0.0; n];
    // a slip that lands short of OP (He's dynamic friction fd, Kano's slip jump below the band)
    // near the best band: a few fits beside the walk's thousands
    let mut slip_short = 0.0;
    if band > 0.0 {
        let found = band;
        let tries = [0.8, 0.9, 1.0, 1.1, 1.25]
            .into_iter()
            .flat_map(|m| [0.25, 0.5, 0.75].map(|k| (m * found, k * m * found)));
        for (fs, fd) in tries {
            if let Ok(m) = He::new(fs, fd) {
                Model::He(m).simulate_from_into(op, Some(op[0]), &mut valve);
                let s = fit.sse(&valve, &mut scratch);
                if s < best {
                    (best, band, slip_short) = (s, fs, fd);
                }
            }
        }
    }
    let ratio = fit.ratio(with_op, best);
    if !ratio.is_finite() {
        return None;
    }
    Some(LevelsWalk {
        ratio,
        band,
        slip_short,
        trajectories,
    })
}

/// Chunks the band's range is cut into (geometric), walked in parallel; the result is the
/// sequential walk's, whatever the number of threads.
const WALK_CHUNKS: usize = 32;

/// What one chunk's walk found: its best piece of a cell and that piece's error, its first and
/// last pieces' errors (a cell that crosses the chunk's edge is walked in two pieces, one in each
/// chunk, with the same trajectory and so the same error), and the pieces walked.
struct ChunkWalk {
    best: Option<Piece>,
    first: Option<Piece>,
    last: Option<Piece>,
    pieces: usize,
}

/// A walked piece of a cell: the error of its trajectory and the piece's bands.
type Piece = (f64, (f64, f64));

/// Every distinct Stenman trajectory of bands in `[range 10⁻⁴, range)`, walked in fixed chunks
/// in parallel: the best trajectory's error and whole cell (the first in order of the band
/// among equals, as a walk in order keeps), and the number of distinct trajectories.
fn walk_chunks(fit: &LevelsFit, op: &[f64], range: f64) -> (Option<Piece>, usize) {
    use rayon::prelude::*;
    let (first, hi) = (range * 1e-4, range);
    let mut edges: Vec<f64> = (0..=WALK_CHUNKS)
        .map(|i| first * (hi / first).powf(i as f64 / WALK_CHUNKS as f64))
        .collect();
    edges[0] = first;
    edges[WALK_CHUNKS] = hi;
    let whole = (0.0, range * (1.0 + 1e-9));
    let walks: Vec<ChunkWalk> = edges
        .par_windows(2)
        .map_init(
            || (fit.scratch(), vec![0.0; op.len()]),
            |(scratch, valve), w| {
                let mut c = ChunkWalk {
                    best: None,
                    first: None,
                    last: None,
                    pieces: 0,
                };
                stenman_walk(op, op[0], (w[0], w[1]), whole, valve, |cell, mv| {
                    let s = fit.sse(mv, scratch);
                    c.pieces += 1;
                    if c.best.is_none_or(|b| s < b.0) {
                        c.best = Some((s, cell));
                    }
                    if c.first.is_none() {
                        c.first = Some((s, cell));
                    }
                    c.last = Some((s, cell));
                });
                c
            },
        )
        .collect();
    // a piece whose error equals the next chunk's first piece's is one cell split at the edge
    let split = |i: usize| match (walks[i].last, walks.get(i + 1).and_then(|w| w.first)) {
        (Some(a), Some(b)) => a.0 == b.0 && a.1 .1 == b.1 .0,
        _ => false,
    };
    let trajectories = walks.iter().map(|w| w.pieces).sum::<usize>()
        - (0..walks.len()).filter(|&i| split(i)).count();
    let mut best: Option<(f64, (f64, f64), usize)> = None;
    for (i, w) in walks.iter().enumerate() {
        if let Some((s, cell)) = w.best {
            if best.is_none_or(|b| s < b.0) {
                best = Some((s, cell, i));
            }
        }
    }
    let best = best.map(|(s, cell, mut i)| {
        // the best piece ends at its chunk's edge: the cell goes on into the next chunks
        let mut piece = cell;
        while walks[i].last.is_some_and(|l| l.1 == piece) && split(i) {
            piece = walks[i + 1].first.map_or(piece, |f| f.1);
            i += 1;
        }
        (s, (cell.0, piece.1))
    });
    (best, trajectories)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The Gram matrix of `cols` and their products with `y`.
fn gram(cols: &[Vec<f64>], y: &[f64]) -> (Vec<Vec<f64>>, Vec<f64>) {
    let p = cols.len();
    let mut a = vec![vec![0.0; p]; p];
    let mut b = vec![0.0; p];
    for i in 0..p {
        b[i] = dot(&cols[i], y);
        for j in i..p {
            a[i][j] = dot(&cols[i], &cols[j]);
            a[j][i] = a[i][j];
        }
    }
    (a, b)
}

/// `A⁻¹ b` by Gaussian elimination with partial pivoting and a small ridge.
fn solve(mut a: Vec<Vec<f64>>, b: &[f64]) -> Vec<f64> {
    let p = b.len();
    let mut x = b.to_vec();
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-9 * row[i].abs() + 1e-300;
    }
    for k in 0..p {
        let piv = (k..p)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap_or(k);
        a.swap(k, piv);
        x.swap(k, piv);
        for i in k + 1..p {
            let f = a[i][k] / a[k][k];
            for j in k..p {
                a[i][j] -= f * a[k][j];
            }
            x[i] -= f * x[k];
        }
    }
    for k in (0..p).rev() {
        let s: f64 = (k + 1..p).map(|j| a[k][j] * x[j]).sum();
        x[k] = (x[k] - s) / a[k][k];
    }
    x
}

/// `bᵀ A⁻¹ b` (the sum of squares the columns explain), by Cholesky with a small ridge.
fn explained(mut a: Vec<Vec<f64>>, b: &[f64]) -> f64 {
    let p = b.len();
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += 1e-9 * row[i].abs() + 1e-300;
    }
    let mut l = vec![vec![0.0; p]; p];
    for i in 0..p {
        for j in 0..=i {
            let s: f64 = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = if i == j {
                s.max(1e-300).sqrt()
            } else {
                s / l[j][j]
            };
        }
    }
    let mut z = vec![0.0; p];
    for i in 0..p {
        z[i] = (b[i] - (0..i).map(|k| l[i][k] * z[k]).sum::<f64>()) / l[i][i];
    }
    z.iter().map(|v| v * v).sum()
}

/// AR coefficients `a_1..a_p` of `r` (least squares): `r_t + a_1 r_{t-1} + ... = e_t`.
fn ar_fit(r: &[f64], order: usize) -> Vec<f64> {
    if order == 0 || r.len() <= 2 * order {
        return Vec::new();
    }
    let cols: Vec<Vec<f64>> = (1..=order)
        .map(|k| r[order - k..r.len() - k].to_vec())
        .collect();
    let (a, b) = gram(&cols, &r[order..]);
    let c = solve(a, &b);
    if c.iter().all(|v| v.is_finite()) {
        c.into_iter().map(|v| -v).collect()
    } else {
        Vec::new()
    }
}

/// `c ← A(q) c` in place (the first samples use the lags they have).
fn whiten(ar: &[f64], c: &mut [f64]) {
    if ar.is_empty() {
        return;
    }
    for t in (0..c.len()).rev() {
        let mut s = c[t];
        for (k, a) in ar.iter().enumerate() {
            if t > k {
                s += a * c[t - k - 1];
            }
        }
        c[t] = s;
    }
}

/// Gram-Schmidt, twice per column; columns that add nothing are dropped.
fn orthonormal(cols: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let mut out: Vec<Vec<f64>> = Vec::new();
    for mut c in cols {
        for _ in 0..2 {
            project_out(&out, &mut c);
        }
        let norm = dot(&c, &c).sqrt();
        if norm > 1e-9 {
            out.push(c.iter().map(|x| x / norm).collect());
        }
    }
    out
}

/// `c -= Q Qᵀ c` for an orthonormal `q`.
fn project_out(q: &[Vec<f64>], c: &mut [f64]) {
    for qq in q {
        let p = dot(qq, c);
        for (x, a) in c.iter_mut().zip(qq) {
            *x -= p * a;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::{Model, Stenman};
    use crate::rng::{gaussian, seeded};

    /// A first-order process driven by `valve`, plus white noise.
    fn process(valve: &[f64], noise: f64, seed: u64) -> Vec<f64> {
        let mut rng = seeded(seed);
        let mut x = valve[0];
        valve
            .iter()
            .map(|&v| {
                let y = x + noise * gaussian(&mut rng);
                x += 0.1 * (v - x);
                y
            })
            .collect()
    }

    fn ramp_op(n: usize) -> Vec<f64> {
        (0..n)
            .map(|t| 50.0 + 8.0 * (t as f64 * 0.013).sin() + 0.3 * (t as f64 * 0.71).sin())
            .collect()
    }

    /// The walk in order of the band, in one piece: the reference the chunked walk must equal.
    fn walk_in_order(fit: &LevelsFit, op: &[f64], range: f64) -> (Option<Piece>, usize) {
        let mut scratch = fit.scratch();
        let mut valve = vec![0.0; op.len()];
        let (mut best, mut count) = (None::<Piece>, 0);
        let whole = (0.0, range * (1.0 + 1e-9));
        stenman_walk(
            op,
            op[0],
            (range * 1e-4, range),
            whole,
            &mut valve,
            |cell, mv| {
                count += 1;
                let s = fit.sse(mv, &mut scratch);
                if best.is_none_or(|b| s < b.0) {
                    best = Some((s, cell));
                }
            },
        );
        (best, count)
    }

    #[test]
    fn the_chunked_walk_equals_the_walk_in_order() {
        let op = ramp_op(600);
        let range = 16.6;
        for (d, seed) in [(0.0, 1), (0.4, 2), (2.0, 3), (6.0, 4)] {
            let valve = if d > 0.0 {
                Model::Stenman(Stenman::new(d).unwrap()).simulate(&op)
            } else {
                op.clone()
            };
            let fit = LevelsFit::new(&process(&valve, 0.05, seed), &op, false);
            let (a, b) = (
                walk_chunks(&fit, &op, range),
                walk_in_order(&fit, &op, range),
            );
            assert_eq!(a, b, "d = {d}");
        }
    }

    #[test]
    fn a_sticky_valve_is_found_and_op_is_not_beaten_by_chance() {
        let op = ramp_op(800);
        let sticky = Model::Stenman(Stenman::new(2.0).unwrap()).simulate(&op);
        let pv = process(&sticky, 0.05, 7);
        let found = levels_walk(&op, &pv, false).unwrap();
        assert!(found.ratio > 100.0, "ratio {}", found.ratio);
        assert!((found.band - 2.0).abs() < 0.5, "band {}", found.band);
        let healthy = process(&op, 0.05, 7);
        let none = levels_walk(&op, &healthy, false).unwrap();
        assert!(none.ratio < 20.0, "ratio {}", none.ratio);
        assert!(none.trajectories > 10);
    }

    #[test]
    fn a_valve_whose_slips_land_short_of_op_is_fitted_as_one() {
        // He's valve, fs = 3, fd = 0.75: the refinement after the Stenman walk picks it
        let op = ramp_op(800);
        let he = Model::He(He::new(3.0, 0.75).unwrap()).simulate_from(&op, Some(op[0]));
        let pv = process(&he, 0.05, 11);
        let w = levels_walk(&op, &pv, false).unwrap();
        assert!(w.slip_short > 0.0 && w.slip_short < w.band, "{w:?}");
        assert!((w.band - 3.0).abs() < 0.75, "{w:?}");
        assert!(w.ratio > 20.0, "{w:?}");
    }

    #[test]
    fn a_healthy_level_loop_with_little_noise_is_not_a_sticky_one() {
        // PV integrates the valve: the running sum's column is large beside what is left of PV
        let op = ramp_op(2000);
        let mut rng = seeded(5);
        let mut level = 40.0;
        let pv: Vec<f64> = op
            .iter()
            .map(|&u| {
                let y = level + 0.01 * gaussian(&mut rng);
                level += 0.02 * (u - 50.0);
                y
            })
            .collect();
        let w = levels_walk(&op, &pv, true).unwrap();
        assert!(w.ratio.is_finite() && w.ratio < 20.0, "ratio {}", w.ratio);
    }

    #[test]
    fn short_constant_or_broken_records_give_none() {
        assert!(levels_walk(&[1.0; 50], &[1.0; 50], false).is_none());
        assert!(levels_walk(&[1.0; 300], &[2.0; 300], false).is_none());
        let mut op = ramp_op(300);
        op[5] = f64::NAN;
        assert!(levels_walk(&op, &ramp_op(300), false).is_none());
    }
}
