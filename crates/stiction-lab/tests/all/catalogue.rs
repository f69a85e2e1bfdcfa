//! The benchmark catalogue: sizes and classes as the issues ask, determinism, sticky valves that
//! slip, fast sticky loops that limit-cycle, and issue 14's example.

use stiction_core::models::{Kano, Model};
use stiction_core::sim::{Characteristic, Signal};
use stiction_lab::catalogue::{
    self, catalogue, find, generate, issue14_example, loop_id, BenchmarkLoop, LoopClass,
    NoiseLevel, Set, Suite, Truth, MIN_SLIPS,
};

fn count(ls: &[BenchmarkLoop], f: impl Fn(&BenchmarkLoop) -> bool) -> usize {
    ls.iter().filter(|l| f(l)).count()
}

#[test]
fn the_routine_suite_is_what_issue_10_asks() {
    let ls = catalogue(Suite::Routine, Set::Benchmark);
    assert!(ls.len() >= 400);
    let sticky = count(&ls, |l| l.truth == Truth::Sticky);
    // about half sticky (240 of 540: the look-alikes added since, load steps and a fed-forward
    // load, are not-sticky; the balanced accuracy does not weigh the classes by their counts)
    assert!(
        (sticky as f64 / ls.len() as f64 - 0.5).abs() < 0.07,
        "{sticky} sticky"
    );
    for class in [
        LoopClass::Healthy,
        LoopClass::EqualPercentage,
        LoopClass::QuantisedPv,
        LoopClass::CompressedPv,
        LoopClass::SlowLongDelay,
        LoopClass::AggressiveTuning,
        LoopClass::ExternalOscillation,
        LoopClass::BacklashValve,
        LoopClass::LoadSteps,
        LoopClass::FeedForward,
    ] {
        assert!(count(&ls, |l| l.class == class) >= 30, "{class}");
    }
    for l in &ls {
        let shape = (l.data.t.len(), l.ts());
        assert!(
            shape == (750, 10.0) || shape == (2000, 1.0),
            "{}: {shape:?}",
            l.id
        );
        assert_eq!(l.data.pv.len(), l.data.t.len());
        assert!(l.data.op.iter().all(|o| (0.0..=100.0).contains(o)));
        if l.truth == Truth::Sticky {
            assert!(l.slips >= MIN_SLIPS, "{} slips {}", l.id, l.slips);
            let band = l.setup.model.values()[0];
            assert!((0.5..=5.0).contains(&band));
        }
    }
    assert!(count(&ls, |l| l.ts() == 10.0) > 150 && count(&ls, |l| l.ts() == 1.0) > 150);
    assert!(count(&ls, |l| l.integrating) > 50);
    for nl in NoiseLevel::ALL {
        assert!(count(&ls, |l| l.noise_level == nl && l.truth == Truth::Sticky) > 40);
    }
    for model in ["stenman", "kano", "he"] {
        let small = count(&ls, |l| {
            l.truth == Truth::Sticky
                && l.setup.model.kind().name() == model
                && l.setup.model.values()[0] < 1.0
        });
        assert!(small >= 10, "{model}: {small} bands below 1 %");
    }
}

#[test]
fn look_alikes_have_their_feature() {
    let ls = catalogue(Suite::Routine, Set::Benchmark);
    for l in &ls {
        let s = &l.setup;
        let healthy_valve = matches!(s.model, Model::Stenman(v) if v.d == 0.0);
        match l.class {
            LoopClass::BacklashValve => {
                assert!(matches!(s.model, Model::Kano(Kano { j, .. }) if j == 0.0))
            }
            LoopClass::EqualPercentage => assert!(matches!(
                s.characteristic,
                Characteristic::EqualPercentage { .. }
            )),
            LoopClass::QuantisedPv => assert!(s.quantisation.is_some()),
            LoopClass::CompressedPv => assert!(s.historian.pv.is_some()),
            LoopClass::ExternalOscillation => {
                assert!(s.disturbance.is_some() || s.load.is_some())
            }
            LoopClass::SlowLongDelay => assert!(s.process.delay() >= 40.0),
            LoopClass::LoadSteps => {
                assert!(matches!(s.load, Some(Signal::RandomSteps { .. })))
            }
            LoopClass::FeedForward => {
                assert!(matches!(s.load, Some(Signal::RandomSteps { .. })));
                assert!(s.feed_forward.is_some_and(|g| (0.7..=1.1).contains(&g)));
            }
            _ => {}
        }
        assert_eq!(l.truth == Truth::NotSticky, healthy_valve, "{}", l.id);
    }
    // compression and quantisation show in the record: repeated or few distinct PV values
    let q = ls
        .iter()
        .find(|l| l.class == LoopClass::QuantisedPv)
        .unwrap();
    let step = q.setup.quantisation.unwrap().step;
    assert!(q
        .data
        .pv
        .iter()
        .all(|v| ((v / step) - (v / step).round()).abs() < 1e-6));
}

#[test]
fn the_fast_suite_is_what_issue_14_asks() {
    let ls = catalogue(Suite::Fast, Set::Benchmark);
    assert!(count(&ls, |l| l.truth == Truth::Sticky) >= 60);
    for class in [
        LoopClass::ExternalOscillation,
        LoopClass::NearUnstable,
        LoopClass::SaturatedOp,
        LoopClass::CascadeInner,
    ] {
        assert!(count(&ls, |l| l.class == class) >= 20, "{class}");
    }
    for l in &ls {
        let h = l.setup.controller_period.unwrap();
        assert!((1.0..=3.0).contains(&h) && (1.0..=5.0).contains(&l.ts()));
        assert!(l.setup.valve_lag > 0.0 && l.setup.noise > 0.0);
        if l.truth == Truth::Sticky {
            // a visible, regular limit cycle without noise
            let c = l.cycle.unwrap_or_else(|| panic!("{} does not cycle", l.id));
            assert!(
                c.spread < 0.4 && c.period >= 6.0 * l.ts() && c.amplitude >= 2.0 * l.setup.noise
            );
        }
        match l.class {
            LoopClass::SaturatedOp => assert!(l.saturated > 0.01, "{}", l.id),
            LoopClass::CascadeInner => {
                let run = l.setup.simulate().unwrap();
                assert_eq!(run.data.sp, run.outer.unwrap().op);
            }
            _ => {}
        }
    }
    let sat_low = count(&ls, |l| {
        l.class == LoopClass::SaturatedOp && l.setup.op0 < 50.0
    });
    assert!(sat_low > 5 && sat_low < 25, "both limits: {sat_low} low");
}

#[test]
fn the_catalogue_is_deterministic_and_thread_independent() {
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| catalogue(Suite::Fast, Set::Calibration));
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap()
        .install(|| catalogue(Suite::Fast, Set::Calibration));
    assert_eq!(one, two);
    let l = &one[17];
    assert_eq!(find(&l.id).as_ref(), Some(l));
    // the setup reproduces the record
    assert_eq!(l.setup.run().unwrap(), l.data);
    // ids carry suite, set and index
    assert_eq!(l.id, "fast-c-0017");
    assert_eq!(one.len(), catalogue::size(Suite::Fast));
    for bad in [
        "fast-c-9999",
        "routine-x-0001",
        "slow-b-0001",
        "routine-b-1-2",
        "routine-b",
    ] {
        assert!(find(bad).is_none(), "{bad}");
    }
}

#[test]
fn benchmark_and_calibration_sets_differ_but_share_the_plan() {
    let b = catalogue(Suite::Routine, Set::Benchmark);
    let c = catalogue(Suite::Routine, Set::Calibration);
    assert_eq!(b.len(), c.len());
    for (x, y) in b.iter().zip(&c) {
        assert_eq!(x.class, y.class);
        assert_ne!(x.data.pv, y.data.pv, "{} and {}", x.id, y.id);
    }
}

#[test]
fn extra_draws_are_other_loops_of_the_same_plan_found_by_id() {
    for i in [0, 300, 479] {
        let c = generate(Suite::Routine, Set::Calibration, i).unwrap();
        let x1 = generate(Suite::Routine, Set::Extra(1), i).unwrap();
        let x2 = generate(Suite::Routine, Set::Extra(2), i).unwrap();
        assert_eq!((x1.class, x2.class), (c.class, c.class));
        assert_ne!(x1.data.pv, c.data.pv, "{}", x1.id);
        assert_ne!(x1.data.pv, x2.data.pv, "{}", x1.id);
        let found = find(&x2.id).unwrap();
        assert_eq!(
            (found.id.as_str(), &found.data.pv),
            (x2.id.as_str(), &x2.data.pv)
        );
    }
    assert_eq!(loop_id(Suite::Fast, Set::Extra(7), 12), "fast-x7-0012");
    for bad in [
        "routine-x-0001",
        "routine-xa-0001",
        "routine-x256-0001",
        "routine-y1-0001",
    ] {
        assert!(find(bad).is_none(), "{bad}");
    }
}

#[test]
fn classes_parse_by_name() {
    for c in LoopClass::ALL {
        assert_eq!(c.name().parse::<LoopClass>(), Ok(c));
        assert_eq!(
            serde_json::to_value(c).unwrap(),
            serde_json::Value::String(c.name().into())
        );
    }
    let e = "sticky".parse::<LoopClass>().unwrap_err();
    assert!(e.contains("stenman_valve"), "{e}");
}

#[test]
fn issue_14_example_limit_cycles_as_described() {
    let l = issue14_example();
    assert_eq!(l.ts(), 2.0);
    assert_eq!(l.setup.model.values(), vec![2.0]);
    let op = &l.data.op;
    let mean = op.iter().sum::<f64>() / op.len() as f64;
    let ups: Vec<usize> = (1..op.len())
        .filter(|&k| op[k - 1] < mean && op[k] >= mean)
        .collect();
    let period = (ups[ups.len() - 1] - ups[0]) as f64 * 2.0 / (ups.len() - 1) as f64;
    assert!((100.0..140.0).contains(&period), "period {period}");
    let mut sorted = op.clone();
    sorted.sort_by(f64::total_cmp);
    let (lo, hi) = (sorted[40], sorted[1959]);
    assert!(
        (27.0..35.0).contains(&lo) && (50.0..57.0).contains(&hi),
        "OP {lo}..{hi}"
    );
    // the linear loop sits just inside its stability limit
    match l.tuning {
        catalogue::Tuning::Ultimate { fraction, .. } => assert!((0.98..1.0).contains(&fraction)),
        other => panic!("{other:?}"),
    }
    // the same loop with other noise seeds cycles alike
    for seed in 2..5 {
        let mut s = l.setup.clone();
        s.seed = seed;
        let d = s.run().unwrap();
        let mut o = d.op.clone();
        o.sort_by(f64::total_cmp);
        assert!(
            o[1959] - o[40] > 15.0 && o[1959] - o[40] < 30.0,
            "seed {seed}"
        );
    }
}

#[test]
fn the_ultimate_gain_is_the_linear_loops_stability_limit() {
    use stiction_core::models::Stenman;
    use stiction_core::sim::{ClosedLoop, Pi, Process, Signal};
    use stiction_lab::catalogue::LinearLoop;
    for process in [
        Process::Foptd {
            k: 1.2,
            tau: 40.0,
            delay: 12.0,
        },
        Process::Soptd {
            k: 0.8,
            tau1: 60.0,
            tau2: 15.0,
            delay: 8.0,
        },
        Process::Integrating {
            k: 0.01,
            delay: 10.0,
        },
    ] {
        let lin = LinearLoop {
            process,
            valve_lag: 2.0,
            h: 1.0,
            valve_gain: 1.0,
        };
        let ti = lin.simc(lin.effective_delay()).ti;
        let (ku, pu) = lin.ultimate(ti).unwrap();
        let swing = |fraction: f64| {
            let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 0.0 }));
            cl.process = process;
            cl.pi = Pi {
                kc: fraction * ku,
                ti,
            };
            cl.valve_lag = 2.0;
            cl.samples = 6000;
            cl.setpoint = Signal::Step {
                from: 50.0,
                to: 50.5,
                at: 10.0,
            };
            let d = cl.run().unwrap();
            let range = |a: usize| {
                let w = &d.pv[a..a + 1000];
                w.iter().cloned().fold(f64::MIN, f64::max)
                    - w.iter().cloned().fold(f64::MAX, f64::min)
            };
            (range(1000), range(5000))
        };
        let (early, late) = swing(0.95);
        assert!(late < early, "{process:?} at 0.95 Ku: {early} -> {late}");
        let (early, late) = swing(1.05);
        assert!(late > early, "{process:?} at 1.05 Ku: {early} -> {late}");
        assert!(pu > 2.0 * lin.effective_delay() && pu < 20.0 * lin.effective_delay());
    }
    // SIMC for a first-order process
    let lin = LinearLoop {
        process: Process::Foptd {
            k: 2.0,
            tau: 30.0,
            delay: 4.0,
        },
        valve_lag: 1.0,
        h: 2.0,
        valve_gain: 0.5,
    };
    let pi = lin.simc(6.0);
    assert!((lin.effective_delay() - 6.0).abs() < 1e-12);
    assert!((pi.kc - 30.0 / (1.0 * 12.0)).abs() < 1e-12 && pi.ti == 30.0);
}

#[test]
fn a_plant_day_is_one_sticky_valve_in_ten_drawn_the_same_at_every_run() {
    let sticky = (0..100)
        .filter(|&i| stiction_lab::catalogue::day_class(i).truth() == Truth::Sticky)
        .count();
    assert_eq!(sticky, 10);
    let a = stiction_lab::catalogue::plant_day(1, 3_000);
    let b = stiction_lab::catalogue::plant_day(1, 3_000);
    assert_eq!(a.data.pv, b.data.pv);
    assert_eq!((a.data.op.len(), a.ts()), (3_000, 1.0));
    assert_eq!(
        stiction_lab::catalogue::plant_day(0, 3_000).truth,
        Truth::Sticky
    );
}
