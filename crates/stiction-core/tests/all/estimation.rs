//! Estimators: the exact solver against brute force, the batched objective against the model,
//! reproducibility (seed, thread count), and the paper's reproduction.

use proptest::prelude::*;
use stiction_core::estimate::{estimate, exact, Method, Objective, Request};
use stiction_core::models::{Kano, Model, ModelKind, Stenman};
use stiction_core::reproduce::{reproduce_paper, PaperSetup};
use stiction_core::sim::{simulate_open_loop, Signal};

fn walk(n: usize, d: f64, noise: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let s = Signal::RandomWalk {
        step_std: 0.3,
        offset: 50.0,
        seed,
    };
    let data =
        simulate_open_loop(&Model::Stenman(Stenman { d }), &s, 1.0, n, noise, seed + 1).unwrap();
    (data.op, data.mv)
}

/// A visited cell of a walk: its edges, trajectory and the samples that changed.
type WalkStep = ((f64, f64), Vec<f64>, Option<Vec<usize>>);

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Every d in the exact optimal set has the optimal cost; a fine grid never beats it; grid
    /// points outside the set cost more.
    #[test]
    fn exact_optimum_is_certified_by_brute_force(seed in 0u64..1000, d in 0.05f64..2.0, noise in 0.0f64..0.2) {
        let (op, mv) = walk(150, d, noise, seed);
        let sol = exact::solve_stenman(&op, &mv, 0.0, 4.0, &Default::default());
        let obj = Objective::new(ModelKind::Stenman, &op, &mv);
        for &(lo, hi) in &sol.pieces {
            for f in [0.0, 0.3, 0.7] {
                let c = obj.eval(&[lo + f * (hi - lo)]);
                prop_assert_eq!(c, sol.sse);
            }
        }
        for i in 0..2000 {
            let g = 4.0 * i as f64 / 2000.0;
            let c = obj.eval(&[g]);
            prop_assert!(c >= sol.sse, "grid d = {} costs {} below the optimum {}", g, c, sol.sse);
            if !sol.contains(g) {
                prop_assert!(c > sol.sse);
            }
        }
    }

    /// The walk that follows changes visits the same cells with the same trajectories as the
    /// walk that simulates each cell whole, bit for bit, and names exactly the samples that
    /// changed; also on OP quantised to a coarse step, where many steps tie at a cell's edge.
    #[test]
    fn incremental_walk_equals_the_whole_walk(seed in 0u64..1000, quantum in prop_oneof![Just(0.0), Just(0.1), Just(0.5)], start in -1.0f64..1.0, a in 0.0f64..1.0, width in 0.1f64..4.0) {
        let (mut op, _) = walk(300, 0.5, 0.0, seed);
        if quantum > 0.0 {
            for u in op.iter_mut() {
                *u = (*u / quantum).round() * quantum;
            }
        }
        let x0 = op[0] + start;
        let (lo, hi) = (0.0, 5.0);
        let chunk = (a, (a + width).min(hi));
        let mut whole: Vec<((f64, f64), Vec<f64>)> = Vec::new();
        let mut mv = vec![0.0; op.len()];
        exact::stenman_walk(&op, x0, chunk, (lo, hi), &mut mv, |cell, mv| whole.push((cell, mv.to_vec())));
        let mut steps: Vec<WalkStep> = Vec::new();
        exact::stenman_walk_changes(&op, x0, chunk, (lo, hi), |cell, mv, changed| {
            steps.push((cell, mv.to_vec(), changed.map(|c| c.to_vec())))
        });
        prop_assert_eq!(whole.len(), steps.len());
        for (k, ((c1, m1), (c2, m2, changed))) in whole.iter().zip(&steps).enumerate() {
            prop_assert_eq!(c1.0.to_bits(), c2.0.to_bits(), "cell {} lower edge", k);
            prop_assert_eq!(c1.1.to_bits(), c2.1.to_bits(), "cell {} upper edge", k);
            let bits = |m: &[f64]| m.iter().map(|v| v.to_bits()).collect::<Vec<u64>>();
            prop_assert_eq!(bits(m1), bits(m2), "cell {} trajectory", k);
            match (k, changed) {
                (0, None) => {}
                (_, Some(changed)) if k > 0 => {
                    let prev = &whole[k - 1].1;
                    let truth: Vec<usize> = (0..m1.len()).filter(|&i| m1[i].to_bits() != prev[i].to_bits()).collect();
                    prop_assert_eq!(&truth, changed, "cell {} changes", k);
                }
                _ => prop_assert!(false, "cell {}: changes given for the first cell or missing for a later one", k),
            }
        }
    }

    #[test]
    fn batched_objective_equals_single_model(seed in 0u64..1000, count in 1usize..40) {
        let (op, mv) = walk(120, 0.7, 0.05, seed);
        for kind in ModelKind::ALL {
            let dim = kind.dim();
            let mut cands: Vec<f64> = (0..count * dim).map(|i| 0.05 + ((i * 37 + seed as usize) % 97) as f64 * 0.03).collect();
            for c in cands.chunks_mut(dim) {
                kind.repair(c);
            }
            let mut out = vec![0.0; count];
            Objective::new(kind, &op, &mv).eval_batch(&cands, &mut out);
            for (i, c) in cands.chunks(dim).enumerate() {
                let single = kind.build(c).unwrap().sse(&op, &mv);
                prop_assert_eq!(out[i], single, "{} candidate {}", kind, i);
            }
        }
    }
}

#[test]
fn exact_finds_true_d_without_noise() {
    let (op, mv) = walk(2000, 0.8, 0.0, 5);
    let sol = exact::solve_stenman(&op, &mv, 0.01, 10.0, &Default::default());
    assert_eq!(sol.sse, 0.0);
    assert!(sol.contains(0.8), "{:?}", sol.pieces);
}

#[test]
fn every_method_recovers_stenman_d() {
    let (op, mv) = walk(1000, 0.5, 0.0, 11);
    for method in Method::ALL {
        let r = estimate(&op, &mv, &Request::new(ModelKind::Stenman, method)).unwrap();
        let d = r.params["d"];
        assert!((d - 0.5).abs() < 0.05, "{method}: d = {d}");
        if let Some(c) = &r.certificate {
            assert!(c.estimate_is_optimal, "{method}: {c:?}");
        }
    }
}

#[test]
fn acor_recovers_a_kano_valve() {
    let s = Signal::Sine {
        amplitude: 10.0,
        period: 50.0,
        offset: 50.0,
    };
    let truth = Model::Kano(Kano { s: 4.0, j: 1.0 });
    let data = simulate_open_loop(&truth, &s, 0.5, 600, 0.0, 0).unwrap();
    let mut req = Request::new(ModelKind::Kano, Method::AcoR);
    req.seed = 3;
    let r = estimate(&data.op, &data.mv, &req).unwrap();
    assert!((r.params["S"] - 4.0).abs() < 0.3, "{:?}", r.params);
    assert!((r.params["J"] - 1.0).abs() < 0.3, "{:?}", r.params);
}

#[test]
fn random_methods_are_reproducible_from_the_seed() {
    let (op, mv) = walk(800, 1.2, 0.1, 2);
    for method in [Method::Aco, Method::AcoR] {
        let mut req = Request::new(ModelKind::He, method);
        req.seed = 42;
        req.trace = true;
        let a = estimate(&op, &mv, &req).unwrap();
        let b = estimate(&op, &mv, &req).unwrap();
        assert_eq!(a.params, b.params);
        assert_eq!(a.trace, b.trace);
        assert_eq!(a.evaluations, b.evaluations);
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    // large enough that batches are spread over threads
    let (op, mv) = walk(6000, 0.9, 0.1, 8);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut out = Vec::new();
            for (kind, method) in [
                (ModelKind::Stenman, Method::Grid),
                (ModelKind::Stenman, Method::Exact),
                (ModelKind::He, Method::Grid),
                (ModelKind::Kano, Method::AcoR),
            ] {
                let mut req = Request::new(kind, method);
                req.grid.points = 400;
                req.acor.iterations = 30;
                let r = estimate(&op, &mv, &req).unwrap();
                out.push((r.params, r.sse));
            }
            out
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn bad_requests_are_refused() {
    let (op, mv) = walk(100, 0.5, 0.0, 1);
    let mut req = Request::new(ModelKind::Stenman, Method::Grid);
    req.bounds = Some(vec![(-1.0, 2.0)]);
    assert!(estimate(&op, &mv, &req)
        .unwrap_err()
        .to_string()
        .contains("negative"));
    req.bounds = Some(vec![(2.0, 1.0)]);
    assert!(estimate(&op, &mv, &req)
        .unwrap_err()
        .to_string()
        .contains("reversed"));
    let req = Request::new(ModelKind::Kano, Method::Exact);
    assert!(estimate(&op, &mv, &req).is_err());
    let req = Request::new(ModelKind::Stenman, Method::Exact);
    assert!(estimate(&op[..5], &mv[..5], &req)
        .unwrap_err()
        .to_string()
        .contains("at least 10"));
    assert!(estimate(&[1.0; 20], &[1.0; 20], &req)
        .unwrap_err()
        .to_string()
        .contains("constant"));
    let mut nan = mv.clone();
    nan[7] = f64::NAN;
    assert!(estimate(&op, &nan, &req)
        .unwrap_err()
        .to_string()
        .contains("sample 7"));
    // a method's setting is named as in its settings, with the value: no front end's flag
    let mut req = Request::new(ModelKind::Stenman, Method::Aco);
    req.aco.ants = 0;
    let e = estimate(&op, &mv, &req).unwrap_err().to_string();
    assert_eq!(e, "aco ants must be at least 1, got 0");
    let mut req = Request::new(ModelKind::Kano, Method::AcoR);
    req.acor.q = 0.0;
    let e = estimate(&op, &mv, &req).unwrap_err().to_string();
    assert_eq!(e, "aco-r q must be a finite number > 0, got 0");
}

#[test]
fn the_paper_reproduces_with_every_seed_optimal() {
    let rep = reproduce_paper(&PaperSetup::default());
    assert_eq!(rep.cases.len(), 2);
    for c in &rep.cases {
        assert!(
            c.true_d_inside,
            "true d {} outside {:?}",
            c.true_d, c.interval
        );
        assert_eq!(
            c.inside, 20,
            "d = {}: {:?} vs {:?}",
            c.true_d, c.estimates, c.interval
        );
        assert_eq!(c.traces.len(), 20);
        assert_eq!(c.traces[0].len(), 100);
    }
    assert!((rep.cases[0].mean - 0.2).abs() < 0.01);
}
