//! The summary of a batch: one small row per loop, the ranking, and summary.csv / summary.json.
//!
//! A row is always built from the diagnosis as JSON (the same text that goes to `loops/<id>.json`),
//! so a row rebuilt by `--resume` from that file equals the row of a fresh run.

use anyhow::{Context, Result};
use serde::Serialize;
use serde_json::Value;
use std::cmp::Ordering;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// The verdicts in ranking order, `failed` last.
pub const VERDICTS: [&str; 5] = [
    "stiction",
    "undetermined",
    "no_stiction",
    "insufficient_data",
    "failed",
];

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    pub loop_id: String,
    pub source: String,
    pub verdict: String,
    pub confidence: Option<f64>,
    /// Apparent stiction times confidence for a `stiction` verdict, else 0.
    pub severity: f64,
    pub apparent_stiction_closed_loop: Option<f64>,
    pub apparent_stiction_ellipse: Option<f64>,
    pub period_s: Option<f64>,
    /// Thornhill's regularity; `None` in JSON also when it is infinite (perfectly regular).
    pub regularity: Option<f64>,
    pub reason: String,
    pub samples: Option<u64>,
    /// Time `diagnose` took on this loop.
    pub seconds: Option<f64>,
    /// Why the loop could not be read or diagnosed; empty unless the verdict is `failed`.
    pub error: String,
    /// Rebuilt from an existing `loops/<id>.json` (`--resume`), not diagnosed in this run.
    #[serde(skip)]
    pub resumed: bool,
    /// Has an HTML report.
    #[serde(skip)]
    pub report: bool,
}

fn f(v: &Value, path: &[&str]) -> Option<f64> {
    path.iter().try_fold(v, |v, k| v.get(k))?.as_f64()
}

impl Row {
    pub fn failed(loop_id: &str, source: &str, error: String) -> Row {
        Row {
            loop_id: loop_id.into(),
            source: source.into(),
            verdict: "failed".into(),
            confidence: None,
            severity: 0.0,
            apparent_stiction_closed_loop: None,
            apparent_stiction_ellipse: None,
            period_s: None,
            regularity: None,
            reason: error.clone(),
            samples: None,
            seconds: None,
            error,
            resumed: false,
            report: false,
        }
    }

    /// The row of a diagnosis serialised as JSON (a `stiction_core::diagnose::Diagnosis`).
    /// `None` when the JSON is not a diagnosis.
    pub fn from_json(loop_id: &str, source: &str, d: &Value) -> Option<Row> {
        let verdict = d.get("verdict")?.as_str()?.to_string();
        if !VERDICTS[..4].contains(&verdict.as_str()) {
            return None;
        }
        let confidence = d.get("confidence")?.as_f64()?;
        let closed = f(d, &["apparent_stiction", "closed_loop"]);
        let ellipse = f(d, &["apparent_stiction", "ellipse"]);
        let apparent = closed.or(ellipse).unwrap_or(0.0);
        let severity = if verdict == "stiction" {
            apparent * confidence
        } else {
            0.0
        };
        // serde_json writes an infinite regularity (perfectly regular periods) as null
        let regularity = d.get("oscillation").map(|o| {
            o.get("regularity")
                .and_then(|r| r.get("regularity"))
                .and_then(Value::as_f64)
                .unwrap_or(f64::INFINITY)
        });
        let reason = match d.get("reason").and_then(Value::as_str) {
            Some(r) => r.to_string(),
            None => votes(d),
        };
        Some(Row {
            loop_id: loop_id.into(),
            source: source.into(),
            verdict,
            confidence: Some(confidence),
            severity,
            apparent_stiction_closed_loop: closed,
            apparent_stiction_ellipse: ellipse,
            period_s: f(d, &["oscillation", "period"]),
            regularity,
            reason,
            samples: d.get("samples").and_then(Value::as_u64),
            seconds: d.get("seconds").and_then(Value::as_f64),
            error: String::new(),
            resumed: false,
            report: false,
        })
    }

    fn rank(&self) -> usize {
        VERDICTS
            .iter()
            .position(|v| *v == self.verdict)
            .unwrap_or(VERDICTS.len())
    }
}

/// "votes: cross_correlation stiction (0.704), curve_fitting stiction (0.997), ...": why a
/// verdict reached by the indices is what it is.
fn votes(d: &Value) -> String {
    let Some(indices) = d.get("indices").and_then(Value::as_array) else {
        return String::new();
    };
    let parts: Vec<String> = indices
        .iter()
        .map(|i| {
            let name = i.get("name").and_then(Value::as_str).unwrap_or("?");
            let vote = i.get("vote").and_then(Value::as_str).unwrap_or("?");
            match i.get("value").and_then(Value::as_f64) {
                Some(v) => format!("{name} {vote} ({v:.3})"),
                None => format!("{name} {vote}"),
            }
        })
        .collect();
    if parts.is_empty() {
        String::new()
    } else {
        format!("votes: {}", parts.join(", "))
    }
}

/// Severity descending, then verdict (stiction, undetermined, no_stiction, insufficient_data,
/// failed), then loop id: a total order, so the ranking never depends on which loop finished first.
pub fn ranking(a: &Row, b: &Row) -> Ordering {
    b.severity
        .total_cmp(&a.severity)
        .then(a.rank().cmp(&b.rank()))
        .then_with(|| a.loop_id.cmp(&b.loop_id))
}

/// Number of loops per verdict, in `VERDICTS` order.
pub fn counts(rows: &[Row]) -> [usize; 5] {
    let mut c = [0; 5];
    for r in rows {
        c[r.rank().min(4)] += 1;
    }
    c
}

fn cell(v: Option<f64>) -> String {
    match v {
        None => String::new(),
        Some(x) if x == f64::INFINITY => "inf".into(),
        Some(x) => format!("{x}"),
    }
}

pub const CSV_HEADER: [&str; 13] = [
    "loop_id",
    "source",
    "verdict",
    "confidence",
    "severity",
    "apparent_stiction_closed_loop",
    "apparent_stiction_ellipse",
    "period_s",
    "regularity",
    "reason",
    "samples",
    "seconds",
    "error",
];

#[derive(Serialize)]
struct Counts {
    stiction: usize,
    undetermined: usize,
    no_stiction: usize,
    insufficient_data: usize,
    failed: usize,
}

/// summary.json: `complete` is false in the copies written while the batch runs.
#[derive(Serialize)]
struct SummaryJson<'a> {
    complete: bool,
    loops: usize,
    counts: Counts,
    rows: &'a [Row],
}

/// Write a file atomically (a temporary file beside it, then a rename), streaming the content.
fn write_streamed(path: &Path, body: impl FnOnce(&mut dyn Write) -> Result<()>) -> Result<()> {
    let tmp = path.with_extension(format!(
        "{}.tmp{}",
        path.extension().and_then(|e| e.to_str()).unwrap_or(""),
        std::process::id()
    ));
    let cannot = || format!("{}: cannot write the file", path.display());
    let mut w = BufWriter::new(File::create(&tmp).with_context(cannot)?);
    body(&mut w).with_context(cannot)?;
    w.into_inner()
        .map_err(|e| e.into_error())
        .with_context(cannot)?;
    std::fs::rename(&tmp, path).with_context(cannot)
}

/// Write summary.csv and summary.json (rows ranked, each file atomically and streamed, so that
/// no copy of the summary is built in memory). `complete` is false for the interim copies
/// written while the batch runs.
pub fn write(outdir: &Path, rows: &mut [Row], complete: bool) -> Result<()> {
    rows.sort_by(ranking);
    write_streamed(&outdir.join("summary.csv"), |out| {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(CSV_HEADER)?;
        for r in rows.iter() {
            w.write_record([
                r.loop_id.as_str(),
                &r.source,
                &r.verdict,
                &cell(r.confidence),
                &cell(Some(r.severity)),
                &cell(r.apparent_stiction_closed_loop),
                &cell(r.apparent_stiction_ellipse),
                &cell(r.period_s),
                &cell(r.regularity),
                &r.reason,
                &r.samples.map(|s| s.to_string()).unwrap_or_default(),
                &cell(r.seconds),
                &r.error,
            ])?;
        }
        w.flush()?;
        Ok(())
    })?;
    let c = counts(rows);
    let json = SummaryJson {
        complete,
        loops: rows.len(),
        counts: Counts {
            stiction: c[0],
            undetermined: c[1],
            no_stiction: c[2],
            insufficient_data: c[3],
            failed: c[4],
        },
        rows,
    };
    write_streamed(&outdir.join("summary.json"), |out| {
        serde_json::to_writer_pretty(&mut *out, &json)?;
        out.write_all(b"\n")?;
        Ok(())
    })
}
