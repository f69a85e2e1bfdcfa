//! The summary of a batch: one row per loop (the core's typed [`fleet::Row`], ranked by the
//! core's [`fleet::ranking`]), written to summary.csv and summary.json.

use crate::atomic::write_with;
use anyhow::Result;
use serde::Serialize;
use std::borrow::Cow;
use std::path::Path;
use stiction_core::fleet::{self, Counts};
use stiction_report::fleet::Spark;

/// Whether the input a row was diagnosed from is still among the inputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SourceStatus {
    /// Read in this run (diagnosed, or kept by `--resume` after checking its input is unchanged).
    Present,
    /// Kept from an earlier run (`--resume`) though its input is no longer among the inputs.
    Vanished,
}

impl SourceStatus {
    fn as_str(self) -> &'static str {
        match self {
            SourceStatus::Present => "present",
            SourceStatus::Vanished => "vanished",
        }
    }
}

/// What this run did with a loop, for the counts `--resume` prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// Diagnosed: no earlier result (or no `--resume`).
    New,
    /// Kept from an earlier run: same input, same settings.
    Kept,
    /// Diagnosed again: its input or its settings changed since the earlier run.
    Redone,
}

/// A row of the summary: the fleet row and what the batch knows besides.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    #[serde(flatten)]
    pub fleet: fleet::Row,
    pub source_status: SourceStatus,
    /// Other loops of this batch that oscillate at this loop's period
    /// ([`fleet::same_period`]): set when the summary is written.
    pub same_period_loops: usize,
    #[serde(skip)]
    pub fate: Fate,
    /// Has an HTML report.
    #[serde(skip)]
    pub report: bool,
    /// PV and OP for the fleet page's sparkline (at most 200 bytes), when the index is written.
    #[serde(skip)]
    pub spark: Option<Spark>,
}

impl Row {
    pub fn new(fleet: fleet::Row, fate: Fate) -> Row {
        Row {
            fleet,
            source_status: SourceStatus::Present,
            same_period_loops: 0,
            fate,
            report: false,
            spark: None,
        }
    }

    pub fn failed(loop_id: &str, source: &str, error: String) -> Row {
        Row::new(fleet::Row::failed(loop_id, source, error), Fate::New)
    }
}

/// Sort rows into the fleet ranking.
pub fn rank(rows: &mut [Row]) {
    rows.sort_by(|a, b| fleet::ranking(&a.fleet, &b.fleet));
}

pub fn counts(rows: &[Row]) -> Counts {
    Counts::of(rows.iter().map(|r| r.fleet.verdict))
}

fn cell(v: Option<f64>) -> String {
    match v {
        None => String::new(),
        Some(x) if x == f64::INFINITY => "inf".into(),
        Some(x) => format!("{x}"),
    }
}

/// A text cell a spreadsheet will show, never run: one starting with `=`, `+`, `-`, `@`, a tab or
/// a carriage return (a formula to Excel, LibreOffice and Google Sheets) gets a leading `'`
/// (OWASP, "CSV Injection").
fn text(s: &str) -> Cow<'_, str> {
    if s.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        Cow::Owned(format!("'{s}"))
    } else {
        Cow::Borrowed(s)
    }
}

pub const CSV_HEADER: [&str; 17] = [
    "loop_id",
    "source",
    "verdict",
    "probability",
    "severity",
    "band_percent_of_span",
    "band_source",
    "ellipse_percent_of_span",
    "small_band_percent_of_span",
    "period_s",
    "regularity",
    "same_period_loops",
    "reason",
    "samples",
    "seconds",
    "error",
    "source_status",
];

/// summary.json: `complete` is false in the copies written while the batch runs or after it was
/// stopped.
#[derive(Serialize)]
struct SummaryJson<'a> {
    complete: bool,
    loops: usize,
    counts: Counts,
    rows: &'a [Row],
}

fn write_csv(path: &Path, rows: &[Row]) -> Result<()> {
    write_with(path, |out| {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(CSV_HEADER)?;
        for r in rows {
            let f = &r.fleet;
            w.write_record([
                text(&f.loop_id).as_ref(),
                &text(&f.source),
                f.verdict.as_str(),
                &cell(f.probability),
                &cell(Some(f.severity)),
                &cell(f.band_percent_of_span),
                f.band_source.map_or("", |s| s.as_str()),
                &cell(f.ellipse_percent_of_span),
                &cell(f.small_band_percent_of_span),
                &cell(f.period_s),
                &cell(f.regularity),
                &r.same_period_loops.to_string(),
                &text(&f.reason),
                &f.samples.map(|s| s.to_string()).unwrap_or_default(),
                &cell(f.seconds),
                &text(&f.error),
                r.source_status.as_str(),
            ])?;
        }
        w.flush()?;
        Ok(())
    })
}

/// Write summary.csv and summary.json, rows ranked, each file atomically and streamed (no copy
/// of the summary is built in memory). A summary that cannot be written leaves the earlier one
/// as it was.
pub fn write(outdir: &Path, rows: &mut [Row], complete: bool) -> Result<()> {
    rank(rows);
    let shared = fleet::same_period(rows.iter().map(|r| &r.fleet));
    for (r, n) in rows.iter_mut().zip(shared) {
        r.same_period_loops = n;
    }
    write_csv(&outdir.join("summary.csv"), rows)?;
    let json = SummaryJson {
        complete,
        loops: rows.len(),
        counts: counts(rows),
        rows,
    };
    write_with(&outdir.join("summary.json"), |out| {
        serde_json::to_writer_pretty(&mut *out, &json)?;
        out.write_all(b"\n")?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formula_cells_are_defused() {
        for s in ["=1+2", "+1", "-x", "@SUM(A1)", "\tx", "\rx"] {
            assert_eq!(text(s), format!("'{s}"));
        }
        for s in ["FIC101", "a=b", "", "1.5"] {
            assert_eq!(text(s), s);
        }
    }
}
