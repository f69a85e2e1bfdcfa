//! `index.html` for `--reports`: every loop ranked, linking its report (`stiction report`'s
//! page). Self-contained (inline CSS, no scripts, nothing fetched from elsewhere).

use super::summary::{Row, SourceStatus};
use crate::atomic::write_atomic;
use crate::cmd_report::esc;
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;
use stiction_core::fleet::Outcome;

const STYLE: &str = "body{font-family:system-ui,sans-serif;margin:2em;color:#222;max-width:72em}\
table{border-collapse:collapse;margin:1em 0}th,td{border:1px solid #ccc;padding:.3em .6em;text-align:left;vertical-align:top}\
th{background:#f3f3f3}td.n{text-align:right;font-variant-numeric:tabular-nums}\
.stiction{color:#b00020;font-weight:bold}.undetermined{color:#a66a00}.no_stiction{color:#1b5e20}\
.insufficient_data{color:#555}.failed{color:#b00020}small{color:#666}";

fn num(v: Option<f64>, decimals: usize) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x:.decimals$}"),
        Some(x) if x > 0.0 => "∞".into(),
        _ => "–".into(),
    }
}

fn page(title: &str, body: &str) -> String {
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title><style>{STYLE}</style></head>\n<body>\n{body}</body></html>\n",
        esc(title)
    )
}

/// `index.html`: every loop, ranked as in summary.csv, linking its report.
pub fn write_index(outdir: &Path, rows: &[Row], complete: bool) -> Result<()> {
    let mut b = String::new();
    let _ = writeln!(b, "<h1>Stiction batch: {} loops</h1>", rows.len());
    let counts = super::summary::counts(rows);
    let parts: Vec<String> = Outcome::ALL
        .iter()
        .map(|&v| (v, counts.get(v)))
        .filter(|(_, n)| *n > 0)
        .map(|(v, n)| {
            format!(
                "<span class=\"{v}\">{n} {}</span>",
                v.as_str().replace('_', " ")
            )
        })
        .collect();
    let _ = writeln!(
        b,
        "<p>{}{}. Ranked by severity (apparent stiction &times; confidence), then verdict, then loop id. \
         Data: <a href=\"summary.csv\">summary.csv</a>, <a href=\"summary.json\">summary.json</a>.</p>",
        parts.join(", "),
        if complete {
            ""
        } else {
            " (the batch is still running or was interrupted: not every loop is listed)"
        }
    );
    let _ = writeln!(
        b,
        "<table><tr><th>#</th><th>loop</th><th>verdict</th><th>confidence</th><th>severity</th><th>band (% of span)</th><th>period (s)</th><th>reason</th></tr>"
    );
    for (k, row) in rows.iter().enumerate() {
        let r = &row.fleet;
        let name = if row.report {
            format!(
                "<a href=\"reports/{}.html\">{}</a>",
                esc(&r.loop_id),
                esc(&r.loop_id)
            )
        } else {
            esc(&r.loop_id)
        };
        let _ = writeln!(
            b,
            "<tr><td class=\"n\">{}</td><td>{name}<br><small>{}</small></td><td class=\"{}\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
            k + 1,
            esc(&r.source)
                + match row.source_status {
                    SourceStatus::Present => "",
                    SourceStatus::Vanished => " (no longer among the inputs: kept from an earlier run)",
                },
            r.verdict,
            r.verdict.as_str().replace('_', " "),
            num(r.confidence, 2),
            num(Some(r.severity), 3),
            num(r.band_percent_of_span, 2),
            num(r.period_s, 1),
            esc(&r.reason)
        );
    }
    let _ = writeln!(b, "</table>");
    write_atomic(
        &outdir.join("index.html"),
        page("Stiction batch", &b).as_bytes(),
    )
}
