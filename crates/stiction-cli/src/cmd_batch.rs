//! `stiction batch`: diagnose many loops in parallel and rank them.
//!
//! Inputs are streamed: a reader thread turns the INPUT arguments into one job per loop (a
//! long-format file is read once, front to back, one loop at a time) and hands them over a bounded
//! channel to a rayon pool; each worker reads its loop, diagnoses it, writes `loops/<id>.json`
//! (and a report) and sends back a small summary row. Only those rows are kept, so memory stays
//! flat however many loops there are. The summary is ranked with a total order (severity, verdict,
//! loop id), so it is the same for any number of threads, and rewritten every few seconds, so an
//! interrupted run loses nothing: `--resume` picks up from the `loops/<id>.json` already written.
//!
//! Loop ids: a file's stem, or the loop id cell of a long-format file, made a safe file name
//! (characters other than letters, digits and `- _ . + ~` become `_`). Ids used twice get a
//! suffix in input order (`X`, `X~2`, `X~3`), with a note; the `source` column says which is which.

mod html;
mod inputs;
mod progress;
mod summary;

use crate::cmd_diagnose::{Columns, LoopFile};
use crate::cmd_simulate::write_atomic;
use crate::data;
use anyhow::{bail, Context, Result};
use inputs::{Ids, Job, JobData};
use progress::Progress;
use rayon::prelude::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use stiction_core::diagnose::{diagnose, Diagnosis};
use summary::{Row, VERDICTS};

#[derive(clap::Args, Clone)]
#[command(
    about = "Diagnose many loops in parallel (folders, patterns, long-format files) and rank them by severity",
    after_help = "Examples:
  stiction batch plant/ -o out --sp sp
  stiction batch 'plant/*.csv' more/FIC101.csv -o out --op OP --pv PV --threads 4 --reports
  stiction batch historian.csv -o out --loop-id tag --sp SP --no-quantify
  stiction batch plant/ -o out --sp sp --resume      # after an interruption: done loops are kept

Writes OUTDIR/summary.csv and summary.json (one row per loop, ranked by severity = apparent
stiction x confidence for a stiction verdict, then verdict, then loop id), OUTDIR/loops/<id>.json
(the full diagnosis), and with --reports OUTDIR/reports/<id>.html and OUTDIR/index.html. A loop
that cannot be read is a 'failed' row with the reason; the batch goes on.
Loop ids: the file stem, or the loop id cell of a long-format file, as a safe file name; an id
used twice gets a suffix in input order (X, X~2, X~3), with a note."
)]
pub struct Args {
    /// Folders (every *.csv directly inside), file patterns such as 'plant/*.csv' (quoted), CSV
    /// files with one loop each, or long-format CSV files with a loop id column (many loops, the
    /// rows of each loop together)
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<String>,
    /// Output folder
    #[arg(short, long, value_name = "OUTDIR")]
    pub output: PathBuf,
    #[command(flatten)]
    pub columns: Columns,
    /// The column of a long-format file that names the loop of each row
    #[arg(long, default_value = "loop_id", value_name = "COL")]
    pub loop_id: String,
    /// Worker threads [default: one per CPU]
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Also write an HTML report per loop (OUTDIR/reports/<id>.html) and OUTDIR/index.html
    #[arg(long)]
    pub reports: bool,
    /// Keep the loops whose OUTDIR/loops/<id>.json exists (an interrupted run) instead of diagnosing them again
    #[arg(long)]
    pub resume: bool,
    /// Skip the closed-loop estimate of the band (faster; severity then uses the ellipse estimate)
    #[arg(long)]
    pub no_quantify: bool,
}

/// What every worker needs.
struct Ctx {
    columns: Columns,
    quantify: bool,
    out: PathBuf,
    loops_dir: PathBuf,
    reports_dir: Option<PathBuf>,
    resume: bool,
}

/// The loop's full report (`stiction report`), with a link back to the fleet's index page.
fn write_loop_report(path: &Path, loop_id: &str, lf: &LoopFile, d: &Diagnosis) -> Result<()> {
    let html = crate::cmd_report::render(loop_id, lf, d)?.replacen(
        "<main>\n",
        "<main>\n<p class=\"back\"><a href=\"../index.html\">&larr; all loops</a></p>\n",
        1,
    );
    crate::cmd_simulate::write_atomic(path, html.as_bytes())
}

/// The settings that decide a loop's diagnosis: `--resume` refuses to mix loops diagnosed with
/// different ones.
fn settings(a: &Args) -> Value {
    let c = &a.columns;
    serde_json::json!({
        "op": c.op, "pv": c.pv, "sp": c.sp, "mode": c.mode, "time": c.time, "ts": c.ts,
        "integrating": c.integrating, "quantify": !a.no_quantify, "loop_id": a.loop_id,
        "estimate_start": c.estimate_start,
    })
}

pub fn run(a: Args) -> Result<()> {
    let started = Instant::now();
    if let Some(ts) = a.columns.ts {
        if !(ts > 0.0 && ts.is_finite()) {
            bail!("--ts {ts}: the sampling time must be a positive number of seconds");
        }
    }
    let threads = match a.threads {
        Some(0) => bail!("--threads 0: give at least 1 worker thread"),
        Some(n) => n,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let mut files = inputs::expand(&a.inputs)?;
    // OUTDIR given as an input folder too: its own summary is not a loop
    if let Ok(own) = std::fs::canonicalize(a.output.join("summary.csv")) {
        files.retain(|f| std::fs::canonicalize(f).map_or(true, |c| c != own));
        if files.is_empty() {
            bail!(
                "no loop files among the inputs (only the summary.csv of {}); give the folders or files holding the loops",
                a.output.display()
            );
        }
    }
    let inputs = inputs::classify(files, &a.loop_id, &a.columns)?;
    let ctx = prepare_output(&a)?;
    let (mut rows, ids) = diagnose_all(inputs, &ctx, threads)?;
    let out = &a.output;
    summary::write(out, &mut rows, true)
        .with_context(|| format!("{}: cannot write the summary", out.display()))?;
    if a.reports {
        html::write_index(out, &rows, true)?;
    }
    for note in &ids.notes {
        eprintln!("note: {note}");
    }
    if ids.duplicates > ids.notes.len() {
        eprintln!(
            "note: {} more loop ids were used twice and got a ~N suffix (see the source column)",
            ids.duplicates - ids.notes.len()
        );
    }
    print_outcome(
        &rows,
        out,
        started.elapsed().as_secs_f64(),
        threads,
        a.reports,
    );
    Ok(())
}

/// Make OUTDIR ready: its folders, the settings of this run (checked against the earlier run's
/// with `--resume`), an empty summary so a stale one never passes for this run's.
fn prepare_output(a: &Args) -> Result<Ctx> {
    let out = &a.output;
    let shown = out.display();
    let loops_dir = out.join("loops");
    std::fs::create_dir_all(&loops_dir).with_context(|| {
        format!("{shown}: cannot create the output folder; choose a writable folder with -o OUTDIR")
    })?;
    let settings_path = out.join("batch.json");
    let settings = settings(a);
    if a.resume {
        if let Some(old) = std::fs::read(&settings_path)
            .ok()
            .and_then(|b| serde_json::from_slice::<Value>(&b).ok())
        {
            if old != settings {
                bail!(
                    "{shown}: its loops were diagnosed with other settings ({old}); resume with the same column flags and --no-quantify choice, or run without --resume to diagnose every loop again"
                );
            }
        }
    }
    write_atomic(&settings_path, &serde_json::to_vec_pretty(&settings)?).with_context(|| {
        format!("{shown}: the output folder is not writable; choose another with -o OUTDIR")
    })?;
    summary::write(out, &mut [], false)?;
    let reports_dir = a.reports.then(|| out.join("reports"));
    if let Some(dir) = &reports_dir {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
    }
    // left by an interrupted run of an earlier version
    let _ = std::fs::remove_dir_all(out.join(".batch-tmp"));
    Ok(Ctx {
        columns: a.columns.clone(),
        quantify: !a.no_quantify,
        out: out.clone(),
        loops_dir,
        reports_dir,
        resume: a.resume,
    })
}

/// The pipeline: a reader thread streams jobs over a bounded channel into the pool; a collector
/// thread keeps the rows, shows the progress and rewrites the summary every 2 s.
fn diagnose_all(inputs: inputs::Inputs, ctx: &Ctx, threads: usize) -> Result<(Vec<Row>, Ids)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("batch-worker{i}"))
        .build()
        .context("cannot start the worker threads")?;
    let (job_tx, job_rx) = mpsc::sync_channel::<Job>(4 * threads + 8);
    let (row_tx, row_rx) = mpsc::channel::<(Row, u64)>();
    let mut progress = Progress::new(inputs.known_loops(), inputs.total_bytes);
    let reader = std::thread::Builder::new()
        .name("batch-reader".into())
        .spawn(move || inputs::stream(inputs.sources, job_tx))
        .context("cannot start the reader thread")?;
    let out = ctx.out.clone();
    let with_index = ctx.reports_dir.is_some();
    let collector = std::thread::Builder::new()
        .name("batch-collector".into())
        .spawn(move || {
            let mut rows: Vec<Row> = Vec::new();
            let mut last_write = Instant::now();
            let mut warned = false;
            for (row, weight) in row_rx {
                rows.push(row);
                progress.tick(weight);
                if last_write.elapsed() >= Duration::from_secs(2) {
                    last_write = Instant::now();
                    let written = summary::write(&out, &mut rows, false).and_then(|()| {
                        if with_index {
                            html::write_index(&out, &rows, false)
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
        })
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
                    Row::failed(
                        &id,
                        &source,
                        format!("{source}: stopped on an internal error (a bug: please report it with this file)"),
                    )
                });
                let _ = tx.send((row, weight));
            })
    });
    let ids = reader.join().expect("the reader thread does not panic");
    let rows = collector
        .join()
        .expect("the collector thread does not panic");
    Ok((rows, ids))
}

fn print_outcome(rows: &[Row], out: &Path, secs: f64, threads: usize, reports: bool) {
    let counts = summary::counts(rows);
    let parts: Vec<String> = VERDICTS
        .iter()
        .zip(counts)
        .filter(|(_, n)| *n > 0)
        .map(|(v, n)| format!("{n} {v}"))
        .collect();
    println!(
        "batch: {} loops in {secs:.1} s ({:.0} loops/s, {threads} threads): {}",
        rows.len(),
        rows.len() as f64 / secs.max(1e-9),
        if parts.is_empty() {
            "none".into()
        } else {
            parts.join(", ")
        }
    );
    let resumed = rows.iter().filter(|r| r.resumed).count();
    if resumed > 0 {
        println!("  {resumed} of them kept from an earlier run (--resume)");
    }
    if counts[4] > 0 {
        println!(
            "  {} failed; the reason of each is in the error column of {}",
            if counts[4] == 1 {
                "1 loop".to_string()
            } else {
                format!("{} loops", counts[4])
            },
            out.join("summary.csv").display()
        );
    }
    println!(
        "  wrote {}, {} and {}{}",
        out.join("summary.csv").display(),
        out.join("summary.json").display(),
        out.join("loops").display(),
        if reports {
            format!(", {}", out.join("index.html").display())
        } else {
            String::new()
        }
    );
}

/// "line N" in a message about a loop of a long-format file (read as a small CSV: header on line
/// 1, row k on line k + 2) becomes the line of the long file.
fn remap_lines(msg: &str, lines: &[u64]) -> String {
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

/// Read one loop. A long-format loop's rows are read from memory by `data::Table` and
/// `Columns::read` (shared with `diagnose`) exactly as a file of its own; their messages are
/// then pointed at the long file's lines.
fn read_loop(data: JobData, ctx: &Ctx) -> Result<LoopFile, String> {
    match data {
        JobData::File(path) => data::Table::read(&path)
            .and_then(|t| ctx.columns.read(&t))
            .map_err(|e| format!("{e:#}")),
        JobData::Rows { file, csv, lines } => data::Table::parse(&file, &csv)
            .and_then(|t| ctx.columns.read(&t))
            .map_err(|e| remap_lines(&format!("{e:#}"), &lines)),
        JobData::Fail(why) => Err(why),
    }
}

/// Diagnose one loop: never panics, never fails the batch; a loop that cannot be read or
/// diagnosed is a `failed` row with the reason.
fn process(job: Job, ctx: &Ctx) -> Row {
    let Job {
        id, source, data, ..
    } = job;
    let json_path = ctx.loops_dir.join(format!("{id}.json"));
    let report_path = ctx
        .reports_dir
        .as_ref()
        .map(|d| d.join(format!("{id}.html")));
    if ctx.resume && report_path.as_ref().is_none_or(|p| p.exists()) {
        let old = std::fs::read(&json_path)
            .ok()
            .and_then(|b| serde_json::from_slice::<Value>(&b).ok());
        if let Some(row) = old.and_then(|v| Row::from_json(&id, &source, &v)) {
            return Row {
                resumed: true,
                report: report_path.is_some(),
                ..row
            };
        }
    }
    let lf = match read_loop(data, ctx) {
        Ok(lf) => lf,
        Err(why) => return Row::failed(&id, &source, why),
    };
    let mut req = ctx.columns.request(lf.ts);
    req.quantify = ctx.quantify;
    let d = match diagnose(&lf.record(), &req) {
        Ok(d) => d,
        Err(e) => return Row::failed(&id, &source, format!("{source}: {e}")),
    };
    // the row is read back from the JSON as written, exactly as `--resume` reads it
    let written = serde_json::to_vec_pretty(&d)
        .map_err(anyhow::Error::from)
        .and_then(|bytes| {
            write_atomic(&json_path, &bytes)?;
            Ok(serde_json::from_slice::<Value>(&bytes)?)
        });
    let value = match written {
        Ok(v) => v,
        Err(e) => return Row::failed(&id, &source, format!("{e:#}")),
    };
    let Some(mut row) = Row::from_json(&id, &source, &value) else {
        return Row::failed(
            &id,
            &source,
            format!("{source}: the diagnosis has no verdict (a bug: please report it)"),
        );
    };
    if let Some(path) = report_path {
        match write_loop_report(&path, &id, &lf, &d) {
            Ok(()) => row.report = true,
            Err(e) => row.error = format!("the report was not written: {e:#}"),
        }
    }
    row
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

    #[test]
    fn ids_are_file_names_and_unique() {
        let mut ids = inputs::Ids::default();
        assert_eq!(ids.assign("FIC 101/PV", "a"), "FIC_101_PV");
        assert_eq!(ids.assign("fic_101_pv", "b"), "fic_101_pv~2");
        assert_eq!(ids.assign("..x", "c"), "_.x");
        assert_eq!(ids.assign("", "d"), "_");
        assert_eq!(ids.duplicates, 1);
        assert!(ids.notes[0].contains("'FIC_101_PV'") && ids.notes[0].contains("~2"));
    }
}
