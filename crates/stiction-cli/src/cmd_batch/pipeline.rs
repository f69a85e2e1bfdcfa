//! The pipeline: a reader thread streams jobs over a bounded channel into a rayon pool; each
//! worker reads its loop, checks `--resume`'s earlier result, diagnoses, writes
//! `loops/<id>.json` (and a report) and sends back a small row; a collector thread keeps the
//! rows, shows the progress and rewrites the summary every 2 s. When the batch is asked to stop,
//! the reader stops reading and the workers skip the jobs not yet started.

use super::html;
use super::inputs::{self, Ids, Inputs, Job, JobData};
use super::layout::LoopSpec;
use super::progress::Progress;
use super::resume::{self, Earlier, Input, LoopJsonRef, LoopSettings};
use super::stop::{Reason, Stop};
use super::summary::{self, Fate, Row, SourceStatus};
use crate::atomic::write_atomic;
use crate::data::Table;
use crate::loop_file::{Columns, LoopFile};
use anyhow::{Context, Result};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};
use stiction_core::diagnose::Diagnosis;
use stiction_core::fleet;
use stiction_report::fleet::Spark;
use stiction_report::PageOptions;

/// What every worker needs.
pub struct Ctx {
    pub flags: Columns,
    pub quantify: bool,
    pub out: PathBuf,
    pub loops_dir: PathBuf,
    pub reports_dir: Option<PathBuf>,
    pub resume: bool,
    pub stop: Arc<Stop>,
}

/// Diagnose every loop the inputs hold; the rows of the loops done and the ids handed out.
pub fn diagnose_all(inputs: Inputs, ctx: &Ctx, threads: usize) -> Result<(Vec<Row>, Ids)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("batch-worker{i}"))
        .build()
        .context("cannot start the worker threads")?;
    // a few loops read ahead per worker keep the workers busy; more would only hold memory (a
    // long-format loop's rows wait in the channel)
    let (job_tx, job_rx) = mpsc::sync_channel::<Job>(2 * threads + 2);
    let (row_tx, row_rx) = mpsc::channel::<(Row, u64)>();
    let progress = Progress::new(inputs.known_loops(), inputs.total_bytes);
    let flags = ctx.flags.clone();
    let stop = Arc::clone(&ctx.stop);
    let reader = std::thread::Builder::new()
        .name("batch-reader".into())
        .spawn(move || inputs::stream(inputs, flags, job_tx, &stop))
        .context("cannot start the reader thread")?;
    let out = ctx.out.clone();
    let with_index = ctx.reports_dir.is_some();
    let stop = Arc::clone(&ctx.stop);
    let collector = std::thread::Builder::new()
        .name("batch-collector".into())
        .spawn(move || collect(row_rx, progress, &out, with_index, &stop))
        .context("cannot start the collector thread")?;
    pool.install(|| {
        job_rx
            .into_iter()
            .par_bridge()
            .for_each_with(row_tx, |tx, job| {
                let (id, source, weight) = (job.id.clone(), job.source.clone(), job.weight);
                // a bug in one loop's path is that loop's failure, never the batch's
                let row = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    process(job, ctx)
                }))
                .unwrap_or_else(|_| {
                    Some(Row::failed(
                        &id,
                        &source,
                        format!("{source}: stopped on an internal error (a bug: please report it with this file)"),
                    ))
                });
                if let Some(row) = row {
                    let _ = tx.send((row, weight));
                }
            })
    });
    let ids = reader.join().expect("the reader thread does not panic");
    let rows = collector
        .join()
        .expect("the collector thread does not panic");
    Ok((rows, ids))
}

/// Keep the rows as they come, show the progress, rewrite the summary every 2 s, and say so
/// when a signal asks the batch to stop.
fn collect(
    rows_in: mpsc::Receiver<(Row, u64)>,
    mut progress: Progress,
    out: &Path,
    with_index: bool,
    stop: &Stop,
) -> Vec<Row> {
    let mut rows: Vec<Row> = Vec::new();
    let mut last_write = Instant::now();
    let mut warned = false;
    let mut stopping = false;
    loop {
        let (row, weight) = match rows_in.recv_timeout(Duration::from_millis(100)) {
            Ok(x) => x,
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if !stopping && matches!(stop.reason(), Some(Reason::Signal(_))) {
                    stopping = true;
                    progress.println(
                        "batch: stopping: the loops under way finish, then the summary of what is done is written (a second Ctrl-C stops at once)",
                    );
                }
                continue;
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        };
        rows.push(row);
        progress.tick(weight);
        if last_write.elapsed() >= Duration::from_secs(2) {
            last_write = Instant::now();
            let written = summary::write(out, &mut rows, false).and_then(|()| {
                if with_index {
                    html::write_index(out, &rows, false)
                } else {
                    Ok(())
                }
            });
            if let Err(e) = written {
                if !warned {
                    progress.println(&format!("warning: the interim summary: {e:#}"));
                    warned = true;
                }
            }
        }
    }
    progress.finish();
    rows
}

/// A loop's input, read: the bytes of its file, its rows of a long-format file, or its share of
/// a wide file's table.
enum Loaded {
    Bytes(PathBuf, Vec<u8>),
    Rows {
        file: PathBuf,
        csv: Vec<u8>,
        lines: Vec<u64>,
    },
    Table(Arc<Table>),
}

/// Read a loop's input and stamp it (path, size, time, hash of the bytes read).
fn load(data: JobData, source: &str, settings: LoopSettings) -> Result<(Input, Loaded), String> {
    match data {
        JobData::File(path) => match std::fs::read(&path) {
            Ok(bytes) => Ok((
                Input::of(source, &path, &bytes, settings),
                Loaded::Bytes(path, bytes),
            )),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(format!(
                "{}: no such file (it went away during the batch)",
                path.display()
            )),
            Err(e) => Err(format!("{}: cannot be read: {e}", path.display())),
        },
        JobData::Rows { file, csv, lines } => Ok((
            Input::of(source, &file, &csv, settings),
            Loaded::Rows { file, csv, lines },
        )),
        JobData::Wide { file, table, hash } => {
            let mut input = Input::of(source, &file, &[], settings);
            input.hash = hash;
            Ok((input, Loaded::Table(table)))
        }
        JobData::Fail(why) => Err(why),
    }
}

/// "line N" in a message about a loop of a long-format file (read as a small CSV: header on line
/// 1, row k on line k + 2) becomes the line of the long file.
pub fn remap_lines(msg: &str, lines: &[u64]) -> String {
    let mut out = String::with_capacity(msg.len());
    let mut rest = msg;
    while let Some(i) = rest.find("line ") {
        out.push_str(&rest[..i + 5]);
        rest = &rest[i + 5..];
        let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
        let mapped = rest[..digits]
            .parse::<usize>()
            .ok()
            .and_then(|n| n.checked_sub(2))
            .and_then(|k| lines.get(k));
        match mapped {
            Some(line) => out.push_str(&line.to_string()),
            None => out.push_str(&rest[..digits]),
        }
        rest = &rest[digits..];
    }
    out.push_str(rest);
    out
}

/// Read one loop with `data::Table` and `Columns::read` (shared with `diagnose`); a long-format
/// loop's messages are pointed at the long file's lines.
fn read_loop(loaded: Loaded, columns: &Columns) -> Result<LoopFile, String> {
    match loaded {
        Loaded::Bytes(path, bytes) => Table::parse(&path, &bytes)
            .and_then(|t| columns.read(&t))
            .map_err(|e| format!("{e:#}")),
        Loaded::Rows { file, csv, lines } => Table::parse(&file, &csv)
            .and_then(|t| columns.read(&t))
            .map_err(|e| remap_lines(&format!("{e:#}"), &lines)),
        Loaded::Table(table) => columns.read(&table).map_err(|e| format!("{e:#}")),
    }
}

/// The loop's full report (`stiction report`), with a link back to the fleet's index page.
fn render_report(loop_id: &str, lf: &LoopFile, d: &Diagnosis, columns: &Columns) -> Result<String> {
    let names = columns.names();
    let reading = lf.reading_notes();
    let options = PageOptions {
        columns: Some(&names),
        back_link: Some(("../index.html".into(), "all loops".into())),
        reading: &reading,
    };
    stiction_report::loop_page(loop_id, &lf.data(), d, &options)
}

/// Diagnose one loop: never panics, never fails the batch; a loop that cannot be read or
/// diagnosed is a `failed` row with the reason. `None` when the batch stopped before the loop
/// started. A file that cannot be written stops the batch (the disk is full, or gone).
fn process(job: Job, ctx: &Ctx) -> Option<Row> {
    if ctx.stop.requested() {
        return None;
    }
    let Job {
        id,
        source,
        data,
        spec,
        ..
    } = job;
    let LoopSpec { columns } = spec;
    let settings = LoopSettings::new(&columns, ctx.quantify);
    let (input, loaded) = match load(data, &source, settings) {
        Ok(x) => x,
        Err(why) => return Some(Row::failed(&id, &source, why)),
    };
    let json_path = ctx.loops_dir.join(format!("{id}.json"));
    let report_path = ctx
        .reports_dir
        .as_ref()
        .map(|d| d.join(format!("{id}.html")));
    let fate = match ctx.resume.then(|| resume::earlier(&json_path)) {
        None | Some(Earlier::None) => Fate::New,
        Some(Earlier::Unusable) => Fate::Redone,
        Some(Earlier::Found(old)) => {
            let same = old.input.as_ref().is_some_and(|i| input.same_loop(i));
            if same && report_path.as_ref().is_none_or(|p| p.exists()) {
                let row = fleet::Row::from_diagnosis(&id, &source, &old.diagnosis);
                let mut row = Row::new(row, Fate::Kept);
                row.report = report_path.is_some();
                // the index shows the loop's sparkline: read the loop again (no diagnosis)
                if row.report {
                    row.spark = read_loop(loaded, &columns)
                        .ok()
                        .map(|lf| Spark::of(&lf.pv, &lf.op));
                }
                return Some(row);
            }
            Fate::Redone
        }
    };
    let lf = match read_loop(loaded, &columns) {
        Ok(lf) => lf,
        Err(why) => return Some(Row::failed(&id, &source, why)),
    };
    let mut req = columns.request(lf.ts);
    req.quantify = ctx.quantify;
    // the request is the loop's own (its sampling time): checked once, then run
    let d = match req
        .check()
        .and_then(|req| crate::diagnosed::diagnose(&lf.record(), &req))
    {
        Ok(d) => d,
        Err(e) => return Some(Row::failed(&id, &source, format!("{source}: {e}"))),
    };
    let mut row = Row::new(fleet::Row::from_diagnosis(&id, &source, &d), fate);
    if report_path.is_some() {
        row.spark = Some(Spark::of(&lf.pv, &lf.op));
    }
    let saved = serde_json::to_vec_pretty(&LoopJsonRef {
        input: &input,
        diagnosis: &d,
    })
    .map_err(anyhow::Error::from)
    .and_then(|bytes| write_atomic(&json_path, &bytes));
    if let Err(e) = saved {
        ctx.stop.fault(format!("{e:#}"));
        return Some(Row::failed(
            &id,
            &source,
            format!("the diagnosis was not saved: {e:#}"),
        ));
    }
    if let Some(path) = report_path {
        match render_report(&id, &lf, &d, &columns) {
            Ok(html) => match write_atomic(&path, html.as_bytes()) {
                Ok(()) => row.report = true,
                Err(e) => {
                    ctx.stop.fault(format!("{e:#}"));
                    row.fleet.error = format!("the report was not written: {e:#}");
                }
            },
            Err(e) => row.fleet.error = format!("the report was not written: {e:#}"),
        }
    }
    test_gate();
    Some(row)
}

/// Tests hold a batch after its first loops, to act (a signal, a second run) while it surely
/// runs: in debug builds only, with `STICTION_TEST_GATE=FILE` each worker waits after a loop
/// until FILE exists.
fn test_gate() {
    #[cfg(debug_assertions)]
    if let Some(gate) = std::env::var_os("STICTION_TEST_GATE") {
        let gate = PathBuf::from(gate);
        while !gate.exists() {
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

/// `--resume`: the loops of an earlier run whose input is no longer among the inputs, kept and
/// marked `vanished` (the source column says where they came from).
pub fn vanished(loops_dir: &Path, ids: &Ids) -> Vec<Row> {
    let Ok(entries) = std::fs::read_dir(loops_dir) else {
        return Vec::new();
    };
    let mut rows = Vec::new();
    for e in entries.filter_map(|e| e.ok()) {
        let path = e.path();
        let Some(id) = path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("json"))
            .then(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()))
            .flatten()
        else {
            continue;
        };
        if ids.contains(&id) || id.starts_with('.') {
            continue;
        }
        if let Earlier::Found(old) = resume::earlier(&path) {
            let source = old
                .input
                .as_ref()
                .map_or(String::new(), |i| i.source.clone());
            let mut row = Row::new(
                fleet::Row::from_diagnosis(&id, &source, &old.diagnosis),
                Fate::Kept,
            );
            row.source_status = SourceStatus::Vanished;
            rows.push(row);
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_of_a_loop_map_to_the_long_file() {
        let lines = [100, 101, 105];
        assert_eq!(
            remap_lines("x.csv: line 4, column 'op': 'a' is not a number", &lines),
            "x.csv: line 105, column 'op': 'a' is not a number"
        );
        assert_eq!(
            remap_lines("ends at line 2 with 0 values; line 9", &lines),
            "ends at line 100 with 0 values; line 9"
        );
    }
}
