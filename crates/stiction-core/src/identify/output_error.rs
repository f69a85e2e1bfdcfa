//! Output-error refinement of an equation-error fit: Steiglitz-McBride iterations and a
//! Levenberg-Marquardt polish on the simulation error.

#![allow(clippy::needless_range_loop)]

use super::pair::simulate_pair_errors;
use super::simulate::Run;
use super::*;

pub(super) const MAX_P: usize = 8;

/// `x` and `z` each filtered by `1 / A(q)`, `A(q) = 1 - a_1 q^-1 - ... - a_na q^-na` (zero
/// initial state), in one pass: each is a recursion whose steps wait for each other, so the two
/// side by side take about the time of one.
pub(super) fn inverse_filter_pair(x: &[f64], z: &[f64], a: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    debug_assert_eq!(z.len(), n);
    let (mut xf, mut zf) = (vec![0.0; n], vec![0.0; n]);
    // orders 1 and 2 run by the definition only until every lag lies inside the record, then
    // without a test per sample (the same sums in the same order); other orders throughout
    let by_definition = if matches!(a.len(), 1 | 2) {
        a.len().min(n)
    } else {
        n
    };
    for t in 0..by_definition {
        let (mut v, mut w) = (x[t], z[t]);
        for (i, ai) in a.iter().enumerate().take(t) {
            v += ai * xf[t - 1 - i];
            w += ai * zf[t - 1 - i];
        }
        xf[t] = v;
        zf[t] = w;
    }
    match *a {
        [a0] => {
            for t in 1..n {
                xf[t] = x[t] + a0 * xf[t - 1];
                zf[t] = z[t] + a0 * zf[t - 1];
            }
        }
        [a0, a1] => {
            for t in 2..n {
                xf[t] = x[t] + a0 * xf[t - 1] + a1 * xf[t - 2];
                zf[t] = z[t] + a0 * zf[t - 1] + a1 * zf[t - 2];
            }
        }
        _ => {}
    }
    (xf, zf)
}

/// The normal equations (upper triangle) of the rows `row_at` writes for each index of `rows`,
/// with the targets it returns. With `p` a constant inside, the sums unroll; each element is
/// summed in the same order whatever `p`.
fn normal_equations(
    p: usize,
    rows: std::ops::Range<usize>,
    row_at: impl Fn(usize, &mut [f64; MAX_P]) -> f64,
) -> ([[f64; MAX_P]; MAX_P], [f64; MAX_P]) {
    fn sums<const P: usize>(
        rows: std::ops::Range<usize>,
        row_at: impl Fn(usize, &mut [f64; MAX_P]) -> f64,
    ) -> ([[f64; MAX_P]; MAX_P], [f64; MAX_P]) {
        let mut g = [[0.0f64; MAX_P]; MAX_P];
        let mut h = [0.0f64; MAX_P];
        let mut row = [0.0f64; MAX_P];
        for t in rows {
            let target = row_at(t, &mut row);
            for i in 0..P {
                h[i] += row[i] * target;
                for j in i..P {
                    g[i][j] += row[i] * row[j];
                }
            }
        }
        (g, h)
    }
    match p {
        1 => sums::<1>(rows, row_at),
        2 => sums::<2>(rows, row_at),
        3 => sums::<3>(rows, row_at),
        4 => sums::<4>(rows, row_at),
        5 => sums::<5>(rows, row_at),
        6 => sums::<6>(rows, row_at),
        7 => sums::<7>(rows, row_at),
        _ => sums::<MAX_P>(rows, row_at),
    }
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
        let (yf, mf) = inverse_filter_pair(y, mv, &a);
        let (g, h) = normal_equations(p, t0..n, |t, row| {
            for i in 0..s.na {
                row[i] = yf[t - 1 - i];
            }
            for j in 0..s.nb {
                row[s.na + j] = mf[t - s.nk - j];
            }
            row[p - 1] = 1.0;
            yf[t]
        });
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
/// ... stopped after a step that lowers the error by at most this share of it: at a millionth the
/// plant benchmark's verdicts stay and its bands move a little, for about 4 % less CPU time in a
/// batch.
const LM_TOLERANCE: f64 = 1e-6;

/// The forward-difference Jacobian of a fit's simulation errors on `mv` (structure `s`): each
/// parameter nudged in turn, the nudged simulations two at a time, side by side.
struct Nudges<'a> {
    y: &'a [f64],
    mv: &'a [f64],
    t0: usize,
    s: Structure,
    /// The errors of the two nudged simulations run last.
    errors: [Vec<f64>; 2],
}

impl<'a> Nudges<'a> {
    /// The nudge of parameter `k` of `theta`.
    fn step(theta: &[f64], k: usize) -> f64 {
        1e-6 * theta[k].abs().max(1e-3)
    }

    /// `theta` with parameter `k` nudged, as a simulation to run.
    fn run(&self, theta: &[f64], k: usize) -> Run<'a> {
        let mut t = theta.to_vec();
        t[k] += Self::step(theta, k);
        Run::of(self.y, self.mv, self.s, &t, f64::INFINITY)
    }

    /// The Jacobian at `theta`, whose errors are `r`, into `jac` column by column; `false` when a
    /// nudged simulation runs away.
    fn jacobian(&mut self, theta: &[f64], r: &[f64], jac: &mut [f64]) -> bool {
        let (p, m) = (theta.len(), r.len());
        for k in (0..p).step_by(2) {
            // an odd last column is simulated beside itself (the same errors twice)
            let pair = [self.run(theta, k), self.run(theta, (k + 1).min(p - 1))];
            let [ea, eb] = &mut self.errors;
            let sses = simulate_pair_errors([&pair[0], &pair[1]], self.t0, [ea, eb]);
            for (i, col) in [k, k + 1].into_iter().enumerate().filter(|&(_, c)| c < p) {
                if !sses[i].is_finite() {
                    return false;
                }
                let h = Self::step(theta, col);
                // column by column (each column contiguous, so the divisions vectorise)
                let e = &self.errors[i];
                for (j, (a, b)) in jac[col * m..(col + 1) * m].iter_mut().zip(r.iter().zip(e)) {
                    *j = (a - b) / h;
                }
            }
        }
        true
    }
}

/// Polish a fit on its simulation (output-error) criterion by Levenberg-Marquardt with a
/// forward-difference Jacobian (Marquardt 1963): Steiglitz-McBride can stop far from the optimum
/// when the valve position is noisy (closed-loop data), and a comparison of fits is only fair at
/// both optima. Keeps stable, better iterates only.
pub(super) fn levenberg_marquardt(
    y: &[f64],
    mv: &[f64],
    t0: usize,
    start: Fit,
    iterations: usize,
) -> Fit {
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
    let mut nudges = Nudges {
        y,
        mv,
        t0,
        s,
        errors: [Vec::new(), Vec::new()],
    };
    for _ in 0..iterations {
        if !nudges.jacobian(&theta, &r, &mut jac) {
            return best_of(start, y, mv, t0, &theta, sse);
        }
        let (g, h) = normal_equations(p, 0..m, |i, row| {
            for (k, v) in row[..p].iter_mut().enumerate() {
                *v = jac[k * m + i];
            }
            r[i]
        });
        let mut improved = false;
        let mut stop = false;
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
                // a step that gains under a millionth of the error is the optimum's
                stop = sse - trial_sse <= LM_TOLERANCE * sse;
                theta = trial;
                sse = trial_sse;
                std::mem::swap(&mut r, &mut rk);
                lambda = (lambda * 0.3).max(1e-9);
                improved = true;
                break;
            }
            lambda *= 10.0;
        }
        if !improved || stop {
            break;
        }
    }
    best_of(start, y, mv, t0, &theta, sse)
}

/// The start or the polished parameters, whichever simulates better.
pub(super) fn best_of(
    start: Fit,
    y: &[f64],
    mv: &[f64],
    t0: usize,
    theta: &[f64],
    sse: f64,
) -> Fit {
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
pub(super) fn one_step_sse(
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

/// Cholesky solve of the upper-triangular-stored normal equations, with a tiny ridge. Each size
/// has its own copy (the loops then unroll: the exact walk solves one system per valve
/// trajectory and structure); every copy does the same operations in the same order.
pub(super) fn solve(g: &[[f64; MAX_P]; MAX_P], h: &[f64; MAX_P], p: usize) -> Option<[f64; MAX_P]> {
    match p {
        0 => solve_n::<0>(g, h),
        1 => solve_n::<1>(g, h),
        2 => solve_n::<2>(g, h),
        3 => solve_n::<3>(g, h),
        4 => solve_n::<4>(g, h),
        5 => solve_n::<5>(g, h),
        6 => solve_n::<6>(g, h),
        7 => solve_n::<7>(g, h),
        _ => solve_n::<MAX_P>(g, h),
    }
}

fn solve_n<const P: usize>(g: &[[f64; MAX_P]; MAX_P], h: &[f64; MAX_P]) -> Option<[f64; MAX_P]> {
    let trace: f64 = (0..P).map(|i| g[i][i]).sum();
    let ridge = 1e-12 * trace.max(f64::MIN_POSITIVE);
    // L L' = G, L stored in the lower triangle of `l`
    let mut l = [[0.0f64; MAX_P]; MAX_P];
    for i in 0..P {
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
    for i in 0..P {
        let mut sum = h[i];
        for k in 0..i {
            sum -= l[i][k] * w[k];
        }
        w[i] = sum / l[i][i];
    }
    let mut x = [0.0f64; MAX_P];
    for i in (0..P).rev() {
        let mut sum = w[i];
        for k in i + 1..P {
            sum -= l[k][i] * x[k];
        }
        x[i] = sum / l[i][i];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::inverse_filter_pair;

    /// The recursion by its definition: each sample plus the lagged outputs inside the record.
    fn by_definition(x: &[f64], a: &[f64]) -> Vec<f64> {
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

    #[test]
    fn each_orders_recursion_gives_the_definitions_sums_bit_for_bit() {
        let x: Vec<f64> = (0..200).map(|t| ((t * 37 % 101) as f64).sin()).collect();
        let z: Vec<f64> = (0..200).map(|t| ((t * 53 % 97) as f64).cos()).collect();
        for a in [&[0.9][..], &[1.3, -0.42], &[0.5, 0.2, -0.1], &[]] {
            for n in [0, 1, 2, 3, 200] {
                let (xf, zf) = inverse_filter_pair(&x[..n], &z[..n], a);
                assert_eq!(xf, by_definition(&x[..n], a), "x, a = {a:?}, n = {n}");
                assert_eq!(zf, by_definition(&z[..n], a), "z, a = {a:?}, n = {n}");
            }
        }
    }
}
