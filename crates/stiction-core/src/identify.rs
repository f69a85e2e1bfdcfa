//! Linear identification of the process from the valve position to the PV: ARX models fitted by
//! least squares, orders and delay chosen by an information criterion, and output-error simulation.
//!
//!   y[t] = a_1 y[t-1] + ... + a_na y[t-na] + b_0 mv[t-nk] + ... + b_{nb-1} mv[t-nk-nb+1] + c
//!
//! For a self-regulating process `y` is the PV; for an integrating one (level loops) it is the PV's
//! change `pv[t] - pv[t-1]`. Both are centred first (the constant `c` takes up the rest), which keeps
//! the normal equations well conditioned. Every structure of a search is fitted on the same samples,
//! so their criteria compare fairly.

// small dense linear algebra reads best with the textbook's indices
#![allow(clippy::needless_range_loop)]

use serde::{Deserialize, Serialize};

/// Which linear structure: family, orders and delay (in samples, `nk >= 1`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Structure {
    pub integrating: bool,
    pub na: usize,
    pub nb: usize,
    pub nk: usize,
}

/// The ranges a structure search covers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchRange {
    /// Orders of the output lags tried for self-regulating processes (integrating: `na - 1`).
    pub na: Vec<usize>,
    pub nb_max: usize,
    pub nk_max: usize,
    /// Try self-regulating structures, integrating ones, or both.
    pub self_regulating: bool,
    pub integrating: bool,
}

impl SearchRange {
    pub fn new(nk_max: usize) -> Self {
        Self {
            na: vec![1, 2],
            nb_max: 2,
            nk_max: nk_max.max(1),
            self_regulating: true,
            integrating: true,
        }
    }

    fn na_max(&self) -> usize {
        self.na.iter().copied().max().unwrap_or(1)
    }

    /// First sample index every structure of the range can use (the integrating family needs one
    /// more sample for the difference).
    pub fn t0(&self) -> usize {
        (self.na_max() + 1).max(self.nk_max + self.nb_max)
    }

    fn structures(&self) -> Vec<Structure> {
        let mut out = Vec::new();
        for integrating in [false, true] {
            if (integrating && !self.integrating) || (!integrating && !self.self_regulating) {
                continue;
            }
            for &na in &self.na {
                let na = if integrating { na - 1 } else { na };
                for nb in 1..=self.nb_max {
                    for nk in 1..=self.nk_max {
                        out.push(Structure {
                            integrating,
                            na,
                            nb,
                            nk,
                        });
                    }
                }
            }
        }
        out
    }
}

/// The signals prepared once: centred output for each family and centred valve position.
pub struct Data<'a> {
    pub pv: &'a [f64],
    pub t0: usize,
    y_level: Vec<f64>,
    y_diff: Vec<f64>,
    mean_level: f64,
    mean_diff: f64,
    /// Smallest error sum of squares the criteria distinguish.
    floor: f64,
}

impl<'a> Data<'a> {
    pub fn new(pv: &'a [f64], t0: usize) -> Self {
        let n = pv.len();
        let mean_level = pv.iter().sum::<f64>() / n as f64;
        let mut diff = vec![0.0; n];
        for t in 1..n {
            diff[t] = pv[t] - pv[t - 1];
        }
        let mean_diff = if n > 1 {
            diff[1..].iter().sum::<f64>() / (n - 1) as f64
        } else {
            0.0
        };
        let y_level: Vec<f64> = pv.iter().map(|v| v - mean_level).collect();
        let floor = 1e-10
            * y_level
                .iter()
                .map(|v| v * v)
                .sum::<f64>()
                .max(f64::MIN_POSITIVE);
        Self {
            pv,
            t0,
            floor,
            y_level,
            y_diff: diff.iter().map(|v| v - mean_diff).collect(),
            mean_level,
            mean_diff,
        }
    }

    fn y(&self, integrating: bool) -> &[f64] {
        if integrating {
            &self.y_diff
        } else {
            &self.y_level
        }
    }

    /// Samples used by every fit.
    pub fn used(&self) -> usize {
        self.pv.len().saturating_sub(self.t0)
    }
}

/// A fitted ARX model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    pub structure: Structure,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    /// Constant, in the units of the centred output.
    pub c: f64,
    /// One-step prediction error sum of squares.
    pub sse_one_step: f64,
    /// Simulation (output-error) sum of squares.
    pub sse_simulation: f64,
    /// Sum of squares of the centred output over the samples used (for R²).
    pub sst: f64,
}

impl Fit {
    /// Whether the fitted A(q) is stable (every pole inside the unit circle): an unstable fit's
    /// simulation runs away, and its R² says nothing but that.
    pub fn stable(&self) -> bool {
        match *self.a.as_slice() {
            [] => true,
            [a1] => a1.abs() < 1.0,
            // z^2 - a1 z - a2 (the Jury conditions)
            [a1, a2] => a2.abs() < 1.0 && a1.abs() < 1.0 - a2,
            _ => false,
        }
    }

    pub fn r2_one_step(&self) -> f64 {
        1.0 - self.sse_one_step / self.sst
    }
    pub fn r2_simulation(&self) -> f64 {
        1.0 - self.sse_simulation / self.sst
    }
}

/// Centre the valve position (the constant term absorbs the mean).
pub fn centred(mv: &[f64]) -> Vec<f64> {
    let m = mv.iter().sum::<f64>() / mv.len().max(1) as f64;
    mv.iter().map(|v| v - m).collect()
}

/// Fit one structure by least squares and simulate it. `mv` must be centred (any constant offset
/// works: the constant term takes it up). `None` when the normal equations are singular (e.g. a
/// valve that never moves).
pub fn fit(data: &Data, mv: &[f64], s: Structure) -> Option<Fit> {
    Prepared::new(data, s).fit(mv)
}

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
        let (s, y, t0, n) = (self.s, self.y, self.t0, self.y.len());
        rows.clear();
        for &i in changed {
            for j in 0..s.nb {
                let t = i + s.nk + j;
                if t >= t0 && t < n {
                    rows.push(t);
                }
            }
        }
        rows.sort_unstable();
        rows.dedup();
        for &t in rows.iter() {
            for (mv, sign) in [(old, -1.0), (new, 1.0)] {
                let m = [mv[t - s.nk], if s.nb > 1 { mv[t - s.nk - 1] } else { 0.0 }];
                for j in 0..s.nb {
                    sums.m1[j] += sign * m[j];
                    sums.hm[j] += sign * y[t] * m[j];
                    for k in j..s.nb {
                        sums.mm[j][k] += sign * m[j] * m[k];
                    }
                    for i in 0..s.na {
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

    fn finish_n<const NA: usize, const NB: usize>(
        &self,
        sums: &ValveSums,
        mv: &[f64],
        bound: f64,
    ) -> Option<Fit> {
        let (s, y, t0) = (self.s, self.y, self.t0);
        let nk = s.nk;
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
        let theta = solve(&g, &h, p)?;
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

const MAX_P: usize = 8;

/// `x` filtered by `1 / A(q)`, `A(q) = 1 - a_1 q^-1 - ... - a_na q^-na` (zero initial state).
fn inverse_filter(x: &[f64], a: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; x.len()];
    for t in 0..x.len() {
        let mut v = x[t];
        for (i, ai) in a.iter().enumerate() {
            if t > i {
                v += ai * out[t - 1 - i];
            }
        }
        out[t] = v;
    }
    out
}

/// Move a fit towards the output-error optimum (Steiglitz and McBride 1965): the output and the
/// valve position are filtered by `1 / A(q)` of the current fit and the structure refitted by
/// least squares, `iterations` times. An equation-error fit of noisy closed-loop data is biased,
/// so its simulation can be much worse than the best linear model's; comparisons of simulation
/// errors (with and without stiction) need both near their own optimum. Returns the iterate of
/// least simulation error (the iteration need not decrease it), the start included.
pub fn refine_output_error(data: &Data, mv: &[f64], start: &Fit, iterations: usize) -> Fit {
    let s = start.structure;
    let mut best = start.clone();
    if s.na == 0 {
        // no output lags: least squares is already the output-error fit
        return best;
    }
    let y = data.y(s.integrating);
    let (t0, n) = (data.t0, y.len());
    let p = s.na + s.nb + 1;
    let mut a = start.a.clone();
    for _ in 0..iterations {
        let yf = inverse_filter(y, &a);
        let mf = inverse_filter(mv, &a);
        let mut g = [[0.0f64; MAX_P]; MAX_P];
        let mut h = [0.0f64; MAX_P];
        let mut row = [0.0f64; MAX_P];
        for t in t0..n {
            for i in 0..s.na {
                row[i] = yf[t - 1 - i];
            }
            for j in 0..s.nb {
                row[s.na + j] = mf[t - s.nk - j];
            }
            row[p - 1] = 1.0;
            for i in 0..p {
                h[i] += row[i] * yf[t];
                for j in i..p {
                    g[i][j] += row[i] * row[j];
                }
            }
        }
        let Some(theta) = solve(&g, &h, p) else {
            break;
        };
        let a_new = theta[..s.na].to_vec();
        let b_new = theta[s.na..s.na + s.nb].to_vec();
        // the filtered constant is the model's constant over A(1)
        let c = theta[p - 1] * (1.0 - a.iter().sum::<f64>());
        let candidate = Fit {
            structure: s,
            a: a_new.clone(),
            b: b_new.clone(),
            c,
            sse_one_step: one_step_sse(y, mv, s, &a_new, &b_new, c, t0),
            sse_simulation: simulate_sse(y, mv, s, &a_new, &b_new, c, t0, None),
            sst: start.sst,
        };
        if !candidate.stable() {
            break;
        }
        if candidate.sse_simulation < best.sse_simulation {
            best = candidate;
        }
        a = a_new;
    }
    best
}

/// Polish the coefficients of `start` (another fit's, e.g. of another valve trajectory) on
/// `mv`'s simulation error by Levenberg-Marquardt. `None` when they do not simulate `mv` stably.
pub fn polish_output_error(data: &Data, mv: &[f64], start: &Fit) -> Option<Fit> {
    let s = start.structure;
    let y = data.y(s.integrating);
    let t0 = data.t0;
    let sse = simulate_sse(y, mv, s, &start.a, &start.b, start.c, t0, None);
    if !sse.is_finite() || !start.stable() {
        return None;
    }
    let begin = Fit {
        sse_simulation: sse,
        sse_one_step: one_step_sse(y, mv, s, &start.a, &start.b, start.c, t0),
        ..start.clone()
    };
    Some(levenberg_marquardt(y, mv, t0, begin, LM_ITERATIONS))
}

/// Levenberg-Marquardt iterations on the simulation error after Steiglitz-McBride.
const LM_ITERATIONS: usize = 12;

/// Polish a fit on its simulation (output-error) criterion by Levenberg-Marquardt with a
/// forward-difference Jacobian (Marquardt 1963): Steiglitz-McBride can stop far from the optimum
/// when the valve position is noisy (closed-loop data), and a comparison of fits is only fair at
/// both optima. Keeps stable, better iterates only.
fn levenberg_marquardt(y: &[f64], mv: &[f64], t0: usize, start: Fit, iterations: usize) -> Fit {
    let s = start.structure;
    let p = s.na + s.nb + 1;
    let pack = |f: &Fit| -> Vec<f64> {
        f.a.iter()
            .chain(&f.b)
            .copied()
            .chain(std::iter::once(f.c))
            .collect()
    };
    let unpack = |theta: &[f64]| -> (Vec<f64>, Vec<f64>, f64) {
        (
            theta[..s.na].to_vec(),
            theta[s.na..s.na + s.nb].to_vec(),
            theta[p - 1],
        )
    };
    let residuals = |theta: &[f64], out: &mut Vec<f64>| -> f64 {
        let (a, b, c) = unpack(theta);
        let mut sim = Vec::with_capacity(y.len());
        let sse = simulate_sse(y, mv, s, &a, &b, c, t0, Some(&mut sim));
        out.clear();
        out.extend(y[t0..].iter().zip(&sim[t0..]).map(|(a, b)| a - b));
        sse
    };
    let mut theta = pack(&start);
    let mut r = Vec::new();
    let mut sse = residuals(&theta, &mut r);
    if !sse.is_finite() {
        return start;
    }
    let m = r.len();
    let mut lambda = 1e-3;
    let mut jac = vec![0.0; m * p];
    let mut rk = Vec::new();
    for _ in 0..iterations {
        for k in 0..p {
            let h = 1e-6 * theta[k].abs().max(1e-3);
            let mut t = theta.clone();
            t[k] += h;
            if !residuals(&t, &mut rk).is_finite() {
                return best_of(start, y, mv, t0, &theta, sse);
            }
            for i in 0..m {
                jac[i * p + k] = (r[i] - rk[i]) / h;
            }
        }
        let mut g = [[0.0f64; MAX_P]; MAX_P];
        let mut h = [0.0f64; MAX_P];
        for i in 0..m {
            let row = &jac[i * p..(i + 1) * p];
            for a in 0..p {
                h[a] += row[a] * r[i];
                for b in a..p {
                    g[a][b] += row[a] * row[b];
                }
            }
        }
        let mut improved = false;
        for _ in 0..6 {
            let mut gl = g;
            for a in 0..p {
                gl[a][a] += lambda * g[a][a].max(1e-12);
            }
            let Some(step) = solve(&gl, &h, p) else {
                lambda *= 10.0;
                continue;
            };
            let trial: Vec<f64> = (0..p).map(|k| theta[k] + step[k]).collect();
            let (a, _, _) = unpack(&trial);
            let stable = Fit { a, ..start.clone() }.stable();
            let trial_sse = if stable {
                residuals(&trial, &mut rk)
            } else {
                f64::INFINITY
            };
            if trial_sse < sse {
                theta = trial;
                sse = trial_sse;
                std::mem::swap(&mut r, &mut rk);
                lambda = (lambda * 0.3).max(1e-9);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    best_of(start, y, mv, t0, &theta, sse)
}

/// The start or the polished parameters, whichever simulates better.
fn best_of(start: Fit, y: &[f64], mv: &[f64], t0: usize, theta: &[f64], sse: f64) -> Fit {
    if sse.is_nan() || sse >= start.sse_simulation {
        return start;
    }
    let s = start.structure;
    let p = s.na + s.nb + 1;
    let (a, b, c) = (
        theta[..s.na].to_vec(),
        theta[s.na..s.na + s.nb].to_vec(),
        theta[p - 1],
    );
    Fit {
        sse_one_step: one_step_sse(y, mv, s, &a, &b, c, t0),
        sse_simulation: sse,
        a,
        b,
        c,
        ..start
    }
}

/// One-step prediction error sum of squares of an ARX model over `t0..`.
fn one_step_sse(
    y: &[f64],
    mv: &[f64],
    s: Structure,
    a: &[f64],
    b: &[f64],
    c: f64,
    t0: usize,
) -> f64 {
    (t0..y.len())
        .map(|t| {
            let mut v = c;
            for (i, ai) in a.iter().enumerate() {
                v += ai * y[t - 1 - i];
            }
            for (j, bj) in b.iter().enumerate() {
                v += bj * mv[t - s.nk - j];
            }
            (y[t] - v).powi(2)
        })
        .sum()
}

/// Cholesky solve of the upper-triangular-stored normal equations, with a tiny ridge.
fn solve(g: &[[f64; MAX_P]; MAX_P], h: &[f64; MAX_P], p: usize) -> Option<[f64; MAX_P]> {
    let trace: f64 = (0..p).map(|i| g[i][i]).sum();
    let ridge = 1e-12 * trace.max(f64::MIN_POSITIVE);
    // L L' = G, L stored in the lower triangle of `l`
    let mut l = [[0.0f64; MAX_P]; MAX_P];
    for i in 0..p {
        for j in 0..=i {
            let mut sum = g[j][i] + if i == j { ridge } else { 0.0 };
            for k in 0..j {
                sum -= l[i][k] * l[j][k];
            }
            if i == j {
                if sum <= 1e-14 * trace.max(1e-300) {
                    return None;
                }
                l[i][i] = sum.sqrt();
            } else {
                l[i][j] = sum / l[j][j];
            }
        }
    }
    let mut w = [0.0f64; MAX_P];
    for i in 0..p {
        let mut sum = h[i];
        for k in 0..i {
            sum -= l[i][k] * w[k];
        }
        w[i] = sum / l[i][i];
    }
    let mut x = [0.0f64; MAX_P];
    for i in (0..p).rev() {
        let mut sum = w[i];
        for k in i + 1..p {
            sum -= l[k][i] * x[k];
        }
        x[i] = sum / l[i][i];
    }
    Some(x)
}

/// Output-error simulation from the measured initial conditions; returns the error sum of squares
/// over `t0..` (infinite when the model diverges). Writes the simulated output when asked.
#[allow(clippy::too_many_arguments)]
fn simulate_sse(
    y: &[f64],
    mv: &[f64],
    s: Structure,
    a: &[f64],
    b: &[f64],
    c: f64,
    t0: usize,
    out: Option<&mut Vec<f64>>,
) -> f64 {
    macro_rules! go {
        ($na:literal, $nb:literal) => {
            simulate_n::<$na, $nb>(
                y,
                mv,
                s.nk,
                &std::array::from_fn(|i| a[i]),
                &std::array::from_fn(|j| b[j]),
                c,
                t0,
                out,
                f64::INFINITY,
            )
        };
    }
    match (s.na, s.nb) {
        (0, 1) => go!(0, 1),
        (0, 2) => go!(0, 2),
        (1, 1) => go!(1, 1),
        (1, 2) => go!(1, 2),
        (2, 1) => go!(2, 1),
        (2, 2) => go!(2, 2),
        _ => unreachable!("orders are at most 2"),
    }
}

#[allow(clippy::too_many_arguments)]
#[inline]
fn simulate_n<const NA: usize, const NB: usize>(
    y: &[f64],
    mv: &[f64],
    nk: usize,
    a: &[f64; NA],
    b: &[f64; NB],
    c: f64,
    t0: usize,
    mut out: Option<&mut Vec<f64>>,
    bound: f64,
) -> f64 {
    let n = y.len();
    // the last NA simulated outputs, newest first
    let mut sim: [f64; NA] = std::array::from_fn(|i| y[t0 - 1 - i]);
    if let Some(o) = out.as_deref_mut() {
        o.clear();
        o.extend_from_slice(&y[..t0]);
    }
    let mut sse = 0.0;
    let len = n - t0;
    let ms: [&[f64]; NB] = std::array::from_fn(|j| &mv[t0 - nk - j..t0 - nk - j + len]);
    let target = &y[t0..n];
    for k in 0..len {
        // everything but the newest simulated output first: the recursion's critical path is
        // then one multiply-add per sample
        let mut v = c;
        for j in 0..NB {
            v += b[j] * ms[j][k];
        }
        for i in (1..NA).rev() {
            v += a[i] * sim[i];
        }
        if NA > 0 {
            v += a[0] * sim[0];
        }
        for i in (1..NA).rev() {
            sim[i] = sim[i - 1];
        }
        if NA > 0 {
            sim[0] = v;
        }
        let e = target[k] - v;
        sse += e * e;
        if let Some(o) = out.as_deref_mut() {
            o.push(v);
        }
        // checked every 64 samples: cheap, and most wrong trajectories are out within a few hundred
        if k % 64 == 63 && sse > bound {
            return f64::INFINITY;
        }
    }
    if sse.is_finite() {
        sse
    } else {
        f64::INFINITY
    }
}

/// The simulated PV of a fit (for plots): integrating fits are integrated back from the measured
/// PV at `t0`.
pub fn simulate_pv(data: &Data, mv: &[f64], f: &Fit) -> Vec<f64> {
    let s = f.structure;
    let y = data.y(s.integrating);
    let mut out = Vec::with_capacity(y.len());
    simulate_sse(y, mv, s, &f.a, &f.b, f.c, data.t0, Some(&mut out));
    if s.integrating {
        let mut pv = data.pv[..data.t0].to_vec();
        let mut level = data.pv[data.t0 - 1];
        for &d in &out[data.t0..] {
            level += d + data.mean_diff;
            pv.push(level);
        }
        pv
    } else {
        out.iter().map(|v| v + data.mean_level).collect()
    }
}

/// A dot product with four running sums: the additions of one sum wait for each other, four
/// sums keep the pipeline full (the order is fixed, so the result is reproducible).
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let chunks = n / 4;
    for k in 0..chunks {
        let i = 4 * k;
        acc[0] += a[i] * b[i];
        acc[1] += a[i + 1] * b[i + 1];
        acc[2] += a[i + 2] * b[i + 2];
        acc[3] += a[i + 3] * b[i + 3];
    }
    let mut tail = 0.0;
    for i in 4 * chunks..n {
        tail += a[i] * b[i];
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// The full regressor set of a search, accumulated once per valve trajectory: every structure is
/// then a sub-matrix, solved in microseconds.
struct FullGram {
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
    pub structure: Structure,
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

/// Gain, time constant and dead time where they follow from the fitted coefficients.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Physical {
    /// Steady-state gain (self-regulating) or integration rate per second (integrating).
    pub gain: Option<f64>,
    /// Time constant in seconds of the (dominant) real pole.
    pub time_constant: Option<f64>,
    /// Dead time in seconds: (nk - 1) sample times (zero-order hold).
    pub dead_time: f64,
}

pub fn physical(f: &Fit, ts: f64) -> Physical {
    let s = f.structure;
    let sum_a: f64 = f.a.iter().sum();
    let sum_b: f64 = f.b.iter().sum();
    let dead_time = (s.nk as f64 - 1.0) * ts;
    let pole = match f.a.len() {
        0 => None,
        1 => Some(f.a[0]),
        _ => {
            // z^2 - a1 z - a2: the dominant real root, if the roots are real
            let (a1, a2) = (f.a[0], f.a[1]);
            let disc = a1 * a1 + 4.0 * a2;
            (disc >= 0.0).then(|| {
                let r1 = 0.5 * (a1 + disc.sqrt());
                let r2 = 0.5 * (a1 - disc.sqrt());
                if r1.abs() >= r2.abs() {
                    r1
                } else {
                    r2
                }
            })
        }
    };
    let time_constant = pole.filter(|&p| p > 0.0 && p < 1.0).map(|p| -ts / p.ln());
    let gain = if (1.0 - sum_a).abs() > 1e-9 {
        let g = sum_b / (1.0 - sum_a);
        Some(if s.integrating { g / ts } else { g })
    } else {
        None
    };
    Physical {
        gain,
        time_constant,
        dead_time,
    }
}
