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
