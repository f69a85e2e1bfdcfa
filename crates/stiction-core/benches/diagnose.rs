//! Diagnosis benchmarks on loops of the public simulation. Run: cargo bench -p stiction-core --bench
//! diagnose (the catalogue's hidden-valve loop: `cargo bench -p stiction-lab --bench
//! diagnose_catalogue`).

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use std::hint::black_box;
use stiction_core::diagnose::{diagnose, DiagnoseRequest, LoopRecord};
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, Pi, Process};

/// `diagnose` of `rec` under each request, as a criterion function of the request's name.
fn bench_each(
    g: &mut BenchmarkGroup<WallTime>,
    rec: &LoopRecord,
    named: &[(String, DiagnoseRequest)],
) {
    for (name, req) in named {
        g.bench_function(name, |b| b.iter(|| diagnose(black_box(rec), req).unwrap()));
    }
}

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("diagnose");
    g.sample_size(10);
    for (name, d) in [("sticky", 2.0), ("healthy", 0.0)] {
        for n in [2000, 10_000, 86_400] {
            let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d }));
            cl.samples = n;
            cl.noise = 0.05;
            cl.seed = 7;
            let data = cl.run().unwrap();
            let rec = LoopRecord {
                op: &data.op,
                pv: &data.pv,
                sp: Some(&data.sp),
                mv: None,
                time: Some(&data.t),
                auto: None,
            };
            let mut named = vec![
                (format!("{name}_{n}"), DiagnoseRequest::default()),
                (
                    format!("{name}_{n}_without_quantify"),
                    DiagnoseRequest {
                        quantify: false,
                        ..DiagnoseRequest::default()
                    },
                ),
            ];
            if n == 86_400 {
                // a day at 1 s, beside the same record judged sample by sample (no means, no
                // part): what averaging at the loop's time scale saves
                let mut every = DiagnoseRequest::default();
                every.settings.averaging.min_samples = usize::MAX;
                every.settings.averaging.max_time_scales = usize::MAX;
                named.push((format!("{name}_{n}_every_sample"), every));
            }
            if n == 2000 {
                // --thorough: the hidden-valve family besides (it reports; the model does not
                // read it)
                named.push((
                    format!("{name}_{n}_thorough_without_quantify"),
                    DiagnoseRequest {
                        quantify: false,
                        thorough: true,
                        ..DiagnoseRequest::default()
                    },
                ));
            }
            bench_each(&mut g, &rec, &named);
        }
    }
    // the loop family's case (issue 14): a fast loop, Ts = 2 s, a 2 % band, a two-minute cycle
    let mut cl = ClosedLoop::new(Model::Stenman(Stenman { d: 2.0 }));
    cl.process = Process::Foptd {
        k: 1.0,
        tau: 12.0,
        delay: 30.0,
    };
    cl.pi = Pi {
        kc: 1.3,
        ti: 1500.0,
    };
    cl.ts = 2.0;
    cl.noise = 0.05;
    cl.seed = 3;
    cl.op0 = 41.5;
    let data = cl.run().unwrap();
    let rec = LoopRecord {
        op: &data.op,
        pv: &data.pv,
        sp: Some(&data.sp),
        mv: None,
        time: Some(&data.t),
        auto: None,
    };
    let fast = |quantify| DiagnoseRequest {
        ts: 2.0,
        quantify,
        ..DiagnoseRequest::default()
    };
    bench_each(
        &mut g,
        &rec,
        &[
            ("fast_sticky_2000".into(), fast(true)),
            ("fast_sticky_2000_without_quantify".into(), fast(false)),
        ],
    );
    g.finish();
    levels_bench(c);
}

/// The stick-slip family's segmentation of PV into levels (PELT) on 2,000 samples: noise about
/// one level (where PELT prunes least) and a staircase of forty levels.
fn levels_bench(c: &mut Criterion) {
    use stiction_core::diagnose::evidence::stick_slip::steps::levels;
    let mut g = c.benchmark_group("levels");
    let mut x: u64 = 7;
    let noise: Vec<f64> = (0..2000)
        .map(|_| {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.2
        })
        .collect();
    let stairs: Vec<f64> = noise
        .iter()
        .enumerate()
        .map(|(i, v)| v + ((i / 50) % 3) as f64)
        .collect();
    let beta = 3.0 * 0.06f64.powi(2) * 2000f64.ln();
    for (name, pv) in [("noise_2000", &noise), ("stairs_2000", &stairs)] {
        g.bench_function(name, |b| b.iter(|| levels(black_box(pv), beta, 2000)));
    }
    g.finish();
}

criterion_group!(diagnose_benches, benches);
criterion_main!(diagnose_benches);
