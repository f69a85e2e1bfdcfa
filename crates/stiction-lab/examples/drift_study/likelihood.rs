//! A drift-aware likelihood ratio of a sticky valve against one that follows OP.
//!
//! The model: `pv = K G(q) mv + n`, with `mv` the valve's position under Stenman's model driven by
//! the recorded OP (band 0: the valve follows OP), `G` a first-order process with an actuator lag
//! (or an integrator behind the lag) and a dead time of whole samples, and `n` a drifting load
//! plus measurement noise: its change follows `(1 - phi q^-1) dn = (1 - theta q^-1) e`, white `e`
//! (`theta` near 1: mostly noise; `phi` near 1: a drifting slope). For fixed shape, delay, band
//! and noise model the innovations are linear in the gain, so the gain and the innovations'
//! variance come out in closed form and every other parameter is searched on a grid: the
//! likelihood's optimum over the grid, never a local one.
//!
//! The noise model is the one that serves the linear loop best; the sticky hypothesis keeps it,
//! which can only make the ratio smaller. The statistic is twice the log-likelihood ratio,
//! `n ln(SS_linear / SS_sticky)` over the `n` innovations compared.

use stiction_core::models::{Model, Stenman};

/// What the likelihood ratio needs besides OP and PV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftRequest {
    /// Sampling interval, seconds.
    pub ts: f64,
    /// The process is integrating (`Some(true)`), self-regulating (`Some(false)`), or either.
    pub integrating: Option<bool>,
    /// The sticky hypothesis searches every noise model too (else it keeps the linear loop's).
    pub full: bool,
}

/// One hypothesis's best fit on the grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftFit {
    /// Stenman's band, OP units (0: the valve follows OP).
    pub band: f64,
    /// Process gain (PV per OP unit; per second for an integrating process).
    pub gain: f64,
    /// The process's time constant, seconds (0 for an integrating process).
    pub time_constant: f64,
    /// The actuator's (or a second) lag, seconds.
    pub lag: f64,
    /// Dead time, seconds (whole samples).
    pub dead_time: f64,
    /// The process integrates.
    pub integrating: bool,
    /// Sum of squares of the innovations.
    pub sse: f64,
}

/// The likelihood ratio and the two fits behind it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriftLikelihood {
    /// Twice the log-likelihood ratio of the sticky hypothesis over the linear one.
    pub statistic: f64,
    /// The valve that follows OP.
    pub linear: DriftFit,
    /// The best Stenman band.
    pub sticky: DriftFit,
    /// The noise model's moving-average coefficient.
    pub theta: f64,
    /// The noise model's autoregressive coefficient on the change.
    pub phi: f64,
    /// Innovations compared.
    pub samples: usize,
}

/// Dead times tried, samples.
const DELAYS: [usize; 17] = [0, 1, 2, 3, 4, 5, 6, 8, 10, 13, 16, 20, 25, 32, 40, 50, 64];
/// Moving-average coefficients of the noise model tried.
const THETAS: [f64; 6] = [0.0, 0.5, 0.8, 0.9, 0.95, 0.98];
/// Autoregressive coefficients on the change tried.
const PHIS: [f64; 3] = [0.0, 0.9, 0.99];
/// Bands tried, % of span: 16 log-uniform from 0.2 to 8.
fn bands() -> impl Iterator<Item = f64> {
    (0..16).map(|i| (0.2f64.ln() + i as f64 / 15.0 * 40f64.ln()).exp())
}

/// One noise model and the PV's change and a constant whitened by it.
struct Whitened {
    theta: f64,
    phi: f64,
    z: Vec<f64>,
    f: Vec<f64>,
}

/// A process shape: integrating or not, time constant, lag (seconds).
#[derive(Debug, Clone, Copy)]
struct Shape {
    integrating: bool,
    tau: f64,
    lag: f64,
}

fn shapes(ts: f64, n: usize, integrating: Option<bool>) -> Vec<Shape> {
    let lo = (0.5 * ts).max(0.2);
    let hi = (n as f64 * ts / 4.0).clamp(lo * 2.0, 3000.0);
    let taus: Vec<f64> = (0..10)
        .map(|i| lo * (hi / lo).powf(i as f64 / 9.0))
        .collect();
    let lags = [0.0, ts, 4.0 * ts];
    let mut out = Vec::new();
    if integrating != Some(true) {
        for &tau in &taus {
            for &lag in lags.iter().filter(|&&l| l <= tau) {
                out.push(Shape {
                    integrating: false,
                    tau,
                    lag,
                });
            }
        }
    }
    if integrating != Some(false) {
        for lag in [0.0, ts, 4.0 * ts, 16.0 * ts] {
            out.push(Shape {
                integrating: true,
                tau: 0.0,
                lag,
            });
        }
    }
    out
}

/// The change of the shape's unit-gain response to `mv`, sample by sample (0 at the start).
fn response_change(shape: Shape, ts: f64, mv: &[f64], out: &mut Vec<f64>) {
    out.clear();
    let pole = |tau: f64| if tau > 0.0 { (-ts / tau).exp() } else { 0.0 };
    let (a1, a2) = (pole(shape.lag), pole(shape.tau));
    // `l`: the lagged input, including the current sample's; `x`: the self-regulating output
    let (mut l, mut x) = (mv[0], mv[0]);
    out.push(0.0);
    for &u in &mv[..mv.len() - 1] {
        l = a1 * l + (1.0 - a1) * u;
        if shape.integrating {
            // the integrator's change; its balance lies in the fit's constant
            out.push(ts * l);
        } else {
            let next = a2 * x + (1.0 - a2) * l;
            out.push(next - x);
            x = next;
        }
    }
}

/// The noise model's whitening filter applied to `u`: `f[t] = theta f[t-1] + u[t] - phi u[t-1]`.
fn whiten(u: &[f64], theta: f64, phi: f64, out: &mut Vec<f64>) {
    out.clear();
    let (mut f, mut prev) = (0.0, 0.0);
    for &x in u {
        f = theta * f + x - phi * prev;
        prev = x;
        out.push(f);
    }
}

/// The best gain and innovations' sum of squares of `z - K w[t - k] - c f[t]` over `t0..`
/// (`f`: the whitened constant, a slope of PV), over the delays: (sse, delay, gain).
fn best_delay(z: &[f64], w: &[f64], f: &[f64], t0: usize, delays: &[usize]) -> (f64, usize, f64) {
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let (zz, zf, ff) = (
        dot(&z[t0..], &z[t0..]),
        dot(&z[t0..], &f[t0..]),
        dot(&f[t0..], &f[t0..]),
    );
    // the constant alone
    let mut best = (zz - zf * zf / ff.max(1e-300), 0, 0.0);
    let m = z.len() - t0;
    for &k in delays {
        let wk = &w[t0 - k..t0 - k + m];
        let (zw, ww, wf) = (dot(&z[t0..], wk), dot(wk, wk), dot(wk, &f[t0..]));
        let det = ww * ff - wf * wf;
        if det > 1e-12 * ww * ff.max(1e-300) {
            let gain = (zw * ff - zf * wf) / det;
            let c = (zf * ww - zw * wf) / det;
            let sse = zz - gain * zw - c * zf;
            if sse < best.0 {
                best = (sse, k, gain);
            }
        }
    }
    best
}

/// The likelihood ratio of a sticky valve against one that follows OP, on records of OP and PV
/// with no gaps. `None` when the record is too short (under 200 samples) or the lengths differ.
pub fn drift_likelihood(op: &[f64], pv: &[f64], req: &DriftRequest) -> Option<DriftLikelihood> {
    let n = op.len();
    if n < 200 || pv.len() != n || req.ts.is_nan() || req.ts <= 0.0 {
        return None;
    }
    let delays: Vec<usize> = DELAYS.iter().copied().filter(|&k| k <= n / 10).collect();
    let t0 = delays.last().copied().unwrap_or(0) + 2;
    let dy: Vec<f64> = std::iter::once(0.0)
        .chain(pv.windows(2).map(|w| w[1] - w[0]))
        .collect();
    let shapes = shapes(req.ts, n, req.integrating);
    let (mut dx, mut w) = (Vec::new(), Vec::new());
    // every noise model's whitened PV change `z` and constant `f`, once
    let ones = vec![1.0; n];
    let whitened: Vec<Whitened> = THETAS
        .iter()
        .flat_map(|&theta| PHIS.iter().map(move |&phi| (theta, phi)))
        .map(|(theta, phi)| {
            let (mut z, mut f) = (Vec::new(), Vec::new());
            whiten(&dy, theta, phi, &mut z);
            whiten(&ones, theta, phi, &mut f);
            Whitened { theta, phi, z, f }
        })
        .collect();
    // the linear hypothesis over every noise model
    let mut linear: Option<(f64, Shape, usize, f64, usize)> = None;
    let responses: Vec<Vec<f64>> = shapes
        .iter()
        .map(|&shape| {
            response_change(shape, req.ts, op, &mut dx);
            dx.clone()
        })
        .collect();
    for (i, noise) in whitened.iter().enumerate() {
        for (shape, dx) in shapes.iter().zip(&responses) {
            whiten(dx, noise.theta, noise.phi, &mut w);
            let (sse, k, gain) = best_delay(&noise.z, &w, &noise.f, t0, &delays);
            if linear.is_none_or(|b| sse < b.0) {
                linear = Some((sse, *shape, k, gain, i));
            }
        }
    }
    let (sse_lin, shape_lin, k_lin, gain_lin, noise_lin) = linear?;
    // the noise models the sticky hypothesis may take: the linear loop's, or (`full`) every one
    let models = if req.full {
        &whitened[..]
    } else {
        &whitened[noise_lin..=noise_lin]
    };
    let mut sticky = (sse_lin, shape_lin, k_lin, gain_lin, 0.0);
    let mut mv = vec![0.0; n];
    for d in bands() {
        Model::Stenman(Stenman { d }).simulate_from_into(op, None, &mut mv);
        for &shape in &shapes {
            response_change(shape, req.ts, &mv, &mut dx);
            for noise in models {
                whiten(&dx, noise.theta, noise.phi, &mut w);
                let (sse, k, gain) = best_delay(&noise.z, &w, &noise.f, t0, &delays);
                if sse < sticky.0 {
                    sticky = (sse, shape, k, gain, d);
                }
            }
        }
    }
    let m = n - t0;
    let fit = |sse: f64, s: Shape, k: usize, gain: f64, band: f64| DriftFit {
        band,
        gain,
        time_constant: s.tau,
        lag: s.lag,
        dead_time: k as f64 * req.ts,
        integrating: s.integrating,
        sse,
    };
    Some(DriftLikelihood {
        statistic: m as f64 * (sse_lin / sticky.0.max(1e-300)).ln(),
        linear: fit(sse_lin, shape_lin, k_lin, gain_lin, 0.0),
        sticky: fit(sticky.0, sticky.1, sticky.2, sticky.3, sticky.4),
        theta: whitened[noise_lin].theta,
        phi: whitened[noise_lin].phi,
        samples: m,
    })
}
