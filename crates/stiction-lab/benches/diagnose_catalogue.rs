//! The diagnosis on a catalogue loop where the hidden-valve family runs, in criterion's
//! `diagnose` group beside the core's own (`cargo bench -p stiction-core --bench diagnose`). Run:
//! cargo bench -p stiction-lab --bench diagnose_catalogue

use criterion::{criterion_group, criterion_main, Criterion};
use std::hint::black_box;
use stiction_core::diagnose::{diagnose, DiagnoseRequest};
use stiction_lab::catalogue_loop;

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("diagnose");
    g.sample_size(10);
    // --thorough where the hidden-valve family runs: a fast loop of the catalogue's calibration
    // set whose valve slips between the samples (fast-c-0007; the families without it call it
    // no_stiction), beside the same loop judged by default
    let l = stiction_lab::catalogue::find("fast-c-0007").unwrap();
    let rec = catalogue_loop::record(&l);
    let catalogue = |thorough| DiagnoseRequest {
        quantify: false,
        thorough,
        ..catalogue_loop::request(&l)
    };
    for (name, thorough) in [
        ("hidden_valve_2000_without_quantify", false),
        ("hidden_valve_2000_thorough_without_quantify", true),
    ] {
        let req = catalogue(thorough);
        g.bench_function(name, |b| {
            b.iter(|| diagnose(black_box(&rec), &req).unwrap())
        });
    }
    g.finish();
}

criterion_group!(diagnose_benches, benches);
criterion_main!(diagnose_benches);
