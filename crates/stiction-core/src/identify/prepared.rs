//! Least-squares fits of one structure: the PV's sums computed once, each valve trajectory's
//! sums and simulation per call.

#![allow(clippy::needless_range_loop)]

use super::pair::simulate_pair;
use super::simulate::{simulate_run, Run};
use super::*;

/// The sums of a least-squares fit that involve the valve position.
#[derive(Debug, Clone, Copy, Default)]
pub struct ValveSums {
    mm: [[f64; 2]; 2],
    ym: [[f64; 2]; 2],
    m1: [f64; 2],
    hm: [f64; 2],
}

/// Everything of a fit that depends only on the PV, computed once per structure: the many valve
/// trajectories a search tries then cost one pass each for their own sums and one simulation.
pub struct Prepared<'a> {
    y: &'a [f64],
    s: Structure,
    t0: usize,
    /// sums over the used samples: y-lag x y-lag, y-lag, y x y-lag, y x y
    yy_lags: [[f64; 2]; 2],
    y_lags: [f64; 2],
    y_y_lags: [f64; 2],
    yy: f64,
    y_sum: f64,
    count: f64,
}

impl<'a> Prepared<'a> {
    /// The PV's sums for structure `s` (at most 2 output lags and 2 input terms; panics otherwise).
    pub fn new(data: &'a Data, s: Structure) -> Self {
        assert!(s.na <= 2 && s.nb <= 2 && s.nk >= 1);
        let y = data.y(s.integrating);
        let t0 = data.t0;
        let mut yy_lags = [[0.0; 2]; 2];
        let mut y_lags = [0.0; 2];
        let mut y_y_lags = [0.0; 2];
        let mut yy = 0.0;
        for t in t0..y.len() {
            for i in 0..s.na {
                let yi = y[t - 1 - i];
                y_lags[i] += yi;
                y_y_lags[i] += y[t] * yi;
                for j in i..s.na {
                    yy_lags[i][j] += yi * y[t - 1 - j];
                }
            }
            yy += y[t] * y[t];
        }
        Self {
            y,
            s,
            t0,
            yy_lags,
            y_lags,
            y_y_lags,
            yy,
            y_sum: y[t0..].iter().sum(),
            count: y.len().saturating_sub(t0) as f64,
        }
    }

    /// The structure these sums are for.
    pub fn structure(&self) -> Structure {
        self.s
    }

    /// Least squares and simulation for one valve trajectory.
    pub fn fit(&self, mv: &[f64]) -> Option<Fit> {
        self.fit_bounded(mv, f64::INFINITY)
    }

    /// As [`Prepared::fit`], but the simulation stops as soon as its error exceeds `bound`
    /// (the fit can then not be the best, and its `sse_simulation` is infinite).
    pub fn fit_bounded(&self, mv: &[f64], bound: f64) -> Option<Fit> {
        // the orders are compile-time constants inside, so the loops unroll
        match (self.s.na, self.s.nb) {
            (0, 1) => self.fit_n::<0, 1>(mv, bound),
            (0, 2) => self.fit_n::<0, 2>(mv, bound),
            (1, 1) => self.fit_n::<1, 1>(mv, bound),
            (1, 2) => self.fit_n::<1, 2>(mv, bound),
            (2, 1) => self.fit_n::<2, 1>(mv, bound),
            (2, 2) => self.fit_n::<2, 2>(mv, bound),
            _ => unreachable!("orders are checked when prepared"),
        }
    }

    fn fit_n<const NA: usize, const NB: usize>(&self, mv: &[f64], bound: f64) -> Option<Fit> {
        let sums = self.sums_n::<NA, NB>(mv);
        self.finish_n::<NA, NB>(&sums, mv, bound)
    }

    /// The valve's own sums for a whole trajectory.
    pub fn sums(&self, mv: &[f64]) -> ValveSums {
        match (self.s.na, self.s.nb) {
            (0, 1) => self.sums_n::<0, 1>(mv),
            (0, 2) => self.sums_n::<0, 2>(mv),
            (1, 1) => self.sums_n::<1, 1>(mv),
            (1, 2) => self.sums_n::<1, 2>(mv),
            (2, 1) => self.sums_n::<2, 1>(mv),
            (2, 2) => self.sums_n::<2, 2>(mv),
            _ => unreachable!("orders are checked when prepared"),
        }
    }

    /// Bring `sums` from trajectory `old` to `new`, which differ only at the samples `changed`
    /// (sorted): only the regression rows that see a changed sample are touched.
    pub fn update_sums(
        &self,
        sums: &mut ValveSums,
        old: &[f64],
        new: &[f64],
        changed: &[usize],
        rows: &mut Vec<usize>,
    ) {
        let (s, t0, n) = (self.s, self.t0, self.y.len());
        rows.clear();
        // the rows that see a changed sample i through an input lag: i + nk and i + nk + 1;
        // `changed` is increasing, so these come out increasing once repeats are skipped
        for &i in changed {
            for j in 0..s.nb {
                let t = i + s.nk + j;
                if t >= t0 && t < n && rows.last().is_none_or(|&last| t > last) {
                    rows.push(t);
                }
            }
        }
        match (s.na, s.nb) {
            (0, 1) => self.update_rows_n::<0, 1>(sums, old, new, rows),
            (0, 2) => self.update_rows_n::<0, 2>(sums, old, new, rows),
            (1, 1) => self.update_rows_n::<1, 1>(sums, old, new, rows),
            (1, 2) => self.update_rows_n::<1, 2>(sums, old, new, rows),
            (2, 1) => self.update_rows_n::<2, 1>(sums, old, new, rows),
            (2, 2) => self.update_rows_n::<2, 2>(sums, old, new, rows),
            _ => unreachable!("orders are checked when prepared"),
        }
    }

    /// The rows' share of the sums taken out for `old` and put in for `new`.
    fn update_rows_n<const NA: usize, const NB: usize>(
        &self,
        sums: &mut ValveSums,
        old: &[f64],
        new: &[f64],
        rows: &[usize],
    ) {
        let (nk, y) = (self.s.nk, self.y);
        for &t in rows {
            for (mv, sign) in [(old, -1.0), (new, 1.0)] {
                let m: [f64; NB] = std::array::from_fn(|j| mv[t - nk - j]);
                for j in 0..NB {
                    sums.m1[j] += sign * m[j];
                    sums.hm[j] += sign * y[t] * m[j];
                    for k in j..NB {
                        sums.mm[j][k] += sign * m[j] * m[k];
                    }
                    for i in 0..NA {
                        sums.ym[i][j] += sign * y[t - 1 - i] * m[j];
                    }
                }
            }
        }
    }

    /// Least squares from the sums, then the simulation (stopped once its error exceeds `bound`).
    pub fn fit_from_sums(&self, sums: &ValveSums, mv: &[f64], bound: f64) -> Option<Fit> {
        match (self.s.na, self.s.nb) {
            (0, 1) => self.finish_n::<0, 1>(sums, mv, bound),
            (0, 2) => self.finish_n::<0, 2>(sums, mv, bound),
            (1, 1) => self.finish_n::<1, 1>(sums, mv, bound),
            (1, 2) => self.finish_n::<1, 2>(sums, mv, bound),
            (2, 1) => self.finish_n::<2, 1>(sums, mv, bound),
            (2, 2) => self.finish_n::<2, 2>(sums, mv, bound),
            _ => unreachable!("orders are checked when prepared"),
        }
    }

    fn sums_n<const NA: usize, const NB: usize>(&self, mv: &[f64]) -> ValveSums {
        let (s, y, t0) = (self.s, self.y, self.t0);
        let nk = s.nk;
        // the valve's own sums: mv-lag x mv-lag, y-lag x mv-lag, mv-lag, y x mv-lag
        let mut mm = [[0.0f64; 2]; 2];
        let mut ym = [[0.0f64; 2]; 2];
        let mut m1 = [0.0f64; 2];
        let mut hm = [0.0f64; 2];
        // lagged views of equal length, so the loop runs without bounds checks
        let len = y.len() - t0;
        let target = &y[t0..t0 + len];
        let ms: [&[f64]; NB] = std::array::from_fn(|j| &mv[t0 - nk - j..t0 - nk - j + len]);
        let ys: [&[f64]; NA] = std::array::from_fn(|i| &y[t0 - 1 - i..t0 - 1 - i + len]);
        for k in 0..len {
            let m: [f64; NB] = std::array::from_fn(|j| ms[j][k]);
            let yl: [f64; NA] = std::array::from_fn(|i| ys[i][k]);
            let target = target[k];
            for j in 0..NB {
                m1[j] += m[j];
                hm[j] += target * m[j];
                for k in j..NB {
                    mm[j][k] += m[j] * m[k];
                }
                for i in 0..NA {
                    ym[i][j] += yl[i] * m[j];
                }
            }
        }
        ValveSums { mm, ym, m1, hm }
    }

    /// The least-squares coefficients from the sums, and the right-hand side they solve.
    fn solve_n<const NA: usize, const NB: usize>(
        &self,
        sums: &ValveSums,
    ) -> Option<([f64; MAX_P], [f64; MAX_P])> {
        let ValveSums { mm, ym, m1, hm } = *sums;
        // assemble [y-lags, mv-lags, 1] (upper triangle)
        let p = NA + NB + 1;
        let mut g = [[0.0f64; MAX_P]; MAX_P];
        let mut h = [0.0f64; MAX_P];
        for i in 0..NA {
            for j in i..NA {
                g[i][j] = self.yy_lags[i][j];
            }
            for j in 0..NB {
                g[i][NA + j] = ym[i][j];
            }
            g[i][p - 1] = self.y_lags[i];
            h[i] = self.y_y_lags[i];
        }
        for j in 0..NB {
            for k in j..NB {
                g[NA + j][NA + k] = mm[j][k];
            }
            g[NA + j][p - 1] = m1[j];
            h[NA + j] = hm[j];
        }
        g[p - 1][p - 1] = self.count;
        h[p - 1] = self.y_sum;
        Some((solve(&g, &h, p)?, h))
    }

    /// The simulation of the least-squares fit from `sums` on `mv`, to be run beside another
    /// ([`costs_from_sums`]); `None` when the normal equations are singular.
    fn run<'m>(&'m self, sums: &ValveSums, mv: &'m [f64], bound: f64) -> Option<Run<'m>> {
        let (na, nb) = (self.s.na, self.s.nb);
        let (theta, _) = match (na, nb) {
            (0, 1) => self.solve_n::<0, 1>(sums),
            (0, 2) => self.solve_n::<0, 2>(sums),
            (1, 1) => self.solve_n::<1, 1>(sums),
            (1, 2) => self.solve_n::<1, 2>(sums),
            (2, 1) => self.solve_n::<2, 1>(sums),
            (2, 2) => self.solve_n::<2, 2>(sums),
            _ => unreachable!("orders are checked when prepared"),
        }?;
        Some(Run::of(self.y, mv, self.s, &theta, bound))
    }

    fn finish_n<const NA: usize, const NB: usize>(
        &self,
        sums: &ValveSums,
        mv: &[f64],
        bound: f64,
    ) -> Option<Fit> {
        let (s, y, t0) = (self.s, self.y, self.t0);
        let nk = s.nk;
        let p = NA + NB + 1;
        let (theta, h) = self.solve_n::<NA, NB>(sums)?;
        let sse_one_step = (self.yy - (0..p).map(|i| theta[i] * h[i]).sum::<f64>()).max(0.0);
        let a: [f64; NA] = std::array::from_fn(|i| theta[i]);
        let b: [f64; NB] = std::array::from_fn(|j| theta[NA + j]);
        let c = theta[p - 1];
        let sse_simulation = simulate_n::<NA, NB>(y, mv, nk, &a, &b, c, t0, None, bound);
        Some(Fit {
            structure: s,
            a: a.to_vec(),
            b: b.to_vec(),
            c,
            sse_one_step,
            sse_simulation,
            sst: self.yy.max(f64::MIN_POSITIVE),
        })
    }
}

/// The simulation errors of the least-squares fits of several structures (`prepared`, all on the
/// same data) on one valve trajectory `mv`, from each one's `sums`, each stopped over its bound:
/// for each, what `fit_from_sums(sums, mv, bound)` gives as `sse_simulation` (infinite without a
/// fit), bit for bit. The simulations run two at a time, side by side.
pub(crate) fn costs_from_sums(
    prepared: &[&Prepared],
    sums: &[ValveSums],
    mv: &[f64],
    bounds: &[f64],
) -> Vec<f64> {
    let mut costs = vec![f64::INFINITY; prepared.len()];
    // the fits that exist, in pairs of equally long outputs (a level and a change per sample
    // are equally long: both the record's length)
    let live: Vec<(usize, Run)> = prepared
        .iter()
        .zip(sums)
        .zip(bounds)
        .enumerate()
        .filter_map(|(i, ((p, s), &b))| p.run(s, mv, b).map(|r| (i, r)))
        .collect();
    let t0 = prepared.first().map_or(0, |p| p.t0);
    for pair in live.chunks(2) {
        match pair {
            [(i, a), (j, b)] => [costs[*i], costs[*j]] = simulate_pair([a, b], t0),
            [(i, r)] => costs[*i] = simulate_run(r, t0, None),
            _ => unreachable!("chunks of two"),
        }
    }
    costs
}
