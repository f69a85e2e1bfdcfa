//! The two-stage identification from the setpoint (Van den Hof and Schrama 1993) the studies
//! share: OP's part the setpoint drives (a least-squares step response of OP to SP's steps,
//! beside a level and a slope), then a first-order process with dead time (or an integrator)
//! fitted from that part alone. It carries none of PV's noise and none of the load the controller
//! answered, so, unlike OP, it is a fair input in closed loop.

use crate::catalogue::BenchmarkLoop;

/// A process: gain, time constant and dead time (seconds).
#[derive(Clone, Copy, Debug)]
pub struct Foptd {
    pub k: f64,
    pub tau: f64,
    pub delay: f64,
}

/// Solve the symmetric positive definite `a x = b` (Cholesky, `a` row-major `n` by `n`).
fn solve(a: &mut [f64], b: &mut [f64], n: usize) -> Option<()> {
    for j in 0..n {
        let mut s = a[j * n + j];
        for k in 0..j {
            s -= a[j * n + k] * a[j * n + k];
        }
        if s <= 0.0 {
            return None;
        }
        let d = s.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k * n + i] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    Some(())
}

/// Least squares of `y` on the columns `x` (each of `y`'s length), a little ridge for safety.
pub fn least_squares(x: &[&[f64]], y: &[f64]) -> Option<Vec<f64>> {
    let p = x.len();
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p];
    for i in 0..p {
        for j in 0..=i {
            let s: f64 = x[i].iter().zip(x[j]).map(|(u, v)| u * v).sum();
            a[i * p + j] = s;
            a[j * p + i] = s;
        }
        b[i] = x[i].iter().zip(y).map(|(u, v)| u * v).sum();
    }
    let scale = (0..p).map(|i| a[i * p + i]).fold(0.0, f64::max);
    for i in 0..p {
        a[i * p + i] += 1e-10 * scale + 1e-300;
    }
    solve(&mut a, &mut b, p)?;
    Some(b)
}

/// Stage one: OP's part the setpoint drives (OP = level + slope + a step response of `m` samples
/// to SP's changes; the level kept, the slope (the load's) left out). `None` when SP is constant.
pub fn op_from_setpoint(sp: &[f64], op: &[f64], m: usize) -> Option<Vec<f64>> {
    let n = sp.len();
    let (lo, hi) = sp
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if hi - lo <= 1e-9 || n < 4 * m {
        return None;
    }
    let at = |t: isize| sp[t.max(0) as usize];
    let mut x: Vec<Vec<f64>> = Vec::with_capacity(m + 3);
    x.push(vec![1.0; n]);
    x.push((0..n).map(|t| t as f64 / n as f64).collect());
    for k in 0..m {
        x.push(
            (0..n as isize)
                .map(|t| at(t - k as isize) - at(t - k as isize - 1))
                .collect(),
        );
    }
    x.push(
        (0..n as isize)
            .map(|t| at(t - m as isize) - sp[0])
            .collect(),
    );
    // columns of a step response with no step in them are left out
    let keep: Vec<usize> = (0..x.len())
        .filter(|&i| x[i].iter().any(|v| v.abs() > 1e-12))
        .collect();
    let cols: Vec<&[f64]> = keep.iter().map(|&i| x[i].as_slice()).collect();
    let beta = least_squares(&cols, op)?;
    let mut fitted = vec![0.0; n];
    for (&i, b) in keep.iter().zip(&beta) {
        if i == 1 {
            continue;
        }
        for (f, v) in fitted.iter_mut().zip(&x[i]) {
            *f += b * v;
        }
    }
    Some(fitted)
}

/// Stage two: the first-order process with dead time (or integrator) from `u` (OP's setpoint-driven
/// part) to `pv`, beside a level and a slope, by a grid over dead time and time constant (the
/// gain, level and slope by least squares at each point).
pub fn process_from(u: &[f64], pv: &[f64], ts: f64, integrating: bool) -> Option<Foptd> {
    let n = u.len();
    let max_delay = (n / 10).min(80);
    let taus: Vec<f64> = if integrating {
        vec![0.0]
    } else {
        (0..40)
            .map(|i| 0.3 * ts * (3000.0 / (0.3 * ts)).powf(i as f64 / 39.0))
            .collect()
    };
    let mean = u.iter().sum::<f64>() / n as f64;
    let ones = vec![1.0; n];
    let slope: Vec<f64> = (0..n).map(|t| t as f64 / n as f64).collect();
    let mut best: Option<(f64, Foptd)> = None;
    for delay in 0..=max_delay {
        for &tau in &taus {
            let a = if integrating { 0.0 } else { (-ts / tau).exp() };
            let mut y = vec![0.0; n];
            let mut s = 0.0;
            for t in 0..n {
                let v = u[t.saturating_sub(delay)] - mean;
                s = if integrating {
                    s + ts * v
                } else {
                    a * s + (1.0 - a) * v
                };
                y[t] = s;
            }
            let cols = [ones.as_slice(), slope.as_slice(), y.as_slice()];
            let Some(beta) = least_squares(&cols, pv) else {
                continue;
            };
            let sse: f64 = (0..n)
                .map(|t| {
                    let e = pv[t] - beta[0] - beta[1] * cols[1][t] - beta[2] * cols[2][t];
                    e * e
                })
                .sum();
            let p = Foptd {
                k: beta[2],
                tau,
                delay: delay as f64 * ts,
            };
            if best.as_ref().is_none_or(|b| sse < b.0) {
                best = Some((sse, p));
            }
        }
    }
    best.map(|b| b.1)
}

/// Where a grey box's process may lie (`greybox_study --setpoint`): around the one identified
/// from the setpoint, in samples, 0.25 to 4
/// times its time constant, dead time and gain.
pub struct Region {
    pub ln_tau: (f64, f64),
    pub delay: (f64, f64),
    pub gain: (f64, f64),
}

const SPREAD: f64 = 4.0;

impl Region {
    /// Around the process from the setpoint, when SP steps; `None` otherwise.
    pub fn of(l: &BenchmarkLoop) -> Option<Region> {
        let d = &l.data;
        let ts = l.setup.ts;
        let u = op_from_setpoint(&d.sp, &d.op, d.op.len() / 8)?;
        let p = process_from(&u, &d.pv, ts, l.integrating)?;
        // the grey box's gain: per sample for an integrator
        let k = if l.integrating { p.k * ts } else { p.k };
        let tau = (p.tau / ts).max(0.3);
        let delay = p.delay / ts;
        let g = (k / SPREAD, k * SPREAD);
        Some(Region {
            ln_tau: ((tau / SPREAD).ln(), (tau * SPREAD).ln()),
            delay: (delay / SPREAD, delay * SPREAD + 1.0),
            gain: if k >= 0.0 { g } else { (g.1, g.0) },
        })
    }

    /// The grid's time constants inside the region, or the nearest one.
    pub fn taus(&self, all: &[f64]) -> Vec<f64> {
        inside_or_nearest(all, self.ln_tau, |&t| t)
    }

    /// The grid's delays inside the region, or the nearest one.
    pub fn delays(&self, all: &[usize]) -> Vec<usize> {
        inside_or_nearest(all, self.delay, |&t| t as f64)
    }
}

/// The grid points whose value lies in `(lo, hi)`, or the one nearest its middle.
fn inside_or_nearest<T: Copy>(
    all: &[T],
    (lo, hi): (f64, f64),
    value: impl Fn(&T) -> f64,
) -> Vec<T> {
    let inside: Vec<T> = all
        .iter()
        .copied()
        .filter(|t| (lo..=hi).contains(&value(t)))
        .collect();
    if !inside.is_empty() {
        return inside;
    }
    let mid = 0.5 * (lo + hi);
    let distance = |t: &T| (value(t) - mid).abs();
    all.iter()
        .copied()
        .min_by(|a, b| distance(a).total_cmp(&distance(b)))
        .into_iter()
        .collect()
}
