//! Choosing the orders and delay: every structure of a search from one Gram matrix per valve
//! trajectory, judged by BIC on the simulation or one-step error.

#![allow(clippy::needless_range_loop)]

use super::*;

/// The full regressor set of a search, accumulated once per valve trajectory: every structure is
/// then a sub-matrix, solved in microseconds.
pub(super) struct FullGram {
    g: Vec<f64>,
    h: Vec<f64>,
    yy: f64,
    p: usize,
    na: usize,
    m: usize,
}

impl FullGram {
    /// `mv_row[j]`: the valve position's product with itself `j` samples back, which both
    /// families share (`mv_products`).
    fn new(y: &[f64], mv: &[f64], na: usize, m: usize, t0: usize, mv_row: &[f64]) -> Self {
        let p = na + m + 1;
        let n = y.len();
        let mut g = vec![0.0; p * p];
        let mut h = vec![0.0; p];
        // column k is series[t - 1 - lag] (y for k < na, mv after), the last one the constant
        let col = |k: usize| -> (&[f64], usize) {
            if k < na {
                (y, k)
            } else {
                (mv, k - na)
            }
        };
        let yy: f64 = y[t0..].iter().map(|v| v * v).sum();
        if n <= t0 {
            return Self { g, h, yy, p, na, m };
        }
        // sum over t in t0..n of a[t - 1 - i] b[t - 1 - j]
        let direct = |a: &[f64], i: usize, b: &[f64], j: usize| -> f64 {
            dot(&a[t0 - 1 - i..n - 1 - i], &b[t0 - 1 - j..n - 1 - j])
        };
        // the constant column's products are sums of one column: differences of prefix sums
        let prefix = |v: &[f64]| {
            let mut out = vec![0.0; v.len() + 1];
            for (i, x) in v.iter().enumerate() {
                out[i + 1] = out[i] + x;
            }
            out
        };
        let (prefix_y, prefix_mv) = (prefix(y), prefix(mv));
        for a in 0..p - 1 {
            let (sa, la) = col(a);
            h[a] = dot(&sa[t0 - 1 - la..n - 1 - la], &y[t0..]);
            let ps = if a < na { &prefix_y } else { &prefix_mv };
            g[a * p + p - 1] = ps[n - 1 - la] - ps[t0 - 1 - la];
        }
        for a in 0..p - 1 {
            let (sa, la) = col(a);
            for b in a..p - 1 {
                let (sb, lb) = col(b);
                // a lagged product shifts by one sample along a diagonal of one block: add the
                // sample that enters, drop the one that leaves (exact up to rounding, O(1) each)
                // (column a - 1 is column a one lag earlier unless a starts a block); the first
                // row (y one sample back against column b) is the output's product with column
                // b one lag earlier, shifted the same way
                let shiftable = b != 0 && b != na;
                g[a * p + b] = if shiftable && a != 0 && a != na {
                    g[(a - 1) * p + (b - 1)] + sa[t0 - 1 - la] * sb[t0 - 1 - lb]
                        - sa[n - 1 - la] * sb[n - 1 - lb]
                } else if shiftable && a == 0 {
                    h[b - 1] + y[t0 - 1] * sb[t0 - 1 - lb] - y[n - 1] * sb[n - 1 - lb]
                } else if a == na {
                    mv_row[lb]
                } else {
                    direct(sa, la, sb, lb)
                };
            }
        }
        g[(p - 1) * p + p - 1] = (n - t0) as f64;
        h[p - 1] = y[t0..].iter().sum();
        Self { g, h, yy, p, na, m }
    }

    /// Sum over t in `t0..n` of `mv[t - 1] mv[t - 1 - j]`, for `j` in `0..m`.
    fn mv_products(mv: &[f64], m: usize, t0: usize) -> Vec<f64> {
        let n = mv.len();
        if n <= t0 {
            return vec![0.0; m];
        }
        (0..m)
            .map(|j| dot(&mv[t0 - 1..n - 1], &mv[t0 - 1 - j..n - 1 - j]))
            .collect()
    }

    /// Least-squares parameters and one-step SSE of a structure, from the sub-matrix.
    fn solve(&self, s: Structure) -> Option<([f64; MAX_P], f64)> {
        let mut idx = [0usize; MAX_P];
        let mut k = 0;
        for i in 0..s.na {
            idx[k] = i;
            k += 1;
        }
        for j in 0..s.nb {
            let lag = s.nk + j; // mv[t - lag] is column na + lag - 1
            if lag > self.m {
                return None;
            }
            idx[k] = self.na + lag - 1;
            k += 1;
        }
        idx[k] = self.p - 1;
        k += 1;
        let mut g = [[0.0f64; MAX_P]; MAX_P];
        let mut h = [0.0f64; MAX_P];
        for a in 0..k {
            h[a] = self.h[idx[a]];
            for b in a..k {
                let (i, j) = (idx[a].min(idx[b]), idx[a].max(idx[b]));
                g[a][b] = self.g[i * self.p + j];
            }
        }
        let theta = solve(&g, &h, k)?;
        let sse = (self.yy - (0..k).map(|i| theta[i] * h[i]).sum::<f64>()).max(0.0);
        Some((theta, sse))
    }
}

/// Bayesian information criterion of a fit's error sum of squares, with a floor (a fraction of
/// the PV's variance, the same for both families) so that perfect noise-free fits still prefer the
/// smaller structure.
pub fn bic(sse: f64, data: &Data, params: usize) -> f64 {
    let n = data.used() as f64;
    n * (sse.max(data.floor) / n).ln() + params as f64 * n.ln()
}

/// Choose the linear structure for one valve trajectory (`mv` centred): the least BIC of one-step
/// prediction over the search range, both families (one-step errors of pv and of its change are
/// the same numbers, so the families compare). Returns the structure with its criteria; the
/// simulation BIC of the chosen structure comes with it.
pub fn select(data: &Data, mv: &[f64], range: &SearchRange) -> Option<Selection> {
    let na = range.na_max();
    let m = range.nk_max + range.nb_max - 1;
    let mut best: Option<(Structure, [f64; MAX_P], f64)> = None;
    let mv_row = FullGram::mv_products(mv, m, data.t0);
    for integrating in [false, true] {
        if (integrating && !range.integrating) || (!integrating && !range.self_regulating) {
            continue;
        }
        let gram = FullGram::new(data.y(integrating), mv, na, m, data.t0, &mv_row);
        for s in range
            .structures()
            .into_iter()
            .filter(|s| s.integrating == integrating)
        {
            if let Some((theta, sse)) = gram.solve(s) {
                let crit = bic(sse, data, s.na + s.nb + 1);
                if best.is_none_or(|b| crit < b.2) {
                    best = Some((s, theta, crit));
                }
            }
        }
    }
    let (s, theta, one_step_bic) = best?;
    let y = data.y(s.integrating);
    let p = s.na + s.nb + 1;
    let sse = simulate_sse(
        y,
        mv,
        s,
        &theta[..s.na],
        &theta[s.na..s.na + s.nb],
        theta[p - 1],
        data.t0,
        None,
    );
    Some(Selection {
        structure: s,
        simulation_bic: bic(sse, data, p),
        one_step_bic,
    })
}

/// What `select` chose, with both criteria.
#[derive(Debug, Clone, Copy)]
pub struct Selection {
    /// The chosen structure.
    pub structure: Structure,
    /// BIC of its simulation error.
    pub simulation_bic: f64,
    /// The family's best one-step BIC (comparable across families).
    pub one_step_bic: f64,
}

/// BIC of a fit's simulation error (the criterion `select` ranks structures by).
pub fn simulation_bic(data: &Data, f: &Fit) -> f64 {
    let s = f.structure;
    bic(f.sse_simulation, data, s.na + s.nb + 1)
}

/// BIC of the simulation error at the PV level: integrating fits (which model the PV's change)
/// are integrated back from the measured PV at `t0`, so the two families compare on the same
/// numbers (their own simulation errors are of different outputs).
pub fn level_simulation_bic(data: &Data, mv: &[f64], f: &Fit) -> f64 {
    let s = f.structure;
    if !s.integrating {
        return simulation_bic(data, f);
    }
    let sim = simulate_pv(data, mv, f);
    let sse: f64 = sim[data.t0..]
        .iter()
        .zip(&data.pv[data.t0..])
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    if !sse.is_finite() {
        return f64::INFINITY;
    }
    bic(sse, data, s.na + s.nb + 1)
}
