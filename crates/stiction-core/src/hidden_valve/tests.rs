use super::*;
use crate::models::{He, Model, Stenman};
use crate::sim::{ClosedLoop, Pi, Process};

fn model() -> LoopModel {
    LoopModel {
        gain: 1.2,
        tau: 8.0,
        delay: 2.0,
        valve_lag: 1.0,
        integrating: false,
        noise: 0.1,
        drift: 0.002,
        cycle: 0.01,
        cycle_radius: 0.95,
        cycle_angle: 0.3,
        input_noise: 0.0,
    }
}

/// A flow-like loop whose controller runs twice a sample: the record misses half of OP's moves.
fn record_of(d: f64, samples: usize) -> crate::sim::LoopData {
    record_with(Model::Stenman(Stenman { d }), samples)
}

/// The same loop with the valve `valve`.
fn record_with(valve: Model, samples: usize) -> crate::sim::LoopData {
    let mut cl = ClosedLoop::new(valve);
    cl.process = Process::Foptd {
        k: 1.0,
        tau: 8.0,
        delay: 1.0,
    };
    cl.pi = Pi { kc: 1.5, ti: 8.0 };
    cl.ts = 2.0;
    cl.controller_period = Some(1.0);
    cl.samples = samples;
    cl.noise = 0.2;
    cl.seed = 11;
    cl.op0 = 40.0;
    cl.run().unwrap()
}

/// The record of `data` (sampled every 2 s) with the valve's travel `limits`.
fn record(data: &crate::sim::LoopData, limits: Option<(f64, f64)>) -> Record<'_> {
    Record {
        op: &data.op,
        pv: &data.pv,
        ts: 2.0,
        limits,
    }
}

#[test]
fn a_valve_that_cannot_stick_has_the_healthy_likelihood() {
    // law: a band of nothing, OP recorded exactly: every particle's valve is OP, so the particle
    // filter is the Kalman filter
    let data = record_of(0.0, 300);
    let rec = record(&data, Some((0.0, 100.0)));
    let m = model();
    let healthy = healthy_log_likelihood(&rec, &m);
    let pf = Particles { count: 16, seed: 3 };
    let sticky = sticky_log_likelihood(&rec, &m, Slip::stenman(1e-12), &pf);
    assert!(healthy.is_finite());
    assert!(
        (healthy - sticky).abs() < 1e-6 * healthy.abs(),
        "{healthy} vs {sticky}"
    );
}

#[test]
fn the_same_seed_gives_the_same_likelihood() {
    let data = record_of(2.0, 300);
    let rec = record(&data, None);
    let m = LoopModel {
        input_noise: 0.3,
        ..model()
    };
    let pf = Particles { count: 32, seed: 9 };
    let a = sticky_log_likelihood(&rec, &m, Slip::stenman(2.0), &pf);
    let b = sticky_log_likelihood(&rec, &m, Slip::stenman(2.0), &pf);
    assert_eq!(a.to_bits(), b.to_bits());
}

/// The loop model a record of `record_of` was simulated with (valve lag aside), its noise and
/// OP's unrecorded moves as the search would read them.
fn true_model(data: &crate::sim::LoopData) -> LoopModel {
    let steps: Vec<f64> = data.op.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    let mean_step = steps.iter().sum::<f64>() / steps.len() as f64;
    LoopModel {
        gain: 1.0,
        tau: 8.0,
        delay: 1.0,
        valve_lag: 0.0,
        noise: 0.2,
        drift: 1e-3,
        cycle: 0.0,
        input_noise: 0.5 * mean_step,
        ..model()
    }
}

#[test]
fn at_the_true_loop_a_hidden_sticky_valve_explains_pv_and_a_healthy_one_is_not_mistaken_for_one() {
    let pf = Particles { count: 64, seed: 5 };
    let ratio = |d: f64, band: f64| {
        let data = record_of(d, 600);
        let rec = record(&data, Some((0.0, 100.0)));
        let m = true_model(&data);
        sticky_log_likelihood(&rec, &m, Slip::stenman(band), &pf) - healthy_log_likelihood(&rec, &m)
    };
    let sticky = ratio(3.0, 3.0);
    let healthy = ratio(0.0, 3.0);
    assert!(sticky > 30.0, "sticky valve, true band: {sticky}");
    assert!(
        healthy < -10.0,
        "healthy valve judged with a 3 % band: {healthy}"
    );
}

#[test]
fn the_search_finds_a_hidden_sticky_valve_and_no_band_in_a_healthy_one() {
    // the particle filter's draws move the greedy search's path: from the scan's best valve
    // alone the search stays at a small band near the healthy optimum on one seed of four
    // (ratio 1.5; the others 33 to 59); started from a band away too, it finds the band on
    // every seed, and the healthy record gives no band on any
    let (sticky_data, healthy_data) = (record_of(3.0, 800), record_of(0.0, 800));
    let found = |band_starts: usize| {
        (1..=4)
            .filter(|&seed| {
                let settings = TestSettings {
                    particles: Particles { count: 50, seed },
                    bands: 6,
                    band_starts,
                    ..TestSettings::default()
                };
                let healthy = test(&record(&healthy_data, Some((0.0, 100.0))), &settings).unwrap();
                assert!(healthy.ratio < 10.0, "healthy, seed {seed}: {healthy:?}");
                let sticky = test(&record(&sticky_data, Some((0.0, 100.0))), &settings).unwrap();
                sticky.ratio > 20.0 && sticky.band > 1.0 && sticky.band < 6.0
            })
            .count()
    };
    let (one, two) = (found(1), found(2));
    assert_eq!(two, 4, "started from two bands");
    assert!(
        one <= two,
        "the scan's best alone found it on {one} seeds, both on {two}"
    );
}

#[test]
fn a_valve_whose_slips_land_short_of_op_is_heard_as_one() {
    // He's valve (fs = 3, fd = 1.8): each slip lands 1.8 short of OP. At the true loop the
    // hidden valve that lands as short explains PV better than Stenman's, which lands on OP
    let data = record_with(Model::He(He { fs: 3.0, fd: 1.8 }), 600);
    let rec = record(&data, Some((0.0, 100.0)));
    let m = true_model(&data);
    let pf = Particles { count: 64, seed: 5 };
    let short = sticky_log_likelihood(
        &rec,
        &m,
        Slip {
            band: 3.0,
            short: 1.8,
        },
        &pf,
    );
    let on_op = sticky_log_likelihood(&rec, &m, Slip::stenman(3.0), &pf);
    let healthy = healthy_log_likelihood(&rec, &m);
    assert!(short - healthy > 30.0, "{short} against healthy {healthy}");
    assert!(short - on_op > 100.0, "{short} against Stenman's {on_op}");
}

#[test]
fn the_search_gives_the_same_result_on_any_number_of_threads() {
    let settings = TestSettings {
        particles: Particles { count: 16, seed: 1 },
        bands: 4,
        short_shares: &[0.0, 0.5],
        ..TestSettings::default()
    };
    let data = record_of(3.0, 300);
    let rec = record(&data, Some((0.0, 100.0)));
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| test(&rec, &settings).unwrap())
    };
    assert_eq!(on(1), on(3));
}
