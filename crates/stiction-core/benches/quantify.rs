//! Closed-loop quantification benchmarks. Run: cargo bench -p stiction-core --bench quantify
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use stiction_core::estimate::Method;
use stiction_core::models::{Model, ModelKind, Stenman};
use stiction_core::quantify::{quantify, QuantifyRequest};
use stiction_core::sim::ClosedLoop;

fn sticky_loop(samples: usize) -> (Vec<f64>, Vec<f64>) {
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 1.0 }));
    cl.samples = samples;
    cl.noise = 0.05;
    cl.seed = 7;
    let d = cl.run().unwrap();
    (d.op, d.pv)
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("quantify");
    g.sample_size(10);
    for n in [2000, 10_000] {
        let (op, pv) = sticky_loop(n);
        let req = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
        g.bench_function(format!("stenman_exact_{n}"), |b| {
            b.iter(|| quantify(black_box(&op), black_box(&pv), &req).unwrap())
        });
        // with the valve's start estimated (the record cut 23 samples in, so it matters)
        let mut start = req.clone();
        start.estimate_start = true;
        g.bench_function(format!("stenman_exact_estimate_start_{n}"), |b| {
            b.iter(|| quantify(black_box(&op[23..]), black_box(&pv[23..]), &start).unwrap())
        });
        // the baseline: every cell of the whole record
        let mut full = req.clone();
        full.staged = false;
        g.bench_function(format!("stenman_exact_full_{n}"), |b| {
            b.iter(|| quantify(black_box(&op), black_box(&pv), &full).unwrap())
        });
        let mut quick = full.clone();
        quick.full_partition = false;
        g.bench_function(format!("stenman_exact_quick_{n}"), |b| {
            b.iter(|| quantify(black_box(&op), black_box(&pv), &quick).unwrap())
        });
    }
    let (op, pv) = sticky_loop(2000);
    let req = QuantifyRequest::new(ModelKind::Kano, Method::AcoR);
    g.bench_function("kano_aco_r_2000", |b| {
        b.iter(|| quantify(black_box(&op), black_box(&pv), &req).unwrap())
    });
    g.finish();
}

criterion_group!(quantify_benches, benches);
criterion_main!(quantify_benches);
