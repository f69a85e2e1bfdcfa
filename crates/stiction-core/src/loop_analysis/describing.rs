//! Describing functions of a sticky valve and the harmonic balance of a loop.
//!
//! A describing function `N(a)` is the complex gain of a non-linearity's fundamental for a
//! sinusoidal input of amplitude `a` (Gelb and Vander Velde 1968). A loop `L` closed around it can
//! sustain a limit cycle of frequency ω and amplitude `a` where `L(jω) N(a) = -1`: the Nyquist curve
//! of `L` meets the locus of `-1 / N(a)`. The valve models here have one scale, the band: `N`
//! depends on `a / band` only, so the locus is fixed and the crossing gives the cycle's period
//! (which the band does not change) and `a / band` (so the amplitude grows in proportion to the
//! band). Read the other way, an observed amplitude gives the band, with no single stick to
//! resolve.
//!
//! - [`kano`]: the closed form for Kano et al.'s (2004) valve with band S (deadband + stickband)
//!   and slip jump J in continuous time; J = 0 is a backlash of width S, J = S the valve of
//!   Stenman et al. (2003) when OP moves faster than the band per sample. Choudhury, Thornhill and
//!   Shah (2005), "Modelling valve stiction", Control Engineering Practice 13, 641-658, give the
//!   describing function of this two-parameter valve; it is derived again in the code's comments.
//! - [`sampled`]: any valve model of [`crate::models`] run on a sampled sinusoid, as the loop runs
//!   it (Stenman's valve in discrete time sticks mid-stroke when OP moves less than the band per
//!   sample, which no continuous-time formula captures).
//! - [`harmonic_balance`]: the crossings of a loop's Nyquist curve with a valve's locus.

use super::cycle::fundamental_from_table;
use super::Complex64;
use crate::models::{Model, ModelKind, Stenman};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Kano's valve, continuous time: the describing function for an OP sinusoid of amplitude `a`
/// around a valve with band `s` and slip jump `j` (0 <= j <= s; OP units). Zero when `a <= s / 2`
/// (the valve never slips).
///
/// In steady state, on OP = a sin θ, the valve moves at OP - h·sign(dOP/dt) (h = (S - J) / 2),
/// sticks at a - h where OP turns at θ = π/2, and slips (by J) when OP has come back by S, at
/// θ = π - β with sin β = 1 - S / a; the other half is the mirror image. The fundamental's
/// coefficients over a half period are then
///
///   b1 = (2/π) [(a - 2h) cos β + a (π/4 + β/2) - a sin 2β / 4],
///   a1 = (2/π) [(a - 2h) sin β - a + (a/2) cos² β],
///
/// and `N = (b1 + j a1) / a`. For J = 0 this is the textbook backlash of width S.
pub fn kano(a: f64, s: f64, j: f64) -> Complex64 {
    if !(a > 0.5 * s) || a <= 0.0 {
        return Complex64::new(0.0, 0.0);
    }
    let h = 0.5 * (s - j.clamp(0.0, s));
    let beta = (1.0 - s / a).clamp(-1.0, 1.0).asin();
    let (sb, cb) = beta.sin_cos();
    let b1 = 2.0 / PI
        * ((a - 2.0 * h) * cb + a * (PI / 4.0 + beta / 2.0) - a * (2.0 * beta).sin() / 4.0);
    let a1 = 2.0 / PI * ((a - 2.0 * h) * sb - a + 0.5 * a * cb * cb);
    Complex64::new(b1, a1) / a
}

/// Periods simulated before the fundamental is measured (the valve settles into its cycle).
const SETTLE_PERIODS: usize = 2;
/// Periods measured.
const MEASURED_PERIODS: usize = 6;

/// The describing function of `model` for an OP sinusoid of amplitude `a` (OP units, at most 40)
/// sampled `samples_per_period` times a period: the valve runs on `50 + a cos(θ k + φ)` from rest
/// at the first sample (OP at its peak), and the fundamental of its position is measured over
/// whole periods once it has settled, averaged over four phases φ of the samples when a period
/// has fewer than 50 samples.
pub fn sampled(model: &Model, a: f64, samples_per_period: f64) -> Complex64 {
    Sinusoids::new(samples_per_period).describing(model, a)
}

/// The sinusoids a sampled describing function runs on, for one number of samples a period,
/// computed once for every amplitude and valve (the results are bit for bit those of computing
/// them each time).
struct Sinusoids {
    n_settle: usize,
    /// For each phase φ of the samples, `cos(θ k + φ)` over the whole run.
    cosines: Vec<Vec<f64>>,
    /// `(sin θk, cos θk)` over the measured periods.
    trig: Vec<(f64, f64)>,
}

impl Sinusoids {
    fn new(samples_per_period: f64) -> Self {
        let theta = 2.0 * PI / samples_per_period.max(2.0);
        let n_settle = (SETTLE_PERIODS as f64 * samples_per_period).ceil() as usize;
        let n = n_settle + (MEASURED_PERIODS as f64 * samples_per_period).round() as usize;
        // where the samples fall on the sinusoid matters only when a period has few of them
        let phases = if samples_per_period < 50.0 { 4 } else { 1 };
        let cosines = (0..phases)
            .map(|q| {
                let phi = q as f64 * theta / phases as f64;
                (0..n).map(|k| (theta * k as f64 + phi).cos()).collect()
            })
            .collect();
        let trig = (0..n - n_settle.min(n))
            .map(|k| (theta * k as f64).sin_cos())
            .collect();
        Self {
            n_settle,
            cosines,
            trig,
        }
    }

    /// The describing function of `model` at OP amplitude `a`, averaged over the phases.
    fn describing(&self, model: &Model, a: f64) -> Complex64 {
        let n = self.cosines[0].len();
        let mut op = vec![0.0; n];
        let mut mv = vec![0.0; n];
        let mut total = Complex64::new(0.0, 0.0);
        for cosine in &self.cosines {
            for (u, c) in op.iter_mut().zip(cosine) {
                *u = 50.0 + a * c;
            }
            model.simulate_into(&op, &mut mv);
            let x = fundamental_from_table(&mv[self.n_settle..], &self.trig);
            let u = fundamental_from_table(&op[self.n_settle..], &self.trig);
            total += x / u;
        }
        total / self.cosines.len() as f64
    }
}

/// Points of the amplitude-over-band grid of a locus, and its ends.
const LOCUS_POINTS: usize = 48;
const LOCUS_FIRST: f64 = 0.52;
const LOCUS_LAST: f64 = 40.0;
/// Kano's slip ratios J / S whose loci span the valves between a backlash and a stick-jump.
const SLIP_RATIOS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// A valve's describing function along a grid of amplitude over band.
#[derive(Debug, Clone, PartialEq)]
pub struct ValveLocus {
    /// The valve model (Kano or Stenman).
    pub kind: ModelKind,
    /// Kano's J / S (1 for Stenman).
    pub slip_ratio: f64,
    /// `(a / band, N)`, in order of `a / band`.
    pub points: Vec<(f64, Complex64)>,
}

fn ratio_grid() -> impl Iterator<Item = f64> {
    (0..LOCUS_POINTS).map(|i| {
        LOCUS_FIRST * (LOCUS_LAST / LOCUS_FIRST).powf(i as f64 / (LOCUS_POINTS - 1) as f64)
    })
}

/// The describing functions of the valves a band can be: Kano's (closed form) for each of
/// `SLIP_RATIOS`, and Stenman's sampled `samples_per_period` times a period (its staircase).
pub fn valve_loci(samples_per_period: f64) -> Vec<ValveLocus> {
    let mut out: Vec<ValveLocus> = SLIP_RATIOS
        .iter()
        .map(|&q| ValveLocus {
            kind: ModelKind::Kano,
            slip_ratio: q,
            points: ratio_grid().map(|r| (r, kano(r, 1.0, q))).collect(),
        })
        .collect();
    let stenman = Model::Stenman(Stenman { d: 1.0 });
    let sinusoids = Sinusoids::new(samples_per_period);
    out.push(ValveLocus {
        kind: ModelKind::Stenman,
        slip_ratio: 1.0,
        points: ratio_grid()
            .map(|r| (r, sinusoids.describing(&stenman, r)))
            .collect(),
    });
    out
}

/// The valve describing function nearest a target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nearest {
    /// The valve model (Kano or Stenman).
    pub kind: ModelKind,
    /// Kano's J / S (1 for Stenman).
    pub slip_ratio: f64,
    /// Amplitude over band there.
    pub ratio: f64,
    /// The describing function there (complex gain).
    pub n: Complex64,
    /// Distance from the target.
    pub distance: f64,
}

/// The point of the loci nearest `target` (segments between grid points, interpolated).
pub fn nearest(loci: &[ValveLocus], target: Complex64) -> Option<Nearest> {
    let mut best: Option<Nearest> = None;
    for l in loci {
        for w in l.points.windows(2) {
            let ((r0, n0), (r1, n1)) = (w[0], w[1]);
            let seg = n1 - n0;
            let len2 = seg.norm_sqr();
            let t = if len2 > 0.0 {
                (((target - n0) * seg.conj()).re / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let n = n0 + seg * t;
            let distance = (target - n).norm();
            if best.is_none_or(|b| distance < b.distance) {
                best = Some(Nearest {
                    kind: l.kind,
                    slip_ratio: l.slip_ratio,
                    ratio: r0 + t * (r1 - r0),
                    n,
                    distance,
                });
            }
        }
    }
    best
}

/// One crossing of a loop's Nyquist curve with a valve's locus `-1 / N`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Balance {
    /// Frequency of the cycle, radians per sample.
    pub theta: f64,
    /// The cycle's amplitude at the valve's input over the band (`a / band`).
    pub ratio: f64,
}

/// The crossings of the Nyquist curve `curve` (points `(theta, L)`, in order of frequency) with
/// the locus `-1 / N(r)` of a valve, given as points `(r, N(r))` in order of `r` = amplitude over
/// band. Each crossing interpolates `theta` and `r` linearly along both segments.
pub fn harmonic_balance(curve: &[(f64, Complex64)], df: &[(f64, Complex64)]) -> Vec<Balance> {
    let locus: Vec<(f64, Complex64)> = df
        .iter()
        .filter(|(_, n)| n.norm() > 1e-9)
        .map(|&(r, n)| (r, -1.0 / n))
        .collect();
    let mut out = Vec::new();
    for l in curve.windows(2) {
        for m in locus.windows(2) {
            if let Some((s, t)) = segments(l[0].1, l[1].1, m[0].1, m[1].1) {
                out.push(Balance {
                    theta: l[0].0 + s * (l[1].0 - l[0].0),
                    ratio: m[0].0 + t * (m[1].0 - m[0].0),
                });
            }
        }
    }
    out
}

/// Where segments p0-p1 and q0-q1 cross: the fractions along each.
fn segments(p0: Complex64, p1: Complex64, q0: Complex64, q1: Complex64) -> Option<(f64, f64)> {
    let (r, s) = (p1 - p0, q1 - q0);
    let cross = |u: Complex64, v: Complex64| u.re * v.im - u.im * v.re;
    let den = cross(r, s);
    if den.abs() < 1e-300 {
        return None;
    }
    let d = q0 - p0;
    let (t, u) = (cross(d, s) / den, cross(d, r) / den);
    ((0.0..=1.0).contains(&t) && (0.0..1.0).contains(&u)).then_some((t, u))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::loop_analysis::cycle::fundamental;
    use crate::models::Kano;

    /// Gelb and Vander Velde's backlash of half-width b.
    fn backlash(a: f64, b: f64) -> Complex64 {
        let x = 1.0 - 2.0 * b / a;
        let re = (PI / 2.0 + x.asin() + 2.0 * x * (b / a * (1.0 - b / a)).sqrt()) / PI;
        let im = -4.0 * b / (PI * a) * (1.0 - b / a);
        Complex64::new(re, im)
    }

    #[test]
    fn kano_without_slip_jump_is_the_textbook_backlash() {
        for a in [0.6, 1.0, 2.5, 10.0] {
            let n = kano(a, 1.0, 0.0);
            assert!((n - backlash(a, 0.5)).norm() < 1e-12, "a = {a}: {n}");
        }
        // a large sinusoid passes almost unchanged; a small one does not pass
        assert!((kano(1e4, 1.0, 0.5) - 1.0).norm() < 1e-3);
        assert_eq!(kano(0.4, 1.0, 1.0), Complex64::new(0.0, 0.0));
    }

    #[test]
    fn the_sampled_valve_agrees_with_the_closed_form() {
        // finely sampled, Kano's discrete valve is the continuous one
        for (a, s, j) in [(1.0, 1.0, 0.5), (3.0, 1.0, 1.0), (2.0, 1.5, 0.0)] {
            let n = sampled(&Model::Kano(Kano::new(s, j).unwrap()), a, 4000.0);
            let c = kano(a, s, j);
            assert!((n - c).norm() < 0.01, "a {a} S {s} J {j}: {n} vs {c}");
        }
    }

    #[test]
    fn a_relay_has_gain_four_over_pi_a() {
        // the fundamental of a square wave of height 1 on a sinusoid of amplitude a
        for a in [0.5, 2.0, 7.0] {
            let n = 1000;
            let theta = 2.0 * PI / 100.0;
            let u: Vec<f64> = (0..n).map(|k| a * (theta * k as f64).sin()).collect();
            let y: Vec<f64> = u.iter().map(|v| v.signum()).collect();
            let g = fundamental(&y, theta) / fundamental(&u, theta);
            assert!(
                (g.norm() - 4.0 / (PI * a)).abs() < 2e-3 * 4.0 / (PI * a),
                "{g}"
            );
            assert!(g.arg().abs() < 0.05);
        }
    }

    #[test]
    fn stenmans_valve_sampled_slowly_lags_by_its_staircase() {
        // OP moves a tenth of the band per sample: the valve climbs a staircase of steps d that
        // lags OP by d / 2 on average, a lag of about 2 d / (π a) radians
        let a = 10.0;
        let n = sampled(&Model::Stenman(Stenman { d: 1.0 }), a, 2.0 * PI * a / 0.1);
        assert!((n.norm() - 1.0).abs() < 0.02, "{n}");
        assert!((-n.arg() - 2.0 / (PI * a)).abs() < 0.01, "{n}");
    }

    #[test]
    fn the_balance_finds_a_crossing() {
        // a straight Nyquist segment through -0.5 - 0.5j, and the locus of a gain N = 1 / r e^{-jπ/4}
        let curve = [
            (0.1, Complex64::new(-1.0, 0.0)),
            (0.2, Complex64::new(0.0, -1.0)),
        ];
        let df: Vec<(f64, Complex64)> = (1..=20)
            .map(|i| {
                let r = i as f64 * 0.1;
                (r, Complex64::from_polar(1.0 / r, -PI / 4.0))
            })
            .collect();
        let b = harmonic_balance(&curve, &df);
        assert_eq!(b.len(), 1);
        // -1/N = -r e^{jπ/4}... meets the segment where it is at distance sqrt(0.5)
        assert!((b[0].theta - 0.15).abs() < 1e-9, "{b:?}");
    }
}
