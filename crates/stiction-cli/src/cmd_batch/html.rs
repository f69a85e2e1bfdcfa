//! `index.html` for `--reports`: every loop ranked as in summary.csv, linking its report, with a
//! sparkline of PV and OP; the page itself is [`stiction_report::fleet`]'s.

use super::summary::{Row, SourceStatus};
use crate::atomic::write_atomic;
use anyhow::Result;
use std::path::Path;
use stiction_report::fleet::{self, Entry};

/// Write `index.html` into `outdir`: the rows in their (ranked) order.
pub fn write_index(outdir: &Path, rows: &[Row], complete: bool) -> Result<()> {
    let shown: Vec<fleet::FleetRow> = rows
        .iter()
        .enumerate()
        .map(|(k, row)| {
            let source = match row.source_status {
                SourceStatus::Present => row.fleet.source.clone(),
                SourceStatus::Vanished => format!(
                    "{} (no longer among the inputs: kept from an earlier run)",
                    row.fleet.source
                ),
            };
            let entry = Entry {
                row: &row.fleet,
                source,
                report: row.report,
                spark: row.spark.as_ref(),
                same_period: row.same_period_loops,
            };
            fleet::row(k + 1, &entry)
        })
        .collect();
    let page = fleet::page(&shown, &super::summary::counts(rows), complete)?;
    write_atomic(&outdir.join("index.html"), page.as_bytes())
}
