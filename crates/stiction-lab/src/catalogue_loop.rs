//! A catalogue loop ([`crate::catalogue`]) as `stiction diagnose loop.csv --sp sp`
//! reads it: the setpoint and the time column given, the default request otherwise (the loop's
//! kind read off the record, as for a CSV whose columns name no tag).

use crate::catalogue::BenchmarkLoop;
use stiction_core::diagnose::{DiagnoseRequest, LoopRecord};

/// The loop's record: op, pv, sp and time (no valve position).
pub fn record(l: &BenchmarkLoop) -> LoopRecord<'_> {
    let d = &l.data;
    LoopRecord {
        op: &d.op,
        pv: &d.pv,
        sp: Some(&d.sp),
        mv: None,
        time: Some(&d.t),
        auto: None,
    }
}

/// The request the CLI would build for it.
pub fn request(l: &BenchmarkLoop) -> DiagnoseRequest {
    DiagnoseRequest {
        ts: l.ts(),
        ..DiagnoseRequest::default()
    }
}

/// The loop as the CSV file `stiction diagnose` reads: the columns `t,sp,op,mv,pv`.
pub fn csv(l: &BenchmarkLoop) -> String {
    use std::fmt::Write as _;
    let d = &l.data;
    let mut csv = String::with_capacity(d.t.len() * 60);
    csv.push_str("t,sp,op,mv,pv\n");
    for i in 0..d.t.len() {
        let _ = writeln!(
            csv,
            "{},{},{},{},{}",
            d.t[i], d.sp[i], d.op[i], d.mv[i], d.pv[i]
        );
    }
    csv
}
