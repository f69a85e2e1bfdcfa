//! Output-error simulation of a fitted model.

#![allow(clippy::needless_range_loop)]

use super::*;

/// Output-error simulation from the measured initial conditions; returns the error sum of squares
/// over `t0..` (infinite when the model diverges). Writes the simulated output when asked.
#[allow(clippy::too_many_arguments)]
pub(super) fn simulate_sse(
    y: &[f64],
    mv: &[f64],
    s: Structure,
    a: &[f64],
    b: &[f64],
    c: f64,
    t0: usize,
    out: Option<&mut Vec<f64>>,
) -> f64 {
    // the parameters in one array on the stack (this runs in every refinement's iterations)
    let mut theta = [0.0; 5];
    theta[..s.na].copy_from_slice(&a[..s.na]);
    theta[s.na..s.na + s.nb].copy_from_slice(&b[..s.nb]);
    theta[s.na + s.nb] = c;
    simulate_run(&Run::of(y, mv, s, &theta, f64::INFINITY), t0, out)
}

/// One output-error simulation: a fit's coefficients (orders at most 2; a missing order's are
/// 0), its output and input, and the bound past which it stops (see [`simulate_n`]).
#[derive(Clone, Copy)]
pub(super) struct Run<'a> {
    pub y: &'a [f64],
    pub mv: &'a [f64],
    pub nk: usize,
    pub na: usize,
    pub nb: usize,
    pub a: [f64; 2],
    pub b: [f64; 2],
    pub c: f64,
    pub bound: f64,
}

impl<'a> Run<'a> {
    /// The run of structure `s`'s parameters `theta` (a, then b, then the constant) on `y` and
    /// `mv`, stopped past `bound`.
    pub fn of(y: &'a [f64], mv: &'a [f64], s: Structure, theta: &[f64], bound: f64) -> Self {
        let (na, nb) = (s.na, s.nb);
        Self {
            y,
            mv,
            nk: s.nk,
            na,
            nb,
            a: std::array::from_fn(|i| if i < na { theta[i] } else { 0.0 }),
            b: std::array::from_fn(|j| if j < nb { theta[na + j] } else { 0.0 }),
            c: theta[na + nb],
            bound,
        }
    }
}

/// [`simulate_n`] with the run's orders.
pub(super) fn simulate_run(r: &Run, t0: usize, out: Option<&mut Vec<f64>>) -> f64 {
    macro_rules! go {
        ($na:literal, $nb:literal) => {
            simulate_n::<$na, $nb>(
                r.y,
                r.mv,
                r.nk,
                &std::array::from_fn(|i| r.a[i]),
                &std::array::from_fn(|j| r.b[j]),
                r.c,
                t0,
                out,
                r.bound,
            )
        };
    }
    match (r.na, r.nb) {
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
pub(super) fn simulate_n<const NA: usize, const NB: usize>(
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
    debug_assert!(NA <= 2, "orders are at most 2");
    let n = y.len();
    // the last two simulated outputs (y[k-1], y[k-2]; a missing order's is never read)
    let mut y1 = if NA > 0 { y[t0 - 1] } else { 0.0 };
    let mut y2 = if NA > 1 { y[t0 - 2] } else { 0.0 };
    if let Some(o) = out.as_deref_mut() {
        o.clear();
        o.extend_from_slice(&y[..t0]);
    }
    let (a0, a1) = (
        if NA > 0 { a[0] } else { 0.0 },
        if NA > 1 { a[1] } else { 0.0 },
    );
    // two samples per step, both from the two outputs before them:
    //   y[k]   = u[k] + a0 y[k-1] + a1 y[k-2]
    //   y[k+1] = u[k+1] + a0 u[k] + (a0² + a1) y[k-1] + a0 a1 y[k-2]
    // so the recursion's critical path is one multiply-add per two samples, not per sample
    let (p1, p2) = (a0 * a0 + a1, a0 * a1);
    let len = n - t0;
    let ms: [&[f64]; NB] = std::array::from_fn(|j| &mv[t0 - nk - j..t0 - nk - j + len]);
    let target = &y[t0..n];
    let input = |k: usize| {
        let mut u = c;
        for j in 0..NB {
            u += b[j] * ms[j][k];
        }
        u
    };
    let mut sse = 0.0;
    let mut k = 0;
    while k + 1 < len {
        let (u0, u1) = (input(k), input(k + 1));
        let v0 = (u0 + a1 * y2) + a0 * y1;
        let v1 = (u1 + a0 * u0 + p2 * y2) + p1 * y1;
        let (e0, e1) = (target[k] - v0, target[k + 1] - v1);
        sse += e0 * e0 + e1 * e1;
        if let Some(o) = out.as_deref_mut() {
            o.push(v0);
            o.push(v1);
        }
        (y2, y1) = (v0, v1);
        k += 2;
        // checked every 64 samples: cheap, and most wrong trajectories are out within a few hundred
        if k % 64 == 0 && sse > bound {
            return f64::INFINITY;
        }
    }
    if k < len {
        let v = (input(k) + a1 * y2) + a0 * y1;
        let e = target[k] - v;
        sse += e * e;
        if let Some(o) = out {
            o.push(v);
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
pub(super) fn dot(a: &[f64], b: &[f64]) -> f64 {
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
