//! Unit tests of the spectral tools.

use super::ellipse::distance_to_ellipse;
use super::*;

#[test]
fn harmonic_distortion_of_sine_triangle_and_square() {
    let period = 50.0;
    let f0 = 1.0 / period;
    let n = 2000;
    let phase = |i: usize| (i as f64 / period).fract();
    let sine: Vec<f64> = (0..n).map(|i| (TAU * i as f64 / period).sin()).collect();
    let triangle: Vec<f64> = (0..n)
        .map(|i| {
            let p = phase(i);
            if p < 0.5 {
                4.0 * p - 1.0
            } else {
                3.0 - 4.0 * p
            }
        })
        .collect();
    let square: Vec<f64> = (0..n)
        .map(|i| if phase(i) < 0.5 { 1.0 } else { -1.0 })
        .collect();
    let hs = harmonic_distortion(&sine, f0, 5).unwrap();
    let ht = harmonic_distortion(&triangle, f0, 5).unwrap();
    let hq = harmonic_distortion(&square, f0, 5).unwrap();
    assert!(hs < 1e-6, "sine {hs}");
    assert!(
        (ht - (1.0 / 81.0 + 1.0 / 625.0)).abs() < 0.002,
        "triangle {ht}"
    );
    assert!((hq - (1.0 / 9.0 + 1.0 / 25.0)).abs() < 0.01, "square {hq}");
    // white measurement noise on a sinusoid is not harmonics
    let mut state = 3u64;
    let noisy: Vec<f64> = sine
        .iter()
        .map(|v| {
            let mut g = 0.0;
            for _ in 0..12 {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                g += (state >> 11) as f64 / (1u64 << 53) as f64;
            }
            v + 0.3 * (g - 6.0)
        })
        .collect();
    let hn = harmonic_distortion(&noisy, f0, 5).unwrap();
    assert!(hn < 0.01, "noisy sine {hn}");
    // fewer than two periods, or harmonics beyond the Nyquist frequency: no answer
    assert!(harmonic_distortion(&sine, 1.0 / 8.0, 5).is_none());
    assert!(harmonic_distortion(&sine, 1.0 / 12.0, 5).is_some());
    assert!(harmonic_distortion(&sine[..80], f0, 5).is_none());
}
use crate::models::{Model, Stenman};
use crate::rng::{gaussian, seeded};
use crate::sim::{ClosedLoop, LoopData, Signal};

fn white(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = seeded(seed);
    (0..n).map(|_| gaussian(&mut rng)).collect()
}

fn direct_autocorrelation(x: &[f64], max_lag: usize) -> Vec<f64> {
    let m = mean(x);
    let c: Vec<f64> = x.iter().map(|v| v - m).collect();
    let var: f64 = c.iter().map(|v| v * v).sum();
    (0..=max_lag.min(x.len() - 1))
        .map(|k| (0..x.len() - k).map(|t| c[t] * c[t + k]).sum::<f64>() / var)
        .collect()
}

fn direct_cross_correlation(a: &[f64], b: &[f64], max_lag: usize) -> Vec<f64> {
    let n = a.len();
    let (ma, mb) = (mean(a), mean(b));
    let ca: Vec<f64> = a.iter().map(|v| v - ma).collect();
    let cb: Vec<f64> = b.iter().map(|v| v - mb).collect();
    let norm =
        (ca.iter().map(|v| v * v).sum::<f64>() * cb.iter().map(|v| v * v).sum::<f64>()).sqrt();
    let lags = max_lag.min(n - 1) as i64;
    (-lags..=lags)
        .map(|k| {
            (0..n as i64)
                .filter(|&t| t + k >= 0 && t + k < n as i64)
                .map(|t| ca[t as usize] * cb[(t + k) as usize])
                .sum::<f64>()
                / norm
        })
        .collect()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// The plans kept between transforms change no result: a thread that has transformed many other
/// sizes (more than it keeps) gives the same spectrum and autocorrelation, bit for bit, as a
/// fresh thread (a planner shared between sizes would round some sizes differently).
#[test]
fn kept_plans_change_no_result() {
    let x: Vec<f64> = white(3000, 9).iter().map(|v| 1.0 + v).collect();
    fn judge(x: &[f64]) -> Vec<Vec<f64>> {
        let mut out: Vec<Vec<f64>> = [210, 330, 462, 1155]
            .iter()
            .map(|&m| welch_psd(x, m))
            .collect();
        out.push(autocorrelation(x, 700));
        out
    }
    let fresh = std::thread::spawn({
        let x = x.clone();
        move || judge(&x)
    })
    .join()
    .unwrap();
    for n in (40..240).step_by(7) {
        let _ = welch_psd(&white(4 * n, 1), n);
        let _ = autocorrelation(&white(n, n as u64), n / 2);
    }
    let again = judge(&x);
    let bits = |r: &[Vec<f64>]| -> Vec<u64> { r.iter().flatten().map(|v| v.to_bits()).collect() };
    assert_eq!(bits(&fresh), bits(&again));
}

#[test]
fn autocorrelation_equals_the_direct_sum() {
    for (n, lag, seed) in [(500, 60, 1), (333, 400, 2), (7, 3, 3), (2, 5, 4), (1, 0, 5)] {
        let x: Vec<f64> = white(n, seed).iter().map(|v| 3.0 + 2.0 * v).collect();
        let r = autocorrelation(&x, lag);
        assert_eq!(r.len(), lag.min(n - 1) + 1);
        if n > 1 {
            assert!(max_diff(&r, &direct_autocorrelation(&x, lag)) < 1e-12);
            assert_eq!(r[0], 1.0);
        }
    }
    assert_eq!(autocorrelation(&[2.5; 50], 10), vec![0.0; 11]);
    assert!(autocorrelation(&[], 10).is_empty());
}

#[test]
fn cross_correlation_equals_the_direct_sum_and_its_lag_convention() {
    for (n, lag) in [(400, 50), (37, 100), (2, 1)] {
        let a = white(n, 10);
        let b: Vec<f64> = white(n, 11).iter().map(|v| 1.0 - 0.5 * v).collect();
        let r = cross_correlation(&a, &b, lag);
        assert_eq!(r.len(), 2 * lag.min(n - 1) + 1);
        assert!(max_diff(&r, &direct_cross_correlation(&a, &b, lag)) < 1e-12);
    }
    // b follows a by 5 samples: the peak is at lag +5
    let a = white(300, 12);
    let b: Vec<f64> = (0..300)
        .map(|t| if t >= 5 { a[t - 5] } else { 0.0 })
        .collect();
    let r = cross_correlation(&a, &b, 20);
    let best = (0..r.len()).max_by(|&i, &j| r[i].total_cmp(&r[j])).unwrap();
    assert_eq!(best, 20 + 5);
    assert_eq!(cross_correlation(&a, &[1.0; 300], 3), vec![0.0; 7]);
    assert!(cross_correlation(&a, &[], 3).is_empty());
}

/// Amplitude and phase of the sine at frequency `f` (cycles per sample) in `x`, by projection.
fn sine_component(x: &[f64], f: f64) -> (f64, f64) {
    let (c, s) = x.iter().enumerate().fold((0.0, 0.0), |(c, s), (t, v)| {
        let w = TAU * f * t as f64;
        (c + v * w.cos(), s + v * w.sin())
    });
    let n = x.len() as f64;
    (2.0 * c.hypot(s) / n, c.atan2(s))
}

#[test]
fn band_pass_keeps_the_band_and_removes_the_rest() {
    for (n, phase) in [(1000, 0.3), (1003, 1.2), (517, 2.0)] {
        let slow: Vec<f64> = (0..n)
            .map(|t| (TAU * 0.02 * t as f64 + phase).sin())
            .collect();
        let x: Vec<f64> = (0..n)
            .map(|t| 5.0 + slow[t] + 0.7 * (TAU * 0.2 * t as f64).sin())
            .collect();
        let y = band_pass(&x, 0.01, 0.05);
        assert_eq!(y.len(), n);
        // the slow sine survives with its amplitude and phase...
        let inner = n / 10..n - n / 10;
        let (amp, ph) = sine_component(&y[inner.clone()], 0.02);
        let (_, ph0) = sine_component(&slow[inner.clone()], 0.02);
        assert!((amp - 1.0).abs() < 0.03, "n {n}: amplitude {amp}");
        assert!(
            (ph - ph0).abs() < 0.02,
            "n {n}: phase {ph} instead of {ph0}"
        );
        // ...to within the ringing a brick-wall filter has near the ends
        let err = max_diff(&y[inner.clone()], &slow[inner]);
        assert!(err < 0.1, "n {n}: error {err}");
        // and nothing is left of the fast one
        assert!(sine_component(&y, 0.2).0 < 0.01);
    }
    assert!(band_pass(&[], 0.1, 0.2).is_empty());
    assert_eq!(band_pass(&[3.0], 0.1, 0.2), vec![0.0]);
    assert_eq!(band_pass(&[1.0, 2.0, 3.0, 4.0], 0.3, 0.1), vec![0.0; 4]);
    assert_eq!(band_pass(&[1.0, 2.0, 3.0], f64::NAN, 0.1), vec![0.0; 3]);
}

#[test]
fn white_noise_is_not_non_linear() {
    let s = BicoherenceSettings::default();
    let flagged = (0..20)
        .filter(|&seed| bicoherence(&white(4096, seed), &s).unwrap().non_linear)
        .count();
    assert!(
        flagged <= 2,
        "{flagged} of 20 white-noise records flagged non-linear"
    );
}

#[test]
fn quadratic_phase_coupling_is_non_linear() {
    let s = BicoherenceSettings::default();
    let noise = white(4096, 7);
    let x: Vec<f64> = (0..4096)
        .map(|t| {
            let t = t as f64;
            let v = (TAU * 0.06 * t).sin() + 0.8 * (TAU * 0.11 * t + 1.0).sin();
            v + 0.5 * v * v + 0.1 * noise[t as usize]
        })
        .collect();
    let b = bicoherence(&x, &s).unwrap();
    assert!(b.non_gaussian && b.non_linear, "{b:?}");
    assert!(b.peak_value > 0.9, "{b:?}");
    assert_eq!((b.segments, b.segment_length), (63, 128));
}

fn sticky_loop(d: f64, disturbance: Option<Signal>, seed: u64) -> LoopData {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman::new(d).unwrap()));
    cl.samples = 4096;
    cl.noise = 0.1;
    cl.seed = seed;
    cl.disturbance = disturbance;
    cl.run().unwrap()
}

fn control_error(data: &LoopData) -> Vec<f64> {
    // drop the start-up (the setpoint step at 10 s)
    data.sp
        .iter()
        .zip(&data.pv)
        .skip(200)
        .map(|(sp, pv)| sp - pv)
        .collect()
}

#[test]
fn a_sticky_valve_limit_cycle_is_non_linear() {
    let s = BicoherenceSettings::default();
    for seed in 0..3 {
        let b = bicoherence(&control_error(&sticky_loop(2.0, None, seed)), &s).unwrap();
        assert!(b.non_linear, "seed {seed}: {b:?}");
    }
}

#[test]
fn a_linear_loop_with_a_sinusoidal_disturbance_is_not() {
    let s = BicoherenceSettings::default();
    for (seed, period) in [(0, 50.0), (1, 100.0), (2, 37.0)] {
        let sine = Signal::Sine {
            amplitude: 1.0,
            period,
            offset: 0.0,
        };
        let b = bicoherence(&control_error(&sticky_loop(0.0, Some(sine), seed)), &s).unwrap();
        assert!(!b.non_linear, "seed {seed}, period {period}: {b:?}");
    }
}

#[test]
fn bicoherence_degrades_gracefully_on_short_or_flat_records() {
    let s = BicoherenceSettings::default();
    // too short for 4 segments of 128 but enough for 64
    let b = bicoherence(&white(300, 1), &s).unwrap();
    assert_eq!((b.segment_length, b.segments), (64, 8));
    assert!(bicoherence(&white(150, 1), &s).is_none());
    assert!(bicoherence(&[], &s).is_none());
    assert!(bicoherence(&[4.2; 4096], &s).is_none());
    let mut x = white(4096, 2);
    x[100] = f64::NAN;
    assert!(bicoherence(&x, &s).is_none());
    let odd = BicoherenceSettings {
        segment_length: 8,
        ..s
    };
    assert!(bicoherence(&white(4096, 3), &odd).is_none());
    let odd = BicoherenceSettings {
        overlap: f64::NAN,
        ..s
    };
    assert_eq!(bicoherence(&white(4096, 3), &odd).unwrap().segments, 32);
}

fn ellipse_points(n: usize, noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let (a, b, alpha) = (5.0, 2.0, 0.5f64);
    let mut rng = seeded(seed);
    (0..n)
        .map(|i| {
            let t = TAU * i as f64 / n as f64;
            let (u, v) = (a * t.cos(), b * t.sin());
            (
                50.0 + u * alpha.cos() - v * alpha.sin() + noise * gaussian(&mut rng),
                20.0 + u * alpha.sin() + v * alpha.cos() + noise * gaussian(&mut rng),
            )
        })
        .unzip()
}

#[test]
fn ellipse_fit_recovers_a_rotated_ellipse() {
    let (a, b, alpha) = (5.0f64, 2.0f64, 0.5f64);
    let width = 2.0 * a * b / (a * a * alpha.sin().powi(2) + b * b * alpha.cos().powi(2)).sqrt();
    for (noise, tol) in [(0.0, 1e-9), (0.02, 0.01)] {
        let (x, y) = ellipse_points(400, noise, 3);
        let e = fit_ellipse(&x, &y).unwrap();
        let rel = |got: f64, want: f64| ((got - want) / want).abs();
        assert!(
            rel(e.centre[0], 50.0) < tol && rel(e.centre[1], 20.0) < tol,
            "{e:?}"
        );
        assert!(
            rel(e.semi_major, a) < tol && rel(e.semi_minor, b) < tol,
            "{e:?}"
        );
        assert!(rel(e.angle, alpha) < tol, "{e:?}");
        assert!(rel(e.width_along_x, width) < tol, "{e:?}");
        assert!(e.rms_residual < 2.0 * noise + 1e-9, "{e:?}");
    }
    // the same ellipse turned by -0.5 rad: the angle keeps its sign
    let (x, y) = ellipse_points(200, 0.0, 4);
    let y: Vec<f64> = y.iter().map(|v| 40.0 - v).collect();
    let e = fit_ellipse(&x, &y).unwrap();
    assert!((e.angle + alpha).abs() < 1e-9, "{e:?}");
}

#[test]
fn distance_to_an_ellipse() {
    // brute force over a fine parametrisation
    let (a, b) = (5.0, 2.0);
    for (p0, p1) in [
        (0.0, 0.0),
        (6.0, 0.0),
        (1.0, 0.0),
        (0.0, -3.0),
        (3.0, 1.0),
        (-4.0, 2.5),
        (0.3, 0.1),
    ] {
        let brute = (0..200_000)
            .map(|i| {
                let t = TAU * i as f64 / 200_000.0;
                (a * t.cos() - p0).hypot(b * t.sin() - p1)
            })
            .fold(f64::INFINITY, f64::min);
        let d = distance_to_ellipse(a, b, p0, p1);
        assert!((d - brute).abs() < 1e-6, "({p0}, {p1}): {d} vs {brute}");
    }
}

#[test]
fn ellipse_fit_rejects_degenerate_data() {
    let x: Vec<f64> = (0..50).map(|i| i as f64).collect();
    let line: Vec<f64> = x.iter().map(|v| 2.0 * v + 1.0).collect();
    assert!(fit_ellipse(&x, &line).is_none());
    // a noisy line: no ellipse, or a very thin one
    let noisy: Vec<f64> = line
        .iter()
        .zip(white(50, 5))
        .map(|(v, n)| v + 0.01 * n)
        .collect();
    if let Some(e) = fit_ellipse(&x, &noisy) {
        assert!(e.semi_minor < 0.01 * e.semi_major, "{e:?}");
    }
    assert!(fit_ellipse(&x, &[3.0; 50]).is_none());
    assert!(fit_ellipse(&[1.0, 2.0, 3.0], &[1.0, 0.0, 1.0]).is_none());
    assert!(fit_ellipse(&[], &[]).is_none());
    let (mut ex, ey) = ellipse_points(100, 0.0, 6);
    ex[3] = f64::INFINITY;
    assert!(fit_ellipse(&ex, &ey).is_none());
}

#[test]
fn apparent_stiction_of_a_sticky_loop() {
    let data = sticky_loop(2.0, None, 1);
    let (op, pv) = (&data.op[200..], &data.pv[200..]);
    let period = crate::detect::regularity(&control_error(&data), 1.0)
        .period
        .unwrap();
    let f = 1.0 / period;
    let e = apparent_stiction_ellipse(op, pv, 0.5 * f, 1.5 * f).unwrap();
    // the apparent stiction is of the order of d (2.1-2.2 here for d = 2)
    assert!(e.width_along_x > 1.0 && e.width_along_x < 4.0, "{e:?}");
}
