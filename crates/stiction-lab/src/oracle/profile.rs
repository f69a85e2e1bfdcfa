//! The oracles that know less of the process: each hypothesis's likelihood with the process
//! profiled on a grid, searched by coordinate ascent (with the band, the noise and the drift's
//! intensity), from the truth or from a fit's process.

use super::kalman::{replay, response, state_space, FullRun, LoadStateSpace, Mat, NS};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, Process, Signal};

/// The log-likelihood of the residual `r` (`G load + noise` under one hypothesis) with PV seen at
/// the steps where `seen`; the load starts at rest. Unlike [`kalman_llr`] it keeps the
/// innovation variances' term, so hypotheses under different processes compare.
fn kalman_ll(ss: &LoadStateSpace, sigma: f64, r: &[f64], seen: &[bool]) -> f64 {
    let mut x = [0.0; NS];
    let mut p = [[0.0; NS]; NS];
    let var = sigma * sigma;
    let mut ll = 0.0;
    for t in 0..r.len() {
        if seen[t] {
            let pc: [f64; NS] = std::array::from_fn(|i| (0..NS).map(|j| p[i][j] * ss.c[j]).sum());
            let s = (0..NS).map(|i| ss.c[i] * pc[i]).sum::<f64>() + var;
            let k: [f64; NS] = std::array::from_fn(|i| pc[i] / s);
            let nu = r[t] - (0..NS).map(|i| ss.c[i] * x[i]).sum::<f64>();
            ll -= 0.5 * (nu * nu / s + (std::f64::consts::TAU * s).ln());
            for i in 0..NS {
                x[i] += k[i] * nu;
                for j in 0..NS {
                    p[i][j] -= k[i] * pc[j];
                }
            }
        }
        x = std::array::from_fn(|i| (0..NS).map(|j| ss.a[i][j] * x[j]).sum());
        let ap: Mat = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..NS).map(|l| ss.a[i][l] * p[l][j]).sum())
        });
        p = std::array::from_fn(|i| {
            std::array::from_fn(|j| (0..NS).map(|l| ap[i][l] * ss.a[j][l]).sum())
        });
        p[3][3] += ss.q;
    }
    ll
}

/// The log-likelihood of the run's PV at the recorded samples if `model` were the valve, under
/// `setup`'s process, noise and load model (as the "recorded" oracle sees it).
pub fn recorded_log_likelihood(setup: &ClosedLoop, model: &Model, run: &FullRun) -> f64 {
    let n = run.op.len();
    let pred = replay(setup, model, run);
    let mut r: Vec<f64> = run.pv.iter().zip(&pred).map(|(y, p)| y - p).collect();
    let kick = match &setup.load {
        Some(Signal::IntegratedRandomWalk { slope_std, .. }) => slope_std * run.dt.sqrt(),
        _ => {
            let load = setup
                .load
                .as_ref()
                .map_or_else(|| vec![0.0; n], |l| l.generate(run.dt, n));
            let g = response(&setup.process, run.dt, &load);
            r.iter_mut().zip(&g).for_each(|(a, b)| *a -= b);
            0.0
        }
    };
    let mut seen = vec![false; n];
    for &j in &run.recorded {
        seen[j] = true;
    }
    kalman_ll(
        &state_space(&setup.process, run.dt, kick),
        setup.noise,
        &r,
        &seen,
    )
}

/// Multipliers of the process's gain, time constants and dead time the profile searches.
pub const NARROW: [f64; 7] = [0.7, 0.8, 0.9, 1.0, 1.1, 1.25, 1.4];
/// A wide profile: 0.25 to 4 times the truth, geometric.
pub const WIDE: [f64; 9] = [0.25, 0.35, 0.5, 0.71, 1.0, 1.41, 2.0, 2.83, 4.0];

/// The generalised likelihood ratio of `sticky` against a healthy valve with the process free
/// under each hypothesis: each hypothesis's log-likelihood maximised over the process's gain, time
/// constants (together) and dead time, each from 0.7 to 1.4 times the truth.
pub fn profiled_llr(setup: &ClosedLoop, sticky: &Model, run: &FullRun, grid: &[f64]) -> f64 {
    profile(setup, &[*sticky], run, grid) - profile(setup, &[HEALTHY], run, grid)
}

/// [`profiled_llr`] with the band free too: the sticky hypothesis's likelihood maximised over
/// Stenman valves of 16 bands (`band_grid`) as well as the process. A generalised likelihood
/// ratio over the whole grid: no search, so no local optimum.
pub fn profiled_band_free_llr(setup: &ClosedLoop, run: &FullRun, grid: &[f64]) -> f64 {
    let valves: Vec<Model> = band_grid(16)
        .map(|d| Model::Stenman(Stenman { d }))
        .collect();
    profile(setup, &valves, run, grid) - profile(setup, &[HEALTHY], run, grid)
}

const HEALTHY: Model = Model::Stenman(Stenman { d: 0.0 });

/// The greatest log-likelihood over the valves and the grid of process multipliers.
fn profile(setup: &ClosedLoop, valves: &[Model], run: &FullRun, grid: &[f64]) -> f64 {
    let mut top = f64::NEG_INFINITY;
    for &k in grid {
        for &t in grid {
            for &d in grid {
                let mut s = setup.clone();
                s.process = rescaled(&setup.process, k, t, d);
                for valve in valves {
                    top = top.max(recorded_log_likelihood(&s, valve, run));
                }
            }
        }
    }
    top
}

/// The process with its gain times `k`, time constants times `t` and dead time times `d`.
pub fn rescaled(p: &Process, k: f64, t: f64, d: f64) -> Process {
    match *p {
        Process::Foptd { k: g, tau, delay } => Process::Foptd {
            k: g * k,
            tau: tau * t,
            delay: delay * d,
        },
        Process::Integrating { k: g, delay } => Process::Integrating {
            k: g * k,
            delay: delay * d,
        },
        Process::Soptd {
            k: g,
            tau1,
            tau2,
            delay,
        } => Process::Soptd {
            k: g * k,
            tau1: tau1 * t,
            tau2: tau2 * t,
            delay: delay * d,
        },
    }
}

/// What a likelihood-ratio test may fit under each hypothesis.
#[derive(Clone, Copy)]
pub struct Free {
    /// The Stenman band (on a grid of 16 bands log-uniform in 0.5-5 % of span); else the loop's
    /// own valve.
    pub band: bool,
    /// The measurement noise's standard deviation and the load drift's intensity.
    pub noise_and_drift: bool,
}

/// `n` bands log-uniform in the suite's range, 0.5-5 % of span (the middles of equal steps).
pub fn band_grid(n: usize) -> impl Iterator<Item = f64> {
    (0..n).map(move |i| (0.5f64.ln() + (i as f64 + 0.5) / n as f64 * 10f64.ln()).exp())
}

/// The generalised likelihood ratio of a sticky valve against a healthy one, each hypothesis's
/// log-likelihood maximised by coordinate ascent (three sweeps) over the process's gain, time
/// constants and dead time (from the truth), and as `free` says the band and the noise and drift.
/// A local search: its optimum is a lower bound on each hypothesis's profile, the same search for
/// both.
pub fn searched_llr(setup: &ClosedLoop, sticky: &Model, run: &FullRun, free: Free) -> f64 {
    searched_from(setup, sticky, run, free, 3, &NARROW)
}

/// [`searched_llr`] with both hypotheses' searches started from `setup`'s process (e.g. as a fit
/// identifies it), over wider steps and more sweeps.
pub fn searched_wide(setup: &ClosedLoop, sticky: &Model, run: &FullRun, free: Free) -> f64 {
    searched_from(
        setup,
        sticky,
        run,
        free,
        5,
        &[0.25, 0.5, 0.8, 1.0, 1.25, 2.0, 4.0],
    )
}

/// The coordinate ascent from `setup`: `sweeps` sweeps, each parameter tried at `steps` times
/// its value.
fn searched_from(
    setup: &ClosedLoop,
    sticky: &Model,
    run: &FullRun,
    free: Free,
    sweeps: usize,
    steps: &[f64],
) -> f64 {
    let fit = |valve: Option<&Model>| -> f64 {
        // multipliers of gain, time constants, dead time, noise, drift; and the band
        let mut m = [1.0f64; 5];
        let mut band = 1.5;
        let ll = |m: &[f64; 5], band: f64| -> f64 {
            let mut s = setup.clone();
            s.process = rescaled(&setup.process, m[0], m[1], m[2]);
            s.noise = setup.noise * m[3];
            if let Some(Signal::IntegratedRandomWalk { slope_std, .. }) = &mut s.load {
                *slope_std *= m[4];
            }
            let model = match valve {
                None => HEALTHY,
                Some(_) if free.band => Model::Stenman(Stenman { d: band }),
                Some(v) => *v,
            };
            recorded_log_likelihood(&s, &model, run)
        };
        let mut best = ll(&m, band);
        let params = if free.noise_and_drift { 5 } else { 3 };
        for _ in 0..sweeps {
            for i in 0..params {
                let centre = m[i];
                let steps: &[f64] = if i == 4 {
                    &[0.1, 0.3, 1.0, 3.0, 10.0]
                } else {
                    steps
                };
                for &f in steps {
                    let mut t = m;
                    t[i] = centre * f;
                    let v = ll(&t, band);
                    if v > best {
                        (best, m) = (v, t);
                    }
                }
            }
            if valve.is_some() && free.band {
                for b in band_grid(16) {
                    let v = ll(&m, b);
                    if v > best {
                        (best, band) = (v, b);
                    }
                }
            }
        }
        best
    };
    fit(Some(sticky)) - fit(None)
}
