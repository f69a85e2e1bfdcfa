//! Loop simulation: signals, the closed PI loop with an ideal and a sticky valve.

use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{simulate_open_loop, ClosedLoop, Process, Signal};

fn std_dev(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
}

#[test]
fn signals_have_their_shape() {
    let sine = Signal::Sine {
        amplitude: 2.0,
        period: 10.0,
        offset: 1.0,
    }
    .generate(0.1, 101);
    assert!((sine[25] - 3.0).abs() < 1e-12 && (sine[75] + 1.0).abs() < 1e-12);
    let tri = Signal::Triangle {
        amplitude: 1.0,
        period: 4.0,
        offset: 0.0,
    }
    .generate(1.0, 5);
    assert_eq!(tri, [0.0, 1.0, 0.0, -1.0, 0.0]);
    let step = Signal::Step {
        from: 1.0,
        to: 2.0,
        at: 2.0,
    }
    .generate(1.0, 4);
    assert_eq!(step, [1.0, 1.0, 2.0, 2.0]);
    let a = Signal::RandomWalk {
        step_std: 0.1,
        offset: 0.0,
        seed: 9,
    }
    .generate(1.0, 500);
    let b = Signal::RandomWalk {
        step_std: 0.1,
        offset: 0.0,
        seed: 9,
    }
    .generate(1.0, 500);
    assert_eq!(a, b);
    let steps: Vec<f64> = a.windows(2).map(|w| w[1] - w[0]).collect();
    assert!((std_dev(&steps) - 0.1).abs() < 0.015);
    let levels = Signal::Steps {
        amplitude: 5.0,
        hold: 10.0,
        offset: 50.0,
        seed: 1,
    }
    .generate(1.0, 100);
    assert!(levels.iter().all(|v| (45.0..=55.0).contains(v)));
    assert_eq!(levels[0], levels[9]);
}

#[test]
fn open_loop_noise_is_seeded_and_sized() {
    let valve = Model::Stenman(Stenman { d: 0.5 });
    let s = Signal::Sine {
        amplitude: 1.0,
        period: 10.0,
        offset: 0.0,
    };
    let clean = simulate_open_loop(&valve, &s, 0.1, 5000, 0.0, 1).unwrap();
    let noisy = simulate_open_loop(&valve, &s, 0.1, 5000, 0.05, 1).unwrap();
    let again = simulate_open_loop(&valve, &s, 0.1, 5000, 0.05, 1).unwrap();
    assert_eq!(noisy, again);
    let diff: Vec<f64> = noisy.mv.iter().zip(&clean.mv).map(|(a, b)| a - b).collect();
    assert!((std_dev(&diff) - 0.05).abs() < 0.005);
    assert!(noisy.sp.is_empty() && noisy.pv.is_empty());
}

#[test]
fn an_ideal_valve_settles_at_the_setpoint() {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 0.0 }));
    cl.samples = 600;
    let d = cl.run().unwrap();
    let last = &d.pv[500..];
    assert!(
        last.iter().all(|pv| (pv - 51.0).abs() < 0.01),
        "pv ends at {:?}",
        &last[..3]
    );
    assert!(std_dev(&d.op[500..]) < 1e-3);
}

#[test]
fn a_sticky_valve_makes_the_loop_cycle() {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 0.5 }));
    cl.samples = 2000;
    cl.noise = 0.05;
    cl.seed = 7;
    let d = cl.run().unwrap();
    // a sustained oscillation: the PV keeps moving in the second half, the valve keeps jumping
    assert!(
        std_dev(&d.pv[1000..]) > 0.2,
        "pv std {}",
        std_dev(&d.pv[1000..])
    );
    let jumps = d.mv[1000..].windows(2).filter(|w| w[1] != w[0]).count();
    assert!((10..900).contains(&jumps), "{jumps} valve moves");
    // the valve only moves to the command
    for t in 1..d.mv.len() {
        assert!(d.mv[t] == d.mv[t - 1] || d.mv[t] == d.op[t]);
    }
}

#[test]
fn integrating_process_and_disturbance_run() {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 0.3 }));
    cl.process = Process::Integrating {
        k: 0.02,
        delay: 2.0,
    };
    cl.pi.kc = 2.0;
    cl.pi.ti = 50.0;
    cl.disturbance = Some(Signal::Sine {
        amplitude: 0.5,
        period: 60.0,
        offset: 0.0,
    });
    cl.samples = 1500;
    let d = cl.run().unwrap();
    assert_eq!(d.pv.len(), 1500);
    assert!(d.pv.iter().all(|v| v.is_finite()));
    assert!(d.op.iter().all(|v| (0.0..=100.0).contains(v)));
}

#[test]
fn invalid_loops_are_refused() {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 0.5 }));
    cl.process = Process::Foptd {
        k: 3.0,
        tau: -1.0,
        delay: 1.0,
    };
    assert!(cl.run().unwrap_err().to_string().contains("tau"));
}
