//! Closed-loop identification: the linear part alone, then stiction from OP and PV.

use stiction_core::estimate::Method;
use stiction_core::identify::{self, Data, SearchRange, Structure};
use stiction_core::models::{Model, ModelKind, Stenman};
use stiction_core::quantify::{quantify, QuantifyRequest, QuantifyStatus, ValveStartKind};
use stiction_core::sim::{ClosedLoop, Signal};

fn sticky_loop(d: f64, noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d }));
    cl.samples = 1500;
    cl.noise = noise;
    cl.seed = seed;
    let data = cl.run().unwrap();
    (data.op, data.mv, data.pv)
}

#[test]
fn arx_recovers_a_first_order_process_with_dead_time() {
    // the valve position is known here: random steps through K = 3, tau = 10 s, delay 10 s
    let mv = Signal::Steps {
        amplitude: 5.0,
        hold: 15.0,
        offset: 50.0,
        seed: 4,
    }
    .generate(1.0, 1500);
    let a = (-0.1f64).exp();
    let mut pv = vec![50.0; mv.len()];
    for t in 11..mv.len() {
        pv[t] = 50.0 + a * (pv[t - 1] - 50.0) + 3.0 * (1.0 - a) * (mv[t - 11] - 50.0);
    }
    let range = SearchRange::new(20);
    let data = Data::new(&pv, range.t0());
    let mv_c = identify::centred(&mv);
    let chosen = identify::select(&data, &mv_c, &range).unwrap().structure;
    assert_eq!((chosen.integrating, chosen.nk), (false, 11), "{chosen:?}");
    let truth = Structure {
        integrating: false,
        na: 1,
        nb: 1,
        nk: 11,
    };
    let fit = identify::fit(&data, &mv_c, truth).unwrap();
    assert!((fit.a[0] - a).abs() < 1e-6, "{:?}", fit.a);
    assert!(fit.r2_simulation() > 0.999999);
    let phys = identify::physical(&fit, 1.0);
    assert!((phys.gain.unwrap() - 3.0).abs() < 1e-4);
    assert!((phys.time_constant.unwrap() - 10.0).abs() < 1e-3);
    assert_eq!(phys.dead_time, 10.0);
}

#[test]
fn stenman_band_from_op_and_pv_alone() {
    let (op, _, pv) = sticky_loop(1.0, 0.0, 1);
    let q = quantify(
        &op,
        &pv,
        &QuantifyRequest::new(ModelKind::Stenman, Method::Exact),
    )
    .unwrap();
    assert_eq!(q.status, QuantifyStatus::Ok);
    let d = q.params["d"];
    assert!((d - 1.0).abs() < 0.05, "d = {d}");
    let [lo, hi] = q.interval["d"];
    assert!(lo <= 1.0 && 1.0 <= hi, "[{lo}, {hi}]");
    let lm = q.linear_model.as_ref().unwrap();
    assert_eq!(lm.nk, 11, "{lm:?}");
    assert!(q.fit.as_ref().unwrap().r2_simulation > 0.99);
    assert_eq!(q.mv.len(), op.len());
    assert_eq!(q.pv_simulated.len(), op.len());
}

#[test]
fn noisy_loop_and_reproducible_two_parameter_search() {
    let (op, _, pv) = sticky_loop(2.0, 0.05, 3);
    let q = quantify(
        &op,
        &pv,
        &QuantifyRequest::new(ModelKind::Stenman, Method::Exact),
    )
    .unwrap();
    assert!((q.params["d"] - 2.0).abs() < 0.2, "{:?}", q.params);
    let mut req = QuantifyRequest::new(ModelKind::Kano, Method::AcoR);
    req.acor.iterations = 20;
    req.seed = 9;
    let a = quantify(&op, &pv, &req).unwrap();
    let b = quantify(&op, &pv, &req).unwrap();
    assert_eq!(a.params, b.params);
    assert_eq!(a.seed, Some(9));
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let (op, _, pv) = sticky_loop(0.5, 0.05, 5);
    let run = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                let q = quantify(
                    &op,
                    &pv,
                    &QuantifyRequest::new(ModelKind::Stenman, Method::Exact),
                )
                .unwrap();
                (q.params, q.interval, q.cells)
            })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn loops_that_cannot_be_judged_say_why() {
    let (op, _, pv) = sticky_loop(1.0, 0.05, 2);
    let req = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
    let short = quantify(&op[..60], &pv[..60], &req).unwrap();
    assert_eq!(short.status, QuantifyStatus::InsufficientData);
    assert!(short.reason.unwrap().contains("samples"));
    let flat = quantify(&op, &vec![3.0; op.len()], &req).unwrap();
    assert!(flat.reason.unwrap().contains("PV is constant"));
    let saturated: Vec<f64> = op
        .iter()
        .enumerate()
        .map(|(i, _)| if i % 2 == 0 { 100.0 } else { 120.0 })
        .collect();
    let sat = quantify(&saturated, &pv, &req).unwrap();
    assert!(sat.reason.unwrap().contains("saturated"));
    let still = quantify(&vec![40.0; op.len()], &pv, &req).unwrap();
    assert!(still.reason.unwrap().contains("OP is constant"));
    // a request that is wrong is an error, not a status
    let mut bad = req.clone();
    bad.bounds = Some(vec![(2.0, 1.0)]);
    assert!(quantify(&op, &pv, &bad).is_err());
    assert!(quantify(
        &op,
        &pv,
        &QuantifyRequest::new(ModelKind::Kano, Method::Exact)
    )
    .is_err());
}

#[test]
fn a_record_that_starts_mid_cycle_needs_the_valve_start_estimated() {
    // a sticky loop's record cut 20 samples in: the valve no longer stands where OP starts
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 1.0 }));
    cl.samples = 2000;
    cl.noise = 0.05;
    cl.seed = 3;
    let data = cl.run().unwrap();
    let (op, pv) = (&data.op[20..], &data.pv[20..]);
    let plain = quantify(
        op,
        pv,
        &QuantifyRequest::new(ModelKind::Stenman, Method::Exact),
    )
    .unwrap();
    let mut req = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
    req.estimate_start = true;
    let estimated = quantify(op, pv, &req).unwrap();
    assert_eq!(plain.valve_start_kind, Some(ValveStartKind::FirstOp));
    assert_eq!(plain.valve_start, Some(op[0]));
    assert_eq!(estimated.valve_start_kind, Some(ValveStartKind::Estimated));
    let d = estimated.params["d"];
    assert!((d - 1.0).abs() < 0.1, "estimated start: d = {d}");
    let sse = |q: &stiction_core::quantify::Quantification| q.fit.as_ref().unwrap().sse_simulation;
    // never worse than starting at the first OP, here much better
    assert!(
        sse(&estimated) < 0.5 * sse(&plain),
        "{} vs {}",
        sse(&estimated),
        sse(&plain)
    );
    // the true valve position at the cut, within the band of the estimate
    let x0 = estimated.valve_start.unwrap();
    assert!(
        (x0 - data.mv[20]).abs() <= 1.0,
        "start {x0} vs valve {}",
        data.mv[20]
    );
}

#[test]
fn a_valve_started_at_the_first_command_is_the_usual_simulation() {
    let op: Vec<f64> = (0..400)
        .map(|i| 50.0 + 3.0 * (i as f64 / 17.0).sin() + 0.4 * (i as f64 / 3.1).cos())
        .collect();
    for model in [
        Model::Stenman(Stenman { d: 0.7 }),
        ModelKind::He.build(&[0.8, 0.3]).unwrap(),
    ] {
        assert_eq!(model.simulate_from(&op, Some(op[0])), model.simulate(&op));
        assert_eq!(model.simulate_from(&op, None), model.simulate(&op));
        // started elsewhere, the valve stays there until the command leaves its band
        let mv = model.simulate_from(&op, Some(op[0] + 0.5));
        assert_eq!(mv[0], op[0] + 0.5);
        assert_eq!(mv[1], op[0] + 0.5);
    }
}

#[test]
fn an_unstable_linear_fit_gives_no_r2_without_stiction() {
    let fit = |a: &[f64]| identify::Fit {
        structure: Structure {
            integrating: false,
            na: a.len(),
            nb: 1,
            nk: 1,
        },
        a: a.to_vec(),
        b: vec![1.0],
        c: 0.0,
        sse_one_step: 0.0,
        sse_simulation: 0.0,
        sst: 1.0,
    };
    assert!(fit(&[0.5]).stable() && !fit(&[1.2]).stable());
    // poles 0.8 and 0.7; then 1 and 0.5; then a complex pair of modulus 0.9
    assert!(fit(&[1.5, -0.56]).stable());
    assert!(!fit(&[1.5, -0.5]).stable());
    assert!(fit(&[0.0, -0.81]).stable() && !fit(&[0.0, -1.21]).stable());

    // a slow sticky loop whose linear fit without stiction runs away in simulation: no number
    // rather than an R² of about -1e56
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 2.0 }));
    cl.process = stiction_core::sim::Process::Foptd {
        k: 1.0,
        tau: 30.0,
        delay: 5.0,
    };
    cl.pi = stiction_core::sim::Pi { kc: 1.0, ti: 30.0 };
    cl.samples = 2000;
    cl.noise = 0.02;
    cl.seed = 2;
    let data = cl.run().unwrap();
    let q = quantify(
        &data.op,
        &data.pv,
        &QuantifyRequest::new(ModelKind::Stenman, Method::Exact),
    )
    .unwrap();
    let f = q.fit.unwrap();
    assert!(f.r2_simulation > 0.9);
    assert!(
        f.r2_simulation_without_stiction.is_none_or(|r2| r2 > -10.0),
        "{:?}",
        f.r2_simulation_without_stiction
    );
}

#[test]
fn a_search_setting_out_of_range_is_an_error_naming_it() {
    let (op, _, pv) = sticky_loop(1.0, 0.02, 4);
    let mut req = QuantifyRequest::new(ModelKind::Stenman, Method::Aco);
    req.aco.ants = 0;
    let e = quantify(&op, &pv, &req).unwrap_err().to_string();
    assert_eq!(e, "aco ants must be at least 1, got 0");
}
