//! The oscillation's reading: holds of the setpoint, cycles across its steps, weak and wandering
//! cycles.

use super::*;

#[test]
fn the_longest_constant_setpoint_stretch() {
    let mut sp = vec![1.0; 100];
    sp[30..].fill(2.0);
    sp[40..].fill(3.0);
    assert_eq!(constant_setpoint(Some(&sp), (0, 100)), (40, 100));
    assert_eq!(constant_setpoint(Some(&sp), (0, 35)), (0, 30));
    assert_eq!(constant_setpoint(None, (5, 9)), (5, 9));
}

/// A valve that sticks through one hold of the setpoint while the load drifts, then cycles
/// through the next: the cycle is judged on that hold, not missed on the longest one.
#[test]
fn a_cycle_in_a_shorter_hold_of_the_setpoint_counts() {
    let noise = sine_in_noise(2000, 40.0, 0.1);
    let record = |cycle_from: usize| -> (Vec<f64>, Vec<f64>) {
        let error = (0..2000)
            .map(|k| {
                if k < cycle_from {
                    // noise about a drift (the sine removed): no cycle
                    let sine = (std::f64::consts::TAU * k as f64 / 40.0).sin();
                    noise[k] - sine + 5.0 * k as f64 / cycle_from as f64
                } else {
                    noise[k]
                }
            })
            .collect();
        let sp = (0..2000)
            .map(|k| if k < cycle_from { 1.0 } else { 2.0 })
            .collect();
        (error, sp)
    };
    let (error, sp) = record(1400);
    let o = of_record(&error, Some(&sp), 1.0);
    assert!(o.oscillating);
    assert_eq!(o.stretch, [1400, 2000]);
    assert!(!o.across_setpoint_steps);
    assert!((o.period.unwrap() - 40.0).abs() < 2.0, "{:?}", o.period);
    // a hold of under a fifth of the record is not searched
    let (error, sp) = record(1700);
    let o = of_record(&error, Some(&sp), 1.0);
    assert_eq!(o.stretch, [0, 1700]);
    assert!(!o.oscillating);
}

/// A sine of `period` samples and unit amplitude in white noise of standard deviation `sigma`.
fn sine_in_noise(n: usize, period: f64, sigma: f64) -> Vec<f64> {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
    (0..n)
        .map(|k| {
            let u: f64 = rng.random::<f64>() - 0.5;
            (std::f64::consts::TAU * k as f64 / period).sin() + sigma * 12f64.sqrt() * u
        })
        .collect()
}

#[test]
fn the_cycle_share_of_a_sine_in_noise_is_its_share_of_the_variance() {
    // variance 0.5 of the sine beside 0.5 of the noise: half
    let x = sine_in_noise(4000, 40.0, 0.5f64.sqrt());
    let share = |x: &[f64]| cycle_share(&detect::autocorrelation(x, x.len() / 2), x.len(), 40.0);
    let c = share(&x).unwrap();
    assert!((c - 0.5).abs() < 0.05, "{c}");
    // a slow drift raises the period's lag and the half period's alike
    let drift: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(k, v)| v + 0.002 * k as f64)
        .collect();
    assert!(share(&drift).unwrap() < 0.6);
    assert!(share(&x[..60]).is_none());
}

#[test]
fn a_cycle_across_setpoint_steps_counts_unless_the_setpoint_moves_all_the_time() {
    // the setpoint steps every 60 samples: no hold has two whole cycles of 40 samples
    let n = 2000;
    let cycle = sine_in_noise(n, 40.0, 0.2);
    let steps: Vec<f64> = (0..n).map(|k| 50.0 + ((k / 60) % 3) as f64).collect();
    let o = of_record(&cycle, Some(&steps), 1.0);
    assert!(o.oscillating && o.across_setpoint_steps, "{o:?}");
    assert_eq!(o.stretch, [0, n]);
    assert!((o.period.unwrap() - 40.0).abs() < 2.0);
    // a setpoint that moves at every sample (a cascade's inner loop): the cycle may be its own
    let moving: Vec<f64> = (0..n).map(|k| 50.0 + 0.001 * k as f64).collect();
    let o = of_record(&cycle, Some(&moving), 1.0);
    assert!(!o.across_setpoint_steps, "{o:?}");
    // steps more often than the cycle: the train of their responses, not a cycle
    let fast: Vec<f64> = (0..n).map(|k| 50.0 + ((k / 30) % 2) as f64).collect();
    assert!(!setpoint_steps(Some(&fast), Some(50.0)));
    assert!(setpoint_steps(Some(&steps), Some(50.0)));
    assert!(!setpoint_steps(None, Some(50.0)));
}

/// A cycle of unit amplitude whose phase wanders (each sample's phase step off by up to
/// `wander` of its own, at random), in white noise of standard deviation `sigma`.
fn wandering_in_noise(n: usize, period: f64, sigma: f64, wander: f64) -> Vec<f64> {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(11);
    let mut phase = 0.0;
    (0..n)
        .map(|_| {
            let u: f64 = rng.random::<f64>() - 0.5;
            let e: f64 = rng.random::<f64>() - 0.5;
            phase += std::f64::consts::TAU / period * (1.0 + 2.0 * wander * u);
            phase.sin() + sigma * 12f64.sqrt() * e
        })
        .collect()
}

#[test]
fn a_weak_cycle_counts_when_it_keeps_no_clock() {
    let (n, sigma) = (2000, 0.4);
    let free = wandering_in_noise(n, 40.0, sigma, 1.5);
    let clock = sine_in_noise(n, 40.0, sigma);
    // both about 3 noise standard deviations: too small for Hägglund's count
    let o = oscillation(&free, 1.0, (0, n));
    assert!(o.iae.exceedances < 4, "{o:?}");
    // the free cycle's period wanders, and it repeats large areas at 1.5
    assert!(
        o.regularity.regularity < 10.0 && o.regularity.oscillating,
        "{o:?}"
    );
    assert!(o.oscillating && o.weak_cycle, "{o:?}");
    // the same cycle keeping a clock's time is an input's: not counted
    let o = oscillation(&clock, 1.0, (0, n));
    assert!(
        o.regularity.regularity > FORCED_REGULARITY && o.iae.exceedances < 4,
        "{o:?}"
    );
    assert!(!o.oscillating, "{o:?}");
    // noise alone is not a cycle
    let o = oscillation(&wandering_in_noise(n, 40.0, 3.0, 1.5), 1.0, (0, n));
    assert!(!o.oscillating, "{o:?}");
}

#[test]
fn noise_std_of_white_noise_and_a_step() {
    // alternating ±1 has first differences of 2: sigma = 2 / 0.6745 / sqrt 2
    let mut x: Vec<f64> = (0..200)
        .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
        .collect();
    let s = noise_std(&x);
    assert!((s - 2.0 / 0.6745 / std::f64::consts::SQRT_2).abs() < 1e-12);
    // a single large step barely moves it
    for v in &mut x[100..] {
        *v += 50.0;
    }
    assert!((noise_std(&x) - s).abs() < 1e-12);
}

/// A square wave of unit amplitude whose half periods last `half` samples, each off by up to
/// `wander` of it at random, in white noise of standard deviation `sigma` (a sticky valve's PV).
fn wandering_square(n: usize, half: f64, wander: f64, sigma: f64, seed: u64) -> Vec<f64> {
    use rand::{RngExt, SeedableRng};
    let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut out = Vec::with_capacity(n);
    let mut level = 1.0;
    while out.len() < n {
        let u: f64 = rng.random::<f64>() - 0.5;
        let len = (half * (1.0 + 2.0 * wander * u)).round() as usize;
        for _ in 0..len.max(1) {
            let e: f64 = rng.random::<f64>() - 0.5;
            out.push(level + sigma * 12f64.sqrt() * e);
        }
        level = -level;
    }
    out.truncate(n);
    out
}

/// Law: a stick-slip cycle whose half periods wander by up to 40 % in noise of 0.6 of its
/// amplitude: read plainly, the autocorrelation's scatter near zero breaks the periods up (1 of 6
/// records found); read through the noise band every one is found, and said so. The band finds no
/// cycle in white noise.
#[test]
fn a_wandering_cycle_is_found_through_the_autocorrelations_noise_band() {
    let n = 800;
    let mut plain_found = 0;
    for seed in 0..6 {
        let x = wandering_square(n, 50.0, 0.4, 0.6, seed);
        let plain = oscillation(&x, 1.0, (0, n));
        plain_found += usize::from(plain.oscillating);
        let o = of_record(&x, None, 1.0);
        assert!(o.oscillating, "seed {seed}: {o:?}");
        assert_eq!(o.through_noise_band, !plain.oscillating, "seed {seed}");
        let period = o.period.unwrap();
        assert!((80.0..120.0).contains(&period), "seed {seed}: {period}");
    }
    assert!(plain_found <= 1, "{plain_found}");
    for seed in 0..50 {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        let noise: Vec<f64> = (0..n).map(|_| rng.random::<f64>() - 0.5).collect();
        // (the plain reading's own verdict on noise is not this test's)
        let o = of_record(&noise, None, 1.0);
        assert!(
            !(o.oscillating && o.through_noise_band),
            "seed {seed}: {o:?}"
        );
    }
}

/// Law: where the autocorrelation crosses zero cleanly (a sinusoid without noise), the band
/// changes no crossing.
#[test]
fn a_clean_cycles_crossings_are_the_same_through_the_band() {
    let x: Vec<f64> = (0..1000)
        .map(|k| (std::f64::consts::TAU * k as f64 / 37.0).sin())
        .collect();
    let acf = detect::autocorrelation(&x, x.len() / 2);
    let plain = detect::regularity_of(&acf, 1.0);
    let banded = detect::regularity_banded(&acf, 1.0, CROSSING_BAND / (x.len() as f64).sqrt());
    assert_eq!(plain.zero_crossings, banded.zero_crossings);
    assert!((plain.period.unwrap() - banded.period.unwrap()).abs() < 1e-9);
}
