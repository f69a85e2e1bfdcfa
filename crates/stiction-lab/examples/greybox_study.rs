//! Would a grey-box likelihood-ratio test find the sticky valves `diagnose` misses? (issue 10,
//! after `oracle_bound`: an oracle that knows the process finds nearly all, even without the
//! band.) This test knows nothing but the record: the process is a first-order lag with an integer
//! delay (or an integrator, for level loops), the load an integrated random walk entering beside
//! the valve, the noise white. Its Kalman filter's gains do not depend on the data, so the
//! process gain and the noise variance are profiled out in closed form; the delay, time constant
//! and load intensity are fitted on a grid by maximum likelihood, under a valve that follows OP
//! and under sticky valves driven by the recorded OP: Kano-like valves (stuck until OP moves S
//! from where the valve stuck, then a slip that lands S - J short of OP; J = S is Stenman's
//! valve), S on a fine grid (the ratio is knife-edged in the band) at three ratios J/S, the
//! dynamics refitted at a coarse grid of bands and held on the fine one. The statistic: the best
//! sticky valve's log-likelihood against the valve that follows OP.
//!
//!     cargo run --release -p stiction-lab --example greybox_study -- [--suite routine|fast] [--benchmark | --extra N] [--steps-only | --setpoint] [--out FILE] [--jsonl FILE]
//!
//! `--steps-only` judges only the records whose setpoint steps; `--setpoint` judges those with the
//! grid held to 0.25-4 times the time constant, dead time and gain of the process identified from
//! the setpoint (`stiction_lab::setpoint`; crates/stiction-lab/journal/accuracy-history.md, "the process from the setpoint").
//!
//! The threshold is the 97.5th percentile of the not-sticky loops' statistic, historian-compressed
//! PVs left out (`diagnose` recognises them and reads no shape from them). Slow on purpose
//! (about 0.3 s a loop): a study, not a method `diagnose` can afford as it stands.

use stiction_lab::catalogue_loop;
use stiction_lab::setpoint;
use stiction_lab::study_args;

use rayon::prelude::*;
use setpoint::Region;
use std::fmt::Write as _;
use stiction_core::diagnose::{diagnose, Verdict};
use stiction_lab::catalogue::{self, BenchmarkLoop, LoopClass, Suite, Truth};
use study_args::StudyArgs;

struct Row {
    json: String,
    class: LoopClass,
    truth: Truth,
    samples: usize,
    ratio: f64,
    called: bool,
}

const DELAYS: [usize; 11] = [0, 1, 2, 3, 4, 6, 8, 11, 15, 20, 27];
const SKIP: usize = 20;
/// Bands of the coarse pass (dynamics refitted) and of the fine pass (dynamics held, gain
/// profiled), log-uniform in 0.5-5 % of span.
const COARSE: usize = 10;
const FINE: usize = 400;
/// Slip ratios J/S of the Kano hypotheses (0: Stenman-like, a slip to OP).
const RATIOS: [f64; 3] = [1.0, 0.6, 0.3];

/// A Kalman filter of the model `x' = a x + c l + K b u(t - theta)`, `l' = l + s`, `s' = s + w`,
/// `y = x + e`, with `R = 1` and `Q = q` on the slope: its gains and innovation variances do not
/// depend on the data, so the innovations are affine in the gain K.
struct Filter {
    a: f64,
    c: f64,
    /// Input factor: (1 - a) for a lag, 1 for an integrator.
    bf: f64,
    theta: usize,
    k: Vec<[f64; 3]>,
    s: Vec<f64>,
    /// The innovations of y with no input.
    nu0: Vec<f64>,
}

impl Filter {
    fn new(y: &[f64], integ: bool, theta: usize, ln_tau: f64, ln_q: f64) -> Self {
        let q = ln_q.exp();
        let (a, c, bf) = if integ {
            (1.0, 1.0, 1.0)
        } else {
            let a = (-1.0 / ln_tau.exp().max(0.05)).exp();
            (a, 1.0 - a, 1.0 - a)
        };
        let n = y.len();
        let vy = {
            let m = y.iter().sum::<f64>() / n as f64;
            y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n as f64
        }
        .max(1e-12);
        let big = 1e3 * vy;
        let mut pm = [[big, 0.0, 0.0], [0.0, big, 0.0], [0.0, 0.0, 1e-2 * vy]];
        let f = [[a, c, 0.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]];
        let mut k = Vec::with_capacity(n);
        let mut s = Vec::with_capacity(n);
        let mut nu0 = Vec::with_capacity(n);
        let mut x = [y[0], 0.0, 0.0];
        for &yt in y {
            let st = pm[0][0] + 1.0;
            let kg = [pm[0][0] / st, pm[1][0] / st, pm[2][0] / st];
            let nu = yt - x[0];
            for i in 0..3 {
                x[i] += kg[i] * nu;
            }
            let row0 = pm[0];
            for i in 0..3 {
                for j in 0..3 {
                    pm[i][j] -= kg[i] * row0[j];
                }
            }
            x = [a * x[0] + c * x[1], x[1] + x[2], x[2]];
            let mut fp = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    fp[i][j] = (0..3).map(|l| f[i][l] * pm[l][j]).sum();
                }
            }
            for i in 0..3 {
                for j in 0..3 {
                    pm[i][j] = (0..3).map(|l| fp[i][l] * f[j][l]).sum();
                }
            }
            pm[2][2] += q;
            k.push(kg);
            s.push(st);
            nu0.push(nu);
        }
        Self {
            a,
            c,
            bf,
            theta,
            k,
            s,
            nu0,
        }
    }

    /// The concentrated log-likelihood with the valve `u` (centred), K and the noise's variance
    /// profiled out.
    fn ll(&self, u: &[f64], gain: Option<(f64, f64)>) -> f64 {
        let (a, c, bf) = (self.a, self.c, self.bf);
        let mut x = [0.0f64; 3];
        let (mut s00, mut s0g, mut sgg, mut sl) = (0.0, 0.0, 0.0, 0.0);
        let mut m = 0usize;
        for t in 0..u.len() {
            let g = x[0]; // the input's share of the prediction: nu = nu0 - K g
            let kg = self.k[t];
            let st = self.s[t];
            if t >= SKIP {
                let nu0 = self.nu0[t];
                s00 += nu0 * nu0 / st;
                s0g += nu0 * g / st;
                sgg += g * g / st;
                sl += st.ln();
                m += 1;
            }
            // the input-driven part of the state, updated with its own innovation -g
            for i in 0..3 {
                x[i] -= kg[i] * g;
            }
            let ut = if t >= self.theta {
                u[t - self.theta]
            } else {
                u[0]
            };
            x = [a * x[0] + c * x[1] + bf * ut, x[1] + x[2], x[2]];
        }
        let kk = if sgg > 0.0 { s0g / sgg } else { 0.0 };
        let s1 = match gain {
            // the gain held to its range: the sum of squares at the clamped gain
            Some((lo, hi)) => {
                let kk = kk.clamp(lo, hi);
                s00 - 2.0 * kk * s0g + kk * kk * sgg
            }
            None => s00 - kk * s0g,
        }
        .max(1e-300);
        -0.5 * m as f64 * (s1 / m as f64).ln() - 0.5 * sl - 0.5 * m as f64
    }
}

const TAUS: usize = 14;
const QS: usize = 9;

/// The best (theta, ln tau, ln q) on a grid for the valve `u`, among `thetas`.
fn grid_fit(
    y: &[f64],
    u: &[f64],
    integ: bool,
    thetas: &[usize],
    region: Option<&Region>,
) -> (f64, usize, f64, f64) {
    let mut best = (f64::NEG_INFINITY, 0, 0.0, 0.0);
    let taus: Vec<f64> = if integ {
        vec![0.0]
    } else {
        let all: Vec<f64> = (0..TAUS)
            .map(|i| (0.3f64).ln() + i as f64 / (TAUS - 1) as f64 * (1000.0f64).ln())
            .collect();
        match region {
            Some(r) => r.taus(&all),
            None => all,
        }
    };
    let gain = region.map(|r| r.gain);
    for &th in thetas {
        for &lt in &taus {
            for j in 0..QS {
                let lq = (1e-9f64).ln() + j as f64 / (QS - 1) as f64 * (1e8f64).ln();
                let f = Filter::new(y, integ, th, lt, lq);
                let l = f.ll(u, gain);
                if l > best.0 {
                    best = (l, th, lt, lq);
                }
            }
        }
    }
    best
}

fn kano(op: &[f64], s: f64, j: f64, out: &mut [f64]) {
    // Kano's model reduced: stuck until OP moves s from where it stuck, then slips to OP - sign (s - j)
    let mut x = op[0];
    let mut anchor = op[0];
    for (o, &u) in out.iter_mut().zip(op) {
        if (u - anchor).abs() > s {
            let dir = (u - anchor).signum();
            x = u - dir * (s - j);
            anchor = u;
        }
        *o = x;
    }
}

fn judge(l: &BenchmarkLoop, region: Option<&Region>) -> Row {
    let d = &l.data;
    let n = d.op.len();
    let mop = d.op.iter().sum::<f64>() / n as f64;
    let mpv = d.pv.iter().sum::<f64>() / n as f64;
    let y: Vec<f64> = d.pv.iter().map(|v| v - mpv).collect();
    let u: Vec<f64> = d.op.iter().map(|v| v - mop).collect();
    let integ = l.integrating;
    let delays = region.map_or(DELAYS.to_vec(), |r| r.delays(&DELAYS));
    let (l0, th, lt, lq) = grid_fit(&y, &u, integ, &delays, region);
    let near: Vec<usize> = delays
        .iter()
        .copied()
        .filter(|&t| t + 3 >= th && t <= th + 3)
        .collect();
    let band_at = |i: usize, count: usize| {
        (0.5f64.ln() + (i as f64 + 0.5) / count as f64 * 10.0f64.ln()).exp()
    };
    let mut valve = vec![0.0; n];
    let mut centred = vec![0.0; n];
    // coarse: dynamics refitted at a few bands
    let mut coarse = (f64::NEG_INFINITY, th, lt, lq);
    for i in 0..COARSE {
        kano(&d.op, band_at(i, COARSE), band_at(i, COARSE), &mut valve);
        for (c, v) in centred.iter_mut().zip(&valve) {
            *c = v - mop;
        }
        let fit = grid_fit(&y, &centred, integ, &near, region);
        if fit.0 > coarse.0 {
            coarse = fit;
        }
    }
    let filter = Filter::new(&y, integ, coarse.1, coarse.2, coarse.3);
    let gain = region.map(|r| r.gain);
    let l0_held = filter.ll(&u, gain);
    let mut fine = Vec::new();
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    for &r in &RATIOS {
        for i in 0..FINE {
            let b = band_at(i, FINE);
            kano(&d.op, b, r * b, &mut valve);
            for (c, v) in centred.iter_mut().zip(&valve) {
                *c = v - mop;
            }
            let v = filter.ll(&centred, gain) - l0;
            if v > best.0 {
                best = (v, b, r);
            }
            fine.push(v);
        }
    }
    let top = fine.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let bf = top + (fine.iter().map(|v| (v - top).exp()).sum::<f64>() / fine.len() as f64).ln();
    let sten = &fine[..FINE];
    let stop = sten.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let sbf = stop + (sten.iter().map(|v| (v - stop).exp()).sum::<f64>() / FINE as f64).ln();
    let called = diagnose(&catalogue_loop::record(l), &catalogue_loop::request(l))
        .is_ok_and(|g| g.verdict == Verdict::Stiction);
    Row {
        json: format!(
            "{{\"id\":\"{}\",\"class\":\"{}\",\"truth\":\"{}\",\"samples\":{n},\"integrating\":{integ},\"theta\":{th},\"l0\":{l0},\"l0_held\":{l0_held},\"max\":{top},\"bf\":{bf},\"sten_max\":{stop},\"sten_bf\":{sbf},\"band\":{},\"slip_ratio\":{},\"diagnose_stiction\":{called}}}",
            l.id,
            l.class,
            l.truth.name(),
            best.1,
            best.2
        ),
        class: l.class,
        truth: l.truth,
        samples: n,
        ratio: top,
        called,
    }
}

fn quantile(mut v: Vec<f64>, q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(((v.len() as f64 - 1.0) * q).round() as usize)
        .copied()
        .unwrap_or(f64::NAN)
}

fn table(rows: &[Row], title: &str) -> String {
    let threshold = quantile(
        rows.iter()
            .filter(|r| r.truth == Truth::NotSticky && r.class != LoopClass::CompressedPv)
            .map(|r| r.ratio)
            .collect(),
        0.975,
    );
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# A grey-box likelihood-ratio test ({title})\n\nGenerated by `cargo run --release -p stiction-lab --example greybox_study`; see the example's docs. \
         Threshold: {threshold:.1}, the 97.5th percentile of the not-sticky loops' ratio (compressed PVs left out). \
         \"Found beside `diagnose`\": loops `diagnose` does not call `stiction` whose ratio reaches the threshold.\n"
    );
    let _ = writeln!(
        md,
        "| class | truth | samples | loops | median ratio | ratio at the threshold | `diagnose` calls stiction | found beside `diagnose` |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|");
    let mut keys: Vec<(String, usize)> = rows
        .iter()
        .map(|r| (r.class.to_string(), r.samples))
        .collect();
    keys.sort();
    keys.dedup();
    for (class, samples) in keys {
        let part: Vec<&Row> = rows
            .iter()
            .filter(|r| r.class.to_string() == class && r.samples == samples)
            .collect();
        let n = part.len();
        let pct = |k: usize| format!("{:.0} %", 100.0 * k as f64 / n.max(1) as f64);
        let _ = writeln!(
            md,
            "| {class} | {} | {samples} | {n} | {:.1} | {} | {} | {} |",
            part[0].truth.name(),
            quantile(part.iter().map(|r| r.ratio).collect(), 0.5),
            pct(part.iter().filter(|r| r.ratio >= threshold).count()),
            pct(part.iter().filter(|r| r.called).count()),
            pct(part
                .iter()
                .filter(|r| !r.called && r.ratio >= threshold)
                .count())
        );
    }
    md
}

fn main() {
    let args = StudyArgs::from_env("greybox_study");
    let set = match args.value("--extra") {
        Some(v) => catalogue::Set::Extra(
            v.parse()
                .unwrap_or_else(|_| args.fail("--extra needs a draw number from 0 to 255")),
        ),
        None => args.set(),
    };
    let suite = args.suite();
    let mut loops = catalogue::catalogue(suite, set);
    // `--steps-only`: the loops whose setpoint steps; `--setpoint`: those, with the process held
    // near the one identified from the setpoint (`Region`)
    let around = args.has("--setpoint");
    if around || args.has("--steps-only") {
        loops.retain(|l| Region::of(l).is_some());
    }
    let rows: Vec<Row> = loops
        .par_iter()
        .map(|l| judge(l, around.then(|| Region::of(l)).flatten().as_ref()))
        .collect();
    if let Some(path) = args.value("--jsonl") {
        let lines: Vec<&str> = rows.iter().map(|r| r.json.as_str()).collect();
        std::fs::write(path, lines.join("\n") + "\n")
            .unwrap_or_else(|e| args.fail(&format!("{path}: {e}")));
    }
    let title = format!(
        "{} suite, {}",
        if suite == Suite::Fast {
            "fast"
        } else {
            "routine"
        },
        match set {
            catalogue::Set::Benchmark => "benchmark set".to_string(),
            catalogue::Set::Calibration => "calibration set".to_string(),
            catalogue::Set::Extra(n) => format!("calibration draw {n}"),
        }
    );
    args.emit(&table(&rows, &title));
}
