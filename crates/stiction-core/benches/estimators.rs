//! Estimator benchmarks on the paper's case and a long noisy random walk.
//! Run: cargo bench -p stiction-core --bench estimators
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use stiction_core::estimate::{estimate, exact, Method, Request};
use stiction_core::models::{Model, ModelKind, Stenman};
use stiction_core::reproduce::PaperSetup;
use stiction_core::sim::{simulate_open_loop, LoopData, Signal};

fn paper_case(d: f64) -> LoopData {
    let s = PaperSetup::default();
    simulate_open_loop(
        &Model::Stenman(Stenman { d }),
        &s.signal,
        s.ts,
        s.samples,
        0.0,
        0,
    )
    .unwrap()
}

fn random_walk(n: usize) -> LoopData {
    let walk = Signal::RandomWalk {
        step_std: 0.1,
        offset: 0.0,
        seed: 3,
    };
    simulate_open_loop(&Model::Stenman(Stenman { d: 0.5 }), &walk, 1.0, n, 0.05, 3).unwrap()
}

fn request(method: Method) -> Request {
    let mut r = Request::new(ModelKind::Stenman, method);
    r.bounds = Some(vec![(0.01, 10.0)]);
    r.certify = false;
    r
}

fn benches(c: &mut Criterion) {
    let paper = paper_case(0.5);
    let mut g = c.benchmark_group("paper_case_1001");
    for method in [Method::Aco, Method::AcoR, Method::Grid, Method::Exact] {
        let req = request(method);
        g.bench_function(method.name(), |b| {
            b.iter(|| estimate(black_box(&paper.op), black_box(&paper.mv), &req).unwrap())
        });
    }
    g.finish();

    let walk = random_walk(100_000);
    let mut g = c.benchmark_group("random_walk_100k_noise_0.05");
    g.sample_size(10);
    g.bench_function("exact", |b| {
        b.iter(|| {
            exact::solve_stenman(
                black_box(&walk.op),
                black_box(&walk.mv),
                0.01,
                10.0,
                &Default::default(),
            )
        })
    });
    g.finish();
}

criterion_group!(estimators, benches);
criterion_main!(estimators);
