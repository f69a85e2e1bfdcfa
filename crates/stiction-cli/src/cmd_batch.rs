//! `stiction batch`: diagnose many loops in parallel and rank them.
//!
//! Inputs are streamed (see `pipeline`): a reader thread turns the INPUT arguments into one job per loop (a
//! long-format file is read once, front to back, one loop at a time) and hands them over a bounded
//! channel to a rayon pool; each worker reads its loop, diagnoses it, writes `loops/<id>.json`
//! (and a report) and sends back a small summary row. Only those rows are kept, so memory stays
//! flat however many loops there are. The summary is ranked with a total order (severity, verdict,
//! loop id), so it is the same for any number of threads, and rewritten every few seconds, so an
//! interrupted run loses nothing: `--resume` picks up from the `loops/<id>.json` already written,
//! checking that each loop's input is unchanged (`resume`). One run writes into a folder at a
//! time (`lock`); a signal stops the batch cleanly (`stop`); every file is written atomically
//! (`crate::atomic`), so a crash or a full disk never leaves half a file.
//!
//! Loop ids: a file's stem, or the loop id cell of a long-format file, made a safe file name
//! (characters other than letters, digits and `- _ . + ~` become `_`). Ids used twice get a
//! suffix in input order (`X`, `X~2`, `X~3`), with a note; the `source` column says which is which.

mod classify;
mod html;
mod inputs;
mod layout;
mod lock;
mod long;
mod pipeline;
mod progress;
mod resume;
mod stop;
mod summary;

use crate::atomic::{remove_stale_temps, write_atomic};
use crate::loop_file::Columns;
use anyhow::{bail, Context, Result};
use layout::{Layout, LoopList, TagPattern};
use pipeline::Ctx;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use stiction_core::fleet::Outcome;
use stop::{Reason, Stop};
use summary::{Fate, Row, SourceStatus};

#[derive(clap::Args, Clone)]
#[command(
    about = "Diagnose many loops in parallel (folders, patterns, long-format files) and rank them by severity",
    after_help = "Examples:
  stiction batch plant/ -o out --sp sp
  stiction batch 'plant/*.csv' more/FIC101.csv -o out --op OP --pv PV --threads 4 --reports
  stiction batch historian.csv -o out --loop-id tag --sp SP --no-quantify
  stiction batch exports/ -o out --tags '{loop}.{role}'   # columns FIC101.OP, FIC101.PV, LIC7.OP, ...
  stiction batch exports/ -o out --columns loops.toml     # a plant's loop list
  stiction batch plant/ -o out --sp sp --resume      # after an interruption: done loops are kept

Writes OUTDIR/summary.csv and summary.json (one row per loop, ranked by severity = apparent
stiction x the probability of a sticky valve for a stiction verdict, then verdict, then loop id), OUTDIR/loops/<id>.json
(the full diagnosis and where it came from), and with --reports OUTDIR/reports/<id>.html and
OUTDIR/index.html. A loop that cannot be read is a 'failed' row with the reason; the batch goes on.
Loop ids: the file stem, the loop id cell of a long-format file, or the loop's name in a loop list
or tag pattern, as a safe file name; an id used twice gets a suffix in input order (X, X~2, X~3),
with a note.

A loop list (--columns) names each loop's columns and options, one [[loop]] table per loop in
TOML or one row per loop in CSV (columns id, file, op, pv, sp, mode, mv, time, integrating, ts):
  [[loop]]
  id = \"FIC101\"
  op = \"FIC101.OP\"
  pv = \"FIC101.PV\"
  sp = \"FIC101.SP\"
  [[loop]]
  id = \"LIC7\"
  file = \"unit2.csv\"     # optional, relative to the list; else every input with the op column
  op = \"LIC7.OP\"
  pv = \"LIC7.PV\"
  integrating = true
  ts = 5
A loop left out of the list's options takes the flags' (--time, --ts, --integrating). A loop whose
list names a column its file lacks is a failed row naming file, column and loop.

One writer per OUTDIR (a lock, OUTDIR/batch.lock): a second run into the same folder stops at once.
Ctrl-C or SIGTERM stops handing out loops, lets running loops finish and writes the summary of
what is done (exit 130 / 143); a second signal stops at once. --resume diagnoses again every loop
whose input or settings changed, and keeps, marked 'vanished', a loop whose input is gone.
Exit status: 0 every loop diagnosed, 3 finished with failed loops, 2 unusable arguments or files
that cannot be written, 130 / 143 stopped by a signal."
)]
// the fields' doc comments are the --help text, written for a terminal ([[loop]], <id>), not
// rustdoc
#[allow(rustdoc::broken_intra_doc_links, rustdoc::invalid_html_tags)]
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
    /// A loop list naming each loop's columns (op, pv, sp, mode, mv, time) and options
    /// (integrating, ts): TOML ([[loop]] tables) or CSV (a row per loop); see below
    #[arg(
        long = "columns",
        value_name = "FILE.toml|FILE.csv",
        conflicts_with = "tags"
    )]
    pub loop_list: Option<PathBuf>,
    /// Split wide exports into loops by their column names: PATTERN holds {loop} and {role}
    /// (op, pv, sp, mode or mv; any case), e.g. '{loop}.{role}' for FIC101.OP, FIC101.PV, LIC7.OP
    #[arg(long, value_name = "PATTERN")]
    pub tags: Option<String>,
    /// Worker threads [default: one per CPU]
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Also write an HTML report per loop (OUTDIR/reports/<id>.html) and OUTDIR/index.html
    #[arg(long)]
    pub reports: bool,
    /// Keep the loops whose OUTDIR/loops/<id>.json exists (an interrupted run) instead of
    /// diagnosing them again, unless their input or settings changed
    #[arg(long)]
    pub resume: bool,
    /// Skip the closed-loop estimate of the band (faster; severity then uses the ellipse estimate)
    #[arg(long)]
    pub no_quantify: bool,
}

/// The settings that decide every loop's diagnosis: `--resume` refuses to mix loops diagnosed
/// with different ones. (Each loop's JSON also records its own columns and options, so a loop
/// whose line of a loop list changed is diagnosed again.)
fn settings(a: &Args) -> Value {
    let c = &a.columns;
    serde_json::json!({
        "op": c.op, "pv": c.pv, "sp": c.sp, "mode": c.mode, "time": c.time, "ts": c.ts,
        "integrating": c.integrating, "self_regulating": c.self_regulating, "quantify": !a.no_quantify, "loop_id": a.loop_id,
        "estimate_start": c.estimate_start, "tags": a.tags,
    })
}

/// Where each loop's columns are, from `--columns` or `--tags`.
fn layout(a: &Args) -> Result<Layout> {
    Ok(match (&a.loop_list, &a.tags) {
        (Some(list), _) => Layout::List(LoopList::read(list, &a.columns)?),
        (None, Some(tags)) => Layout::Tags(TagPattern::parse(tags)?),
        (None, None) => Layout::Flags,
    })
}

/// Run the batch. The exit status: 0 when every loop was diagnosed, 3 when the batch finished
/// but some loops failed, 130 / 143 when stopped by SIGINT / SIGTERM; an error (exit 2) for
/// unusable arguments, a folder another run holds, or files that cannot be written.
pub fn run(a: Args) -> Result<u8> {
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
    let layout = layout(&a)?;
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
    let inputs = classify::classify(files, &a.loop_id, &a.columns, layout)?;
    let known = inputs.known_loops();
    let (_lock, ctx) = prepare_output(&a)?;
    for note in &inputs.notes {
        eprintln!("note: {note}");
    }
    let (mut rows, ids) = pipeline::diagnose_all(inputs, &ctx, threads)?;
    let stopped = ctx.stop.reason();
    if a.resume && stopped.is_none() {
        rows.extend(pipeline::vanished(&ctx.loops_dir, &ids));
    }
    let out = &a.output;
    let written = summary::write(out, &mut rows, stopped.is_none()).and_then(|()| {
        if a.reports {
            html::write_index(out, &rows, stopped.is_none())
        } else {
            Ok(())
        }
    });
    for note in &ids.notes {
        eprintln!("note: {note}");
    }
    if ids.duplicates > ids.notes.len() {
        eprintln!(
            "note: {} more loop ids were used twice and got a ~N suffix (see the source column)",
            ids.duplicates - ids.notes.len()
        );
    }
    let done = match known {
        Some(m) => format!("{} of {m} loops", rows.len()),
        None => format!("{} loops", rows.len()),
    };
    let summary_failed = |e: anyhow::Error| {
        anyhow::anyhow!(
            "{}: cannot write the summary ({e:#}); the result of every loop done is in {}: free space and run the same command with --resume to write it",
            out.display(),
            ctx.loops_dir.display()
        )
    };
    match stopped {
        Some(Reason::Fault(why)) => bail!(
            "stopped after {done}: {why}; free space (or choose another folder with -o OUTDIR) and run the same command with --resume to finish"
        ),
        Some(Reason::Signal(sig)) => {
            written.map_err(summary_failed)?;
            eprintln!("stopped after {done}; run the same command with --resume to finish");
            Ok((128 + sig) as u8)
        }
        None => {
            written.map_err(summary_failed)?;
            let secs = started.elapsed().as_secs_f64();
            print_outcome(&rows, out, secs, threads, a.reports, a.resume);
            let failed = summary::counts(&rows).failed;
            Ok(if failed > 0 { 3 } else { 0 })
        }
    }
}

/// Make OUTDIR ready: its lock (before anything is written), the temporary files a killed run
/// left removed, its folders, the settings of this run (checked against the earlier run's with
/// `--resume`), an empty summary so a stale one never passes for this run's.
fn prepare_output(a: &Args) -> Result<(lock::Lock, Ctx)> {
    let out = &a.output;
    let shown = out.display();
    std::fs::create_dir_all(out).with_context(|| {
        format!("{shown}: cannot create the output folder; choose a writable folder with -o OUTDIR")
    })?;
    let lock = lock::take(out)?;
    let loops_dir = out.join("loops");
    let reports_dir = a.reports.then(|| out.join("reports"));
    for dir in [Some(out), Some(&loops_dir), reports_dir.as_ref()]
        .into_iter()
        .flatten()
    {
        std::fs::create_dir_all(dir)
            .with_context(|| format!("{}: cannot create the folder", dir.display()))?;
        remove_stale_temps(dir);
    }
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
    let again = "free space (or choose another folder with -o OUTDIR) and run the command again";
    write_atomic(&settings_path, &serde_json::to_vec_pretty(&settings)?)
        .and_then(|()| summary::write(out, &mut [], false))
        .map_err(|e| anyhow::anyhow!("{e:#}; {again}"))?;
    // left by an interrupted run of an earlier version
    let _ = std::fs::remove_dir_all(out.join(".batch-tmp"));
    let ctx = Ctx {
        flags: a.columns.clone(),
        quantify: !a.no_quantify,
        out: out.clone(),
        loops_dir,
        reports_dir,
        resume: a.resume,
        stop: Arc::new(Stop::install().context("cannot install the signal handlers")?),
    };
    Ok((lock, ctx))
}

fn print_outcome(rows: &[Row], out: &Path, secs: f64, threads: usize, reports: bool, resume: bool) {
    let counts = summary::counts(rows);
    let parts: Vec<String> = Outcome::ALL
        .iter()
        .map(|&v| (v, counts.get(v)))
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
    let shared = rows.iter().filter(|r| r.same_period_loops > 0).count();
    if shared > 0 {
        println!(
            "  {shared} oscillating loops share their period with others of this batch (same_period_loops in summary.csv): \
             where they belong to one unit and one time window, one loop's cycle (a sticky valve) may drive the others"
        );
    }
    if resume {
        // failed loops are counted apart (they are tried again on every resume)
        let n = |f: Fate, s: SourceStatus| {
            rows.iter()
                .filter(|r| r.fleet.verdict != Outcome::Failed)
                .filter(|r| r.fate == f && r.source_status == s)
                .count()
        };
        let vanished = n(Fate::Kept, SourceStatus::Vanished);
        println!(
            "  resume: {} kept, {} redone because their input or settings changed, {} new{}",
            n(Fate::Kept, SourceStatus::Present),
            n(Fate::Redone, SourceStatus::Present),
            n(Fate::New, SourceStatus::Present),
            if vanished > 0 {
                format!(", {vanished} kept whose input is gone (source_status vanished)")
            } else {
                String::new()
            }
        );
    }
    if counts.failed > 0 {
        println!(
            "  {} failed; the reason of each is in the error column of {}",
            if counts.failed == 1 {
                "1 loop".to_string()
            } else {
                format!("{} loops", counts.failed)
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

#[cfg(test)]
mod tests {
    use super::*;

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
