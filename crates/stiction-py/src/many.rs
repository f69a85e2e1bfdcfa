//! `diagnose_many`: a fleet of loops in one call, in parallel on a pool of its own (rayon) with
//! the GIL released; one fleet row per loop, ranked by the core's fleet ranking (as `stiction
//! batch` ranks). A loop that fails is a `failed` row with its reason; the batch goes on.

use crate::diagnose::{run, Settings};
use crate::{bad, json, slice, slice_bool};
use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use rayon::prelude::*;
use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use stiction_core::fleet::{self, Row};
use stiction_core::record::Signals;

/// Every loop's signals, concatenated: loop `i` is samples `starts[i]..starts[i + 1]`.
struct Fleet<'a> {
    op: Cow<'a, [f64]>,
    pv: Cow<'a, [f64]>,
    sp: Option<Cow<'a, [f64]>>,
    mv: Option<Cow<'a, [f64]>>,
    auto: Option<Cow<'a, [bool]>>,
    time: Option<Cow<'a, [f64]>>,
}

/// Samples `a..b` of a signal the loops may not have.
fn part<'s, T: Clone>(v: &'s Option<Cow<'_, [T]>>, a: usize, b: usize) -> Option<Cow<'s, [T]>> {
    v.as_deref().map(|v| Cow::Borrowed(&v[a..b]))
}

impl Fleet<'_> {
    fn signals(&self, a: usize, b: usize) -> Signals<'_> {
        Signals {
            op: Cow::Borrowed(&self.op[a..b]),
            pv: Cow::Borrowed(&self.pv[a..b]),
            sp: part(&self.sp, a, b),
            mv: part(&self.mv, a, b),
            auto: part(&self.auto, a, b),
            time: part(&self.time, a, b),
        }
    }
}

/// A progress line on standard error, at most once a second.
struct Progress {
    on: bool,
    total: usize,
    done: AtomicUsize,
    last: Mutex<Instant>,
}

impl Progress {
    fn tick(&self) {
        let done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if !self.on {
            return;
        }
        if let Ok(mut last) = self.last.try_lock() {
            if last.elapsed() >= Duration::from_secs(1) || done == self.total {
                *last = Instant::now();
                eprint!("\rdiagnose_many: {done} of {} loops", self.total);
            }
        }
    }

    fn finish(&self) {
        if self.on {
            eprintln!("\rdiagnose_many: {} of {} loops", self.total, self.total);
        }
    }
}

/// One loop's row; never panics through (a bug in one loop is that loop's failure).
fn row(fleet: &Fleet, id: &str, source: &str, (a, b): (usize, usize), s: &Settings) -> Row {
    let done =
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(fleet.signals(a, b), s)));
    match done {
        Ok(Ok((d, _))) => Row::from_diagnosis(id, source, &d),
        Ok(Err(why)) => Row::failed(id, source, format!("{source}: {why}")),
        Err(_) => Row::failed(
            id,
            source,
            format!("{source}: stopped on an internal error (a bug: please report it with this loop's data)"),
        ),
    }
}

/// Diagnose many loops: the ranked fleet rows as JSON (`stiction batch`'s summary rows).
/// `ids[i]` and `sources[i]` name loop `i`, whose samples are `starts[i]..starts[i + 1]` of
/// every signal. `threads`: the pool's size (default: one per core). `failed`: loops the front
/// end could not read, with the reason (a `failed` row each).
#[pyfunction]
#[pyo3(signature = (ids, sources, starts, op, pv, sp=None, mv=None, auto=None, time=None,
    ts=None, integrating=None, quantify=true, op_range=(0.0, 100.0), estimate_start=false, thorough=false,
    time_name=None, threads=None, progress=false, failed=None, tags=None))]
#[allow(clippy::too_many_arguments)]
pub fn diagnose_many(
    py: Python<'_>,
    ids: Vec<String>,
    sources: Vec<String>,
    starts: Vec<usize>,
    op: PyReadonlyArray1<'_, f64>,
    pv: PyReadonlyArray1<'_, f64>,
    sp: Option<PyReadonlyArray1<'_, f64>>,
    mv: Option<PyReadonlyArray1<'_, f64>>,
    auto: Option<PyReadonlyArray1<'_, bool>>,
    time: Option<PyReadonlyArray1<'_, f64>>,
    ts: Option<f64>,
    integrating: Option<bool>,
    quantify: bool,
    op_range: (f64, f64),
    estimate_start: bool,
    thorough: bool,
    time_name: Option<String>,
    threads: Option<usize>,
    progress: bool,
    failed: Option<HashMap<usize, String>>,
    tags: Option<Vec<String>>,
) -> PyResult<String> {
    let failed = failed.unwrap_or_default();
    let fleet = Fleet {
        op: slice(&op),
        pv: slice(&pv),
        sp: sp.as_ref().map(slice),
        mv: mv.as_ref().map(slice),
        auto: auto.as_ref().map(slice_bool),
        time: time.as_ref().map(slice),
    };
    let n = fleet.op.len();
    let ok_starts = starts.len() == ids.len() + 1
        && sources.len() == ids.len()
        && starts.windows(2).all(|w| w[0] <= w[1])
        && starts.last().is_some_and(|&e| e <= n);
    if !ok_starts {
        return Err(bad(
            "starts must hold one offset per loop and the end, increasing within the signals",
        ));
    }
    let settings = Settings {
        ts,
        integrating,
        tags: tags.unwrap_or_default(),
        window: None,
        quantify,
        op_range: [op_range.0, op_range.1],
        estimate_start,
        thorough,
        time_name: time_name.unwrap_or_else(|| "time".into()),
    };
    if [fleet.pv.len()]
        .into_iter()
        .chain(fleet.sp.as_ref().map(|v| v.len()))
        .chain(fleet.mv.as_ref().map(|v| v.len()))
        .chain(fleet.auto.as_ref().map(|v| v.len()))
        .chain(fleet.time.as_ref().map(|v| v.len()))
        .any(|len| len != n)
    {
        return Err(bad("every signal must have as many samples as op"));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .thread_name(|i| format!("stiction-worker{i}"))
        .build()
        .map_err(|e| bad(format!("threads: cannot start the worker threads: {e}")))?;
    let progress = Progress {
        on: progress,
        total: ids.len(),
        done: AtomicUsize::new(0),
        last: Mutex::new(Instant::now()),
    };
    let mut rows: Vec<Row> = py.detach(|| {
        pool.install(|| {
            (0..ids.len())
                .into_par_iter()
                .map(|i| {
                    let r = match failed.get(&i) {
                        // a cell the front end could not read fails its loop only
                        Some(why) => Row::failed(&ids[i], &sources[i], why.clone()),
                        None => row(
                            &fleet,
                            &ids[i],
                            &sources[i],
                            (starts[i], starts[i + 1]),
                            &settings,
                        ),
                    };
                    progress.tick();
                    r
                })
                .collect()
        })
    });
    progress.finish();
    fleet::rank(&mut rows);
    let shared = fleet::same_period(&rows);
    let rows: Vec<ManyRow> = rows
        .iter()
        .zip(shared)
        .map(|(row, same_period_loops)| ManyRow {
            row,
            same_period_loops,
        })
        .collect();
    json(&rows)
}

/// A fleet row with the other loops of the call that oscillate at its period, as `stiction
/// batch`'s summary has it.
#[derive(serde::Serialize)]
struct ManyRow<'a> {
    #[serde(flatten)]
    row: &'a Row,
    same_period_loops: usize,
}
