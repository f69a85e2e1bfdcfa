//! Reading loop data as plants export it: CSV (comma, semicolon or tab; UTF-8 or UTF-16),
//! gzip-compressed CSV, Excel and OpenDocument workbooks, Parquet, or standard input (`-`), the
//! format found from the bytes. Missing values (blank, NaN, #N/A, historian states) are gaps;
//! time columns are read by `jiff`. Every way a file can be wrong is one sentence naming the
//! file, the column and the line.

mod format;
mod layout;
mod missing;
#[cfg(feature = "parquet")]
mod parquet;
mod sheet;
mod table;
mod text;
pub mod time;
mod time_column;

#[cfg(test)]
mod proptests;

pub use format::in_guarded_reader;
use stiction_core::record;
pub use stiction_core::record::longest_clean;
pub use table::Table;
pub use text::sniff_delimiter;
pub use time::{TimeFormat, TimeSpec};

use crate::words::count;
use anyhow::{bail, Result};

/// How to read a file beyond its bytes.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// The sheet of a workbook (default: the first).
    pub sheet: Option<String>,
}

pub(crate) use stiction_core::record::parse_number;

/// The time column: `--time COL` if given, else the first of the common names
/// (`stiction_core::record::TIME_NAMES`: t, time, timestamp, datetime, date, ...).
pub fn time_column(table: &Table, explicit: Option<&str>) -> Result<Option<usize>> {
    match explicit {
        Some(name) => table.require(name, "--time", "time").map(Some),
        None => Ok(stiction_core::record::TIME_NAMES
            .iter()
            .find_map(|n| table.find(n))),
    }
}

/// The rows a fit uses: the whole record, or the longest stretch where no column has a gap.
#[derive(Debug, Clone, PartialEq)]
pub struct Stretch {
    pub start: usize,
    pub end: usize,
    /// What was treated as missing and which stretch is used, for a note; `None` without gaps.
    pub note: Option<String>,
    /// The columns, whole, with their short gaps bridged (see
    /// [`stiction_core::record::short_gaps`]).
    pub columns: Vec<Vec<f64>>,
}

/// The longest stretch without gaps in `columns` (name, values with NaN at gaps) once their short
/// gaps are bridged, or one sentence saying why there is none of at least `min_samples`. `row_of` maps a sample to its
/// row of the table (the rows may have been sorted by time).
pub fn fit_stretch(
    table: &Table,
    columns: &[(&str, &[f64])],
    min_samples: usize,
    row_of: &dyn Fn(usize) -> usize,
) -> Result<Stretch> {
    let file = table.path.display();
    // the signals' samples: fewer than the table's rows when rows were merged (repeated times)
    let n = columns.first().map_or(table.len(), |(_, v)| v.len());
    let values: Vec<&[f64]> = columns.iter().map(|(_, v)| *v).collect();
    let runs = record::short_gaps(&values, &|_| true);
    let filled: Vec<Vec<f64>> = values.iter().map(|v| record::bridged(v, &runs)).collect();
    let bridge_note =
        (!runs.is_empty()).then(|| record::bridged_note(&runs, ("sample", "samples")));
    let columns: Vec<(&str, &[f64])> = columns
        .iter()
        .zip(&filled)
        .map(|((name, _), v)| (*name, v.as_slice()))
        .collect();
    let gaps: Vec<(&str, usize)> = columns
        .iter()
        .map(|(name, v)| (*name, v.iter().filter(|x| !x.is_finite()).count()))
        .filter(|(_, k)| *k > 0)
        .collect();
    let total: usize = gaps.iter().map(|(_, k)| k).sum();
    let which = gaps
        .iter()
        .map(|(name, k)| format!("{name} {k}"))
        .collect::<Vec<_>>()
        .join(", ");
    if table.len() == 0 {
        return Err(table.no_rows());
    }
    if total == 0 {
        if n < min_samples {
            bail!(
                "{file}: only {} of data; at least {min_samples} samples are needed",
                count(n, "row", "rows")
            );
        }
        return Ok(Stretch {
            start: 0,
            end: n,
            note: bridge_note,
            columns: filled,
        });
    }
    let values: Vec<&[f64]> = columns.iter().map(|(_, v)| *v).collect();
    let longest = longest_clean(&values);
    let (a, b) = longest.unwrap_or((0, 0));
    let lines =
        |a: usize, b: usize| format!("{} to {}", table.at(row_of(a)), table.line(row_of(b - 1)));
    if b - a < min_samples {
        bail!(
            "{file}: no stretch of at least {min_samples} samples without missing values ({} treated as missing: {which}; the longest stretch without gaps is {}{}); fill the gaps or export a longer stretch",
            count(total, "cell", "cells"),
            count(b - a, "sample", "samples"),
            if b > a { format!(", {}", lines(a, b)) } else { String::new() }
        );
    }
    let mut note = format!(
        "{} treated as missing ({which}: blank, NaN, #N/A or a historian state such as Bad Input); \
         using {}, the longest stretch without gaps ({} of {n})",
        count(total, "cell", "cells"),
        lines(a, b),
        count(b - a, "sample", "samples"),
    );
    if let Some(bridged) = bridge_note {
        note = format!("{bridged}; {note}");
    }
    Ok(Stretch {
        start: a,
        end: b,
        note: Some(note),
        columns: filled,
    })
}

/// Two columns (e.g. op and mv) ready for estimation: the longest stretch without gaps, with
/// the checks that apply to both.
pub struct Pair {
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    /// What was treated as missing, when anything was.
    pub note: Option<String>,
}

/// Read two columns (e.g. op and mv) ready for estimation. A time column named with `--time`
/// must exist and parse, though estimation does not use it.
pub fn read_pair(
    table: &Table,
    (a_name, a_flag, a_role): (&str, &str, &str),
    (b_name, b_flag, b_role): (&str, &str, &str),
    time: Option<(&str, &TimeSpec)>,
    min_samples: usize,
) -> Result<Pair> {
    let a = table.require(a_name, a_flag, a_role)?;
    let b = table.require(b_name, b_flag, b_role)?;
    if let Some((name, spec)) = time {
        let col = table.require(name, "--time", "time")?;
        table.time_axis(col, spec)?;
    }
    let av = table.numbers(a)?;
    let bv = table.numbers(b)?;
    let s = fit_stretch(
        table,
        &[(&table.headers[a], &av), (&table.headers[b], &bv)],
        min_samples,
        &|k| k,
    )?;
    let av = s.columns[0][s.start..s.end].to_vec();
    let (lo, hi) = av
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    if hi - lo <= 0.0 {
        bail!(
            "{}: column '{}' ({a_role}) is constant at {lo}; a valve whose command never moves shows no stiction, choose a stretch of data where {a_role} varies",
            table.path.display(),
            table.headers[a]
        );
    }
    let units: Vec<String> = [a, b]
        .iter()
        .filter_map(|&c| {
            table.unit(c).map(|u| {
                format!(
                    "'{u}' after every number of column '{}': dropped",
                    table.headers[c]
                )
            })
        })
        .collect();
    let notes: Vec<String> = table
        .notes
        .iter()
        .cloned()
        .chain(units)
        .chain(s.note)
        .collect();
    Ok(Pair {
        a: av,
        b: s.columns[1][s.start..s.end].to_vec(),
        note: (!notes.is_empty()).then(|| notes.join("; ")),
    })
}
