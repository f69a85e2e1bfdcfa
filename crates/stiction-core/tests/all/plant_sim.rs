//! The plant features of the loop simulator, each held to a law.

use proptest::prelude::*;
use stiction_core::models::{Kano, Model, Stenman, StictionModel};
use stiction_core::sim::{
    backlash, Cascade, Characteristic, ClosedLoop, Compression, CompressionMethod, Pi, Process,
    Quantisation, QuantiseAt, Reconstruction, Signal, ValveLag,
};

fn healthy() -> Model {
    Model::Stenman(Stenman { d: 0.0 })
}

fn std_dev(v: &[f64]) -> f64 {
    let m = v.iter().sum::<f64>() / v.len() as f64;
    (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
}

/// A flow-like loop with noise and a moving setpoint.
fn busy_loop(model: Model) -> ClosedLoop {
    let mut cl = ClosedLoop::new(model);
    cl.process = Process::Foptd {
        k: 1.5,
        tau: 20.0,
        delay: 4.0,
    };
    cl.pi = Pi { kc: 0.5, ti: 20.0 };
    cl.setpoint = Signal::RandomSteps {
        amplitude: 3.0,
        min_hold: 60.0,
        max_hold: 200.0,
        offset: 50.0,
        seed: 3,
    };
    cl.noise = 0.1;
    cl.seed = 11;
    cl
}

#[test]
fn the_historian_samples_the_latest_controller_values() {
    // controller every 2 s; a record every 5 s equals a record every 1 s read at 5 k
    let mut fine = busy_loop(Model::Stenman(Stenman { d: 1.0 }));
    fine.controller_period = Some(2.0);
    fine.ts = 1.0;
    fine.samples = 1000;
    let mut coarse = fine.clone();
    coarse.ts = 5.0;
    coarse.samples = 200;
    let (f, c) = (fine.run().unwrap(), coarse.run().unwrap());
    for k in 0..200 {
        assert_eq!(c.t[k], 5.0 * k as f64);
        for (a, b) in [
            (&c.op, &f.op),
            (&c.pv, &f.pv),
            (&c.sp, &f.sp),
            (&c.mv, &f.mv),
        ] {
            assert_eq!(a[k], b[5 * k], "sample {k}");
        }
    }
    // a 1 s record of a 2 s controller holds each value for two samples
    assert!((0..500).all(|k| f.op[2 * k] == f.op[2 * k + 1]));
}

#[test]
fn an_averaging_historian_records_the_mean_of_each_interval() {
    // a record every 10 s of averages equals the means of a 1 s record's ten samples up to it
    let mut fine = busy_loop(Model::Stenman(Stenman { d: 1.0 }));
    fine.controller_period = Some(1.0);
    fine.ts = 1.0;
    fine.samples = 1000;
    let mut coarse = fine.clone();
    coarse.ts = 10.0;
    coarse.samples = 100;
    coarse.historian.average = true;
    let (f, c) = (fine.run().unwrap(), coarse.run().unwrap());
    for k in 1..100 {
        let window = 10 * k - 9..=10 * k;
        for (a, b) in [(&c.op, &f.op), (&c.pv, &f.pv), (&c.mv, &f.mv)] {
            let mean = b[window.clone()].iter().sum::<f64>() / 10.0;
            assert!((a[k] - mean).abs() < 1e-9, "sample {k}: {} vs {mean}", a[k]);
        }
        // the setpoint is a setting: its latest value
        assert_eq!(c.sp[k], f.sp[10 * k]);
    }
}

#[test]
fn substeps_record_the_plant_between_controller_executions() {
    // no lag, no noise, a delay of whole controller periods: the valve's position is held over
    // each period, so stepping the plant three times per period changes nothing the controller sees
    let mut coarse = ClosedLoop::new(Model::Stenman(Stenman { d: 1.0 }));
    coarse.process = Process::Foptd {
        k: 1.5,
        tau: 20.0,
        delay: 6.0,
    };
    coarse.pi = Pi { kc: 0.5, ti: 20.0 };
    coarse.controller_period = Some(3.0);
    coarse.ts = 3.0;
    coarse.samples = 600;
    let mut fine = coarse.clone();
    fine.substeps = Some(3);
    fine.ts = 1.0;
    fine.samples = 1800;
    let (c, f) = (coarse.simulate().unwrap(), fine.simulate().unwrap());
    for k in 0..600 {
        assert!((c.data.pv[k] - f.data.pv[3 * k]).abs() < 1e-9, "sample {k}");
        assert!((c.data.op[k] - f.data.op[3 * k]).abs() < 1e-9);
    }
    assert_eq!((c.slips, c.steps), (f.slips, f.steps));
    assert!(c.slips > 5);
    // between executions OP is held and PV moves
    let op_held = (0..600).all(|k| f.data.op[3 * k] == f.data.op[3 * k + 2]);
    let pv_moves = (0..600)
        .filter(|&k| f.data.pv[3 * k] != f.data.pv[3 * k + 1])
        .count();
    assert!(op_held && pv_moves > 300, "{pv_moves}");
    let mut bad = fine.clone();
    bad.substeps = Some(0);
    assert!(bad.run().unwrap_err().to_string().contains("substeps"));
}

#[test]
fn the_controller_integrates_over_its_own_period() {
    let mut cl = busy_loop(healthy());
    cl.controller_period = Some(0.5);
    cl.ts = 0.5;
    cl.samples = 3000;
    let d = cl.run().unwrap();
    let Pi { kc, ti } = cl.pi;
    let e: Vec<f64> = d.sp.iter().zip(&d.pv).map(|(s, p)| s - p).collect();
    let mut checked = 0;
    for t in 1..d.op.len() {
        if d.op[t] > 0.0 && d.op[t] < 100.0 {
            let expect = d.op[t - 1] + kc * (e[t] - e[t - 1]) + kc * 0.5 / ti * e[t];
            assert!((d.op[t] - expect).abs() < 1e-9, "t = {t}");
            checked += 1;
        }
    }
    assert!(checked > 2900);
}

#[test]
fn the_valve_lag_has_a_first_order_step_response() {
    let (tau, h) = (3.0, 0.5);
    let mut lag = ValveLag::new(tau, h, 10.0);
    for k in 1..40 {
        let x = lag.step(20.0);
        let expect = 20.0 - 10.0 * (-(k as f64) * h / tau).exp();
        assert!((x - expect).abs() < 1e-12, "step {k}: {x} vs {expect}");
    }
    // in a loop with a healthy valve the recorded position chases OP by that law
    let mut cl = busy_loop(healthy());
    cl.valve_lag = tau;
    cl.controller_period = Some(h);
    cl.ts = h;
    cl.samples = 2000;
    let d = cl.run().unwrap();
    let a = (-h / tau).exp();
    for t in 1..d.mv.len() {
        assert!((d.mv[t] - (a * d.mv[t - 1] + (1.0 - a) * d.op[t])).abs() < 1e-9);
    }
    assert!(d.mv.iter().zip(&d.op).any(|(m, o)| (m - o).abs() > 0.1));
}

#[test]
fn equal_percentage_endpoints_and_rangeability() {
    let c = Characteristic::EqualPercentage { rangeability: 50.0 };
    assert!(c.flow(0.0).abs() < 1e-12);
    assert!((c.flow(100.0) - 100.0).abs() < 1e-9);
    assert!((c.flow(50.0) - 100.0 * (50f64.sqrt() - 1.0) / 49.0).abs() < 1e-9);
    assert!((c.gain(100.0) / c.gain(0.0) - 50.0).abs() < 1e-9);
    // the local gain is the slope of the flow
    let x = 37.0;
    let slope = (c.flow(x + 1e-5) - c.flow(x - 1e-5)) / 2e-5;
    assert!((slope - c.gain(x)).abs() < 1e-6);
    assert_eq!(Characteristic::Linear.flow(42.5), 42.5);
    assert!(Characteristic::EqualPercentage { rangeability: 1.0 }
        .validate()
        .is_err());
}

proptest! {
    #[test]
    fn equal_percentage_is_increasing_and_below_linear(a in 0.0..100.0f64, b in 0.0..100.0f64, r in 2.0..100.0f64) {
        let c = Characteristic::EqualPercentage { rangeability: r };
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        prop_assume!(hi - lo > 1e-9);
        prop_assert!(c.flow(lo) < c.flow(hi));
        // convex through (0, 0) and (100, 100): never above the linear valve
        prop_assert!(c.flow(a) <= a + 1e-9);
    }
}

#[test]
fn two_lags_follow_the_analytic_step_response() {
    let h = 2.0;
    for (tau1, tau2) in [(30.0, 8.0), (8.0, 30.0), (15.0, 15.0)] {
        let p = Process::Soptd {
            k: 2.0,
            tau1,
            tau2,
            delay: 0.0,
        };
        let mut s = p.discretise(h);
        for k in 0..100 {
            let t = k as f64 * h;
            let expect = if tau1 == tau2 {
                2.0 * (1.0 - (1.0 + t / tau1) * (-t / tau1).exp())
            } else {
                2.0 * (1.0 - (tau1 * (-t / tau1).exp() - tau2 * (-t / tau2).exp()) / (tau1 - tau2))
            };
            assert!(
                (s.output() - expect).abs() < 1e-12,
                "tau {tau1}/{tau2} t {t}: {} vs {expect}",
                s.output()
            );
            s.advance(1.0);
        }
    }
}

#[test]
fn a_load_step_is_taken_up_by_the_valve() {
    // integral action returns PV to the setpoint: the valve's flow moves by minus the load
    let mut cl = ClosedLoop::new(healthy());
    cl.process = Process::Foptd {
        k: 1.0,
        tau: 10.0,
        delay: 2.0,
    };
    cl.pi = Pi { kc: 0.8, ti: 10.0 };
    cl.setpoint = Signal::Constant { value: 50.0 };
    cl.samples = 1500;
    cl.load = Some(Signal::Step {
        from: 0.0,
        to: 4.0,
        at: 100.0,
    });
    let d = cl.run().unwrap();
    assert!(
        (d.op[1499] - (50.0 - 4.0)).abs() < 1e-6,
        "op {}",
        d.op[1499]
    );
    assert!((d.pv[1499] - 50.0).abs() < 1e-6);
    // through an equal-percentage valve, the flow (not the position) moves by minus the load
    cl.characteristic = Characteristic::EqualPercentage { rangeability: 30.0 };
    let d = cl.run().unwrap();
    let c = cl.characteristic;
    assert!((c.flow(d.mv[1499]) - (c.flow(50.0) - 4.0)).abs() < 1e-6);
}

fn random_record(seed: u64, n: usize) -> (Vec<f64>, Vec<f64>) {
    let x = Signal::Sum {
        parts: vec![
            Signal::RandomWalk {
                step_std: 0.3,
                offset: 50.0,
                seed,
            },
            Signal::Sine {
                amplitude: 2.0,
                period: 97.0,
                offset: 0.0,
            },
        ],
    }
    .generate(1.0, n);
    ((0..n).map(|k| 2.0 * k as f64).collect(), x)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    #[test]
    fn historian_compression_stays_within_its_deviation(seed in 0u64..1000, dev in 0.01..3.0f64, n in 2usize..600) {
        let (t, x) = random_record(seed, n);
        for (method, how, bound) in [
            (CompressionMethod::SwingingDoor, Reconstruction::Linear, dev),
            (CompressionMethod::SwingingDoor, Reconstruction::Hold, f64::INFINITY),
            (CompressionMethod::Deadband, Reconstruction::Hold, dev),
            (CompressionMethod::Deadband, Reconstruction::Linear, 2.0 * dev),
        ] {
            let c = Compression { method, deviation: dev, reconstruction: how };
            let kept = c.stored(&t, &x);
            prop_assert_eq!(kept[0], 0);
            prop_assert_eq!(*kept.last().unwrap(), n - 1);
            prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
            let y = c.apply(&t, &x);
            prop_assert_eq!(y.len(), n);
            for &i in &kept {
                prop_assert_eq!(y[i], x[i]);
            }
            for i in 0..n {
                prop_assert!((y[i] - x[i]).abs() <= bound + 1e-9, "{:?} {:?} sample {}: {} vs {}", method, how, i, y[i], x[i]);
            }
        }
    }
}

#[test]
fn compression_stores_few_points_of_a_quiet_signal() {
    let (t, x) = random_record(5, 2000);
    for method in [CompressionMethod::SwingingDoor, CompressionMethod::Deadband] {
        let c = Compression {
            method,
            deviation: 1.0,
            reconstruction: Reconstruction::Linear,
        };
        let kept = c.stored(&t, &x).len();
        assert!(kept < 700, "{method:?} kept {kept} of 2000");
    }
    // with zero deviation, swinging door keeps every bend and reproduces the signal
    let c = Compression {
        method: CompressionMethod::SwingingDoor,
        deviation: 0.0,
        reconstruction: Reconstruction::Linear,
    };
    let y = c.apply(&t, &x);
    assert!(y.iter().zip(&x).all(|(a, b)| (a - b).abs() < 1e-9));
}

#[test]
fn compressed_and_quantised_records() {
    let mut cl = busy_loop(Model::Stenman(Stenman { d: 0.5 }));
    cl.samples = 1000;
    let plain = cl.run().unwrap();
    let mut q = cl.clone();
    q.quantisation = Some(Quantisation {
        step: 0.25,
        at: QuantiseAt::Historian,
    });
    let dq = q.run().unwrap();
    // historian rounding changes the record, not the loop
    assert_eq!(dq.op, plain.op);
    for (a, b) in dq.pv.iter().zip(&plain.pv) {
        assert!((a / 0.25 - (a / 0.25).round()).abs() < 1e-9);
        assert!((a - b).abs() <= 0.125 + 1e-9);
    }
    q.quantisation = Some(Quantisation {
        step: 0.25,
        at: QuantiseAt::Sensor,
    });
    let ds = q.run().unwrap();
    assert!(ds
        .pv
        .iter()
        .all(|a| (a / 0.25 - (a / 0.25).round()).abs() < 1e-9));
    assert_ne!(ds.op, plain.op, "the controller sees the rounded PV");

    let mut c = cl.clone();
    let comp = Compression {
        method: CompressionMethod::SwingingDoor,
        deviation: 0.3,
        reconstruction: Reconstruction::Linear,
    };
    c.historian.pv = Some(comp);
    c.historian.op = Some(comp);
    let dc = c.run().unwrap();
    assert_eq!(dc.mv, plain.mv);
    for (a, b) in [(&dc.pv, &plain.pv), (&dc.op, &plain.op)] {
        assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 0.3 + 1e-9));
        assert_ne!(a, b);
    }
}

#[test]
fn a_cascade_inner_setpoint_is_the_outer_output() {
    let mut cl = busy_loop(healthy());
    cl.setpoint = Signal::Constant { value: 50.0 };
    cl.samples = 3000;
    let (kc, ti) = (1.2, 300.0);
    cl.cascade = Some(Cascade {
        process: Process::Foptd {
            k: 0.8,
            tau: 120.0,
            delay: 20.0,
        },
        pi: Pi { kc, ti },
        setpoint: Signal::RandomSteps {
            amplitude: 5.0,
            min_hold: 300.0,
            max_hold: 600.0,
            offset: 40.0,
            seed: 2,
        },
        noise: 0.05,
        disturbance: None,
    });
    let run = cl.simulate().unwrap();
    let outer = run.outer.as_ref().unwrap();
    assert_eq!(run.data.sp, outer.op);
    assert_eq!(run.data.sp[0], 50.0);
    // the outer controller is a PI on the outer error
    let e: Vec<f64> = outer.sp.iter().zip(&outer.pv).map(|(s, p)| s - p).collect();
    for t in 1..e.len() {
        if outer.op[t] > 0.0 && outer.op[t] < 100.0 {
            let expect = outer.op[t - 1] + kc * (e[t] - e[t - 1]) + kc / ti * e[t];
            assert!((outer.op[t] - expect).abs() < 1e-9);
        }
    }
    // the outer loop moves the inner setpoint and settles its own PV near its setpoint
    assert!(std_dev(&run.data.sp) > 0.5);
    let tail = 2900..3000;
    let err: f64 = tail
        .clone()
        .map(|t| (outer.sp[t] - outer.pv[t]).abs())
        .sum::<f64>()
        / 100.0;
    assert!(err < 1.0, "outer error {err}");
    // the inner loop's noise is the same with and without the outer loop
    let mut plain = cl.clone();
    plain.cascade = None;
    assert_eq!(plain.run().unwrap().pv[0], run.data.pv[0]);
}

#[test]
fn kano_without_slip_jump_is_a_backlash_once_it_has_moved_both_ways() {
    let band = 3.0;
    let valve = backlash(band);
    let Model::Kano(kano) = valve else {
        panic!("backlash is Kano's model")
    };
    assert_eq!(kano, Kano { s: band, j: 0.0 });
    let op = Signal::Sum {
        parts: vec![
            Signal::RandomWalk {
                step_std: 0.4,
                offset: 50.0,
                seed: 4,
            },
            Signal::Sine {
                amplitude: 4.0,
                period: 80.0,
                offset: 0.0,
            },
        ],
    }
    .generate(1.0, 5000);
    let mv = valve.simulate(&op);
    // the first sample after the valve has moved down and up
    let moved = |dir: f64| {
        (1..op.len())
            .find(|&t| (mv[t] - mv[t - 1]) * dir > 0.0)
            .unwrap()
    };
    let start = moved(1.0).max(moved(-1.0));
    // a plain play operator: the stem stays while the command is within band / 2 of it
    let mut x = mv[start];
    let mut checked = 0;
    for t in start + 1..op.len() {
        let u = op[t].clamp(0.0, 100.0);
        if u - x > band / 2.0 {
            x = u - band / 2.0;
        } else if x - u > band / 2.0 {
            x = u + band / 2.0;
        }
        assert!((mv[t] - x).abs() < 1e-9, "t = {t}: kano {} play {x}", mv[t]);
        checked += 1;
    }
    assert!(checked > 4500);
    // and no slip jump: the stem never moves past the command's side of the band
    assert!(mv
        .iter()
        .zip(&op)
        .skip(start)
        .all(|(m, u)| (m - u).abs() <= band / 2.0 + 1e-9));
    // unlike a valve with a slip jump
    let (mut st, _) = Kano { s: band, j: 2.0 }.start(op[0]);
    let jumps = Kano { s: band, j: 2.0 };
    assert!(op[1..]
        .iter()
        .any(|&u| (jumps.step(&mut st, u) - u).abs() < band / 2.0 - 0.5));
}

#[test]
fn the_warm_up_is_simulated_and_not_recorded() {
    let mut long = busy_loop(Model::Stenman(Stenman { d: 1.0 }));
    long.samples = 1500;
    let mut warm = long.clone();
    warm.samples = 1000;
    warm.warmup = 500.0;
    let (a, b) = (long.run().unwrap(), warm.run().unwrap());
    assert_eq!(b.t[0], 0.0);
    assert_eq!(&b.pv[..], &a.pv[500..]);
    assert_eq!(&b.op[..], &a.op[500..]);
    assert_eq!(&b.sp[..], &a.sp[500..]);
}

#[test]
fn slips_and_saturation_are_counted() {
    let mut cl = busy_loop(Model::Stenman(Stenman { d: 1.5 }));
    cl.samples = 3000;
    let run = cl.simulate().unwrap();
    let mv = &run.data.mv;
    let slips = (2..mv.len())
        .filter(|&t| mv[t] != mv[t - 1] && mv[t - 1] == mv[t - 2])
        .count();
    assert!(slips > 10, "{slips} slips");
    assert_eq!(run.slips, slips);
    assert_eq!(run.steps, 3000);
    // a healthy valve with a quiet loop never stands still and breaks away
    let mut quiet = ClosedLoop::new(healthy());
    quiet.setpoint = Signal::Constant { value: 50.0 };
    let q = quiet.simulate().unwrap();
    assert_eq!((q.slips, q.saturated), (0, 0));
    // a loop near the top of its range: a load it cannot take holds OP at 100 %
    let mut sat = busy_loop(healthy());
    sat.op0 = 95.0;
    sat.load = Some(Signal::Sine {
        amplitude: 8.0,
        period: 600.0,
        offset: 0.0,
    });
    let s = sat.simulate().unwrap();
    assert!(s.saturated > 50, "{} saturated", s.saturated);
    assert!(s.data.op.iter().all(|o| (0.0..=100.0).contains(o)));
}

#[test]
fn plant_signals_have_their_shape() {
    let ramp = Signal::Ramp {
        slope: 0.5,
        start: 2.0,
        offset: 1.0,
    }
    .generate(1.0, 5);
    assert_eq!(ramp, [1.0, 1.0, 1.0, 1.5, 2.0]);

    let steps = Signal::RandomSteps {
        amplitude: 4.0,
        min_hold: 30.0,
        max_hold: 90.0,
        offset: 50.0,
        seed: 8,
    }
    .generate(1.0, 5000);
    assert_eq!(steps[0], 50.0);
    assert!(steps.iter().all(|v| (46.0..=54.0).contains(v)));
    let changes: Vec<usize> = (1..steps.len())
        .filter(|&k| steps[k] != steps[k - 1])
        .collect();
    assert!(changes.len() > 50);
    assert!(changes
        .windows(2)
        .all(|w| (30..=91).contains(&(w[1] - w[0]))));

    // the second difference of an integrated random walk is white with std slope_std ts^1.5
    let ts = 2.0;
    let drift = Signal::IntegratedRandomWalk {
        slope_std: 0.01,
        offset: 0.0,
        seed: 1,
    }
    .generate(ts, 20000);
    let dd: Vec<f64> = drift.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
    let expect = 0.01 * ts.powf(1.5);
    assert!((std_dev(&dd) / expect - 1.0).abs() < 0.03);

    // narrow-band noise: the standard deviation of a sine of that amplitude, and its period
    let nb = Signal::NarrowBand {
        amplitude: 2.0,
        period: 60.0,
        damping: 0.05,
        seed: 3,
    }
    .generate(1.0, 20000);
    assert!((std_dev(&nb) - 2.0 / 2f64.sqrt()).abs() < 1e-9);
    let ups = nb.windows(2).filter(|w| w[0] < 0.0 && w[1] >= 0.0).count();
    let period = 20000.0 / ups as f64;
    assert!((period / 60.0 - 1.0).abs() < 0.1, "period {period}");
    assert!(Signal::NarrowBand {
        amplitude: 1.0,
        period: 60.0,
        damping: 0.0,
        seed: 1
    }
    .validate()
    .is_err());

    // a recorded series: straight between its values, held after the last
    let rec = Signal::Recorded {
        dt: 2.0,
        values: vec![0.0, 4.0, 2.0],
    };
    assert_eq!(
        rec.generate(1.0, 7),
        vec![0.0, 2.0, 4.0, 3.0, 2.0, 2.0, 2.0]
    );
    assert!(rec.validate().is_ok());
    for bad in [
        Signal::Recorded {
            dt: 0.0,
            values: vec![1.0],
        },
        Signal::Recorded {
            dt: 1.0,
            values: vec![],
        },
        Signal::Recorded {
            dt: 1.0,
            values: vec![1.0, f64::NAN],
        },
    ] {
        assert!(bad.validate().is_err(), "{bad:?}");
    }

    let a = Signal::Sine {
        amplitude: 1.0,
        period: 10.0,
        offset: 2.0,
    };
    let b = Signal::Ramp {
        slope: 1.0,
        start: 0.0,
        offset: 0.0,
    };
    let sum = Signal::Sum {
        parts: vec![a.clone(), b.clone()],
    }
    .generate(0.5, 50);
    let (ga, gb) = (a.generate(0.5, 50), b.generate(0.5, 50));
    assert!((0..50).all(|k| sum[k] == ga[k] + gb[k]));
}

#[test]
fn new_settings_are_checked() {
    let mut cl = ClosedLoop::new(healthy());
    cl.controller_period = Some(0.0);
    assert!(cl
        .run()
        .unwrap_err()
        .to_string()
        .contains("controller period"));
    let mut cl = ClosedLoop::new(healthy());
    cl.valve_lag = -1.0;
    assert!(cl.run().unwrap_err().to_string().contains("valve lag"));
    let mut cl = ClosedLoop::new(healthy());
    cl.quantisation = Some(Quantisation {
        step: 0.0,
        at: QuantiseAt::Sensor,
    });
    assert!(cl.run().unwrap_err().to_string().contains("quantisation"));
    // a default loop serialises as it always did: no plant-feature keys
    let json = serde_json::to_value(ClosedLoop::new(healthy())).unwrap();
    let keys: Vec<&String> = json.as_object().unwrap().keys().collect();
    assert_eq!(keys.len(), 10, "{keys:?}");
}

/// A feed-forward of the measured load moves OP against the load as it comes: with all of it fed
/// forward, PV strays less than half as far from the setpoint as under feedback alone (what is
/// left is the process delay, which the load does not wait for), while OP moves as much; without
/// a load there is nothing to feed forward.
#[test]
fn a_fed_forward_load_moves_op_and_spares_pv() {
    let mut cl = busy_loop(healthy());
    cl.setpoint = Signal::Constant { value: 50.0 };
    cl.noise = 0.0;
    cl.load = Some(Signal::RandomSteps {
        amplitude: 6.0,
        min_hold: 150.0,
        max_hold: 300.0,
        offset: 0.0,
        seed: 7,
    });
    let feedback = cl.run().unwrap();
    cl.feed_forward = Some(1.0);
    let fed = cl.run().unwrap();
    let stray = |d: &stiction_core::sim::LoopData| {
        d.pv.iter().map(|p| (p - 50.0).abs()).fold(0.0, f64::max)
    };
    assert!(
        stray(&fed) < 0.5 * stray(&feedback),
        "{} vs {}",
        stray(&fed),
        stray(&feedback)
    );
    assert!(std_dev(&fed.op) > 0.5 * std_dev(&feedback.op));
    cl.load = None;
    assert!(cl.validate().is_err());
}
