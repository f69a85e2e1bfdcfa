//! Diagnosis benchmarks. Run: cargo bench -p stiction-core --bench diagnose
use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use stiction_core::diagnose::{diagnose, DiagnoseRequest, LoopRecord};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::ClosedLoop;

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("diagnose");
    g.sample_size(10);
    for (name, d) in [("sticky", 2.0), ("healthy", 0.0)] {
        for n in [2000, 10_000] {
            let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d }));
            cl.samples = n;
            cl.noise = 0.05;
            cl.seed = 7;
            let data = cl.run().unwrap();
            let rec = LoopRecord {
                op: &data.op,
                pv: &data.pv,
                sp: Some(&data.sp),
                time: Some(&data.t),
                auto: None,
            };
            let req = DiagnoseRequest::default();
            g.bench_function(format!("{name}_{n}"), |b| {
                b.iter(|| diagnose(black_box(&rec), &req).unwrap())
            });
            let indices_only = DiagnoseRequest {
                quantify: false,
                ..DiagnoseRequest::default()
            };
            g.bench_function(format!("{name}_{n}_without_quantify"), |b| {
                b.iter(|| diagnose(black_box(&rec), &indices_only).unwrap())
            });
        }
    }
    g.finish();
}

criterion_group!(diagnose_benches, benches);
criterion_main!(diagnose_benches);
