//! Workbooks (`.xlsx`, `.xlsm`, `.xlsb`, `.xls`, `.ods`) read with `calamine`: one sheet (the
//! first, or `--sheet NAME`), its first non-empty row the header. Date cells become ISO 8601
//! local times, so the time axis reads them like any text timestamp.

use super::table::Table;
use super::ReadOptions;
use anyhow::{bail, Result};
use calamine::{Data, Reader};
use std::io::Cursor;
use std::path::Path;

/// A table from a workbook's bytes; `kind` says what the bytes looked like ("Excel workbook",
/// "OpenDocument spreadsheet", "Excel 97-2003 workbook") for the messages.
pub fn read(path: &Path, bytes: &[u8], opts: &ReadOptions, kind: &'static str) -> Result<Table> {
    let file = path.display();
    let mut book = match calamine::open_workbook_auto_from_rs(Cursor::new(bytes)) {
        Ok(b) => b,
        Err(_) if kind == "zip archive" => bail!(
            "{file}: this is a zip archive, not a workbook; unpack it and give the CSV or workbook inside"
        ),
        Err(e) => bail!(
            "{file}: this looks like an {kind} but it cannot be read ({e}); if it is password-protected or damaged, \
             open it in a spreadsheet and save it again as xlsx or CSV"
        ),
    };
    let names = book.sheet_names();
    let name = match &opts.sheet {
        Some(want) => names
            .iter()
            .find(|n| n.eq_ignore_ascii_case(want.trim()))
            .cloned()
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{file}: no sheet '{want}'; the sheets are {}. Choose one with --sheet NAME",
                    quoted(&names)
                )
            })?,
        None => match names.first() {
            Some(n) => n.clone(),
            None => bail!("{file}: the workbook has no sheets"),
        },
    };
    let range = book.worksheet_range(&name).map_err(|e| {
        anyhow::anyhow!("{file}: sheet '{name}' cannot be read ({e}); save it as CSV and read that")
    })?;
    let first_row = range.start().map_or(0, |(r, _)| r as u64);
    let mut rows = range.rows().enumerate();
    let header = rows.find(|(_, r)| r.iter().any(|c| !matches!(c, Data::Empty)));
    let Some((_, header)) = header else {
        bail!(
            "{file}: sheet '{name}' is empty{}; choose the sheet with the data with --sheet NAME",
            if names.len() > 1 {
                format!(" (the sheets are {})", quoted(&names))
            } else {
                String::new()
            }
        );
    };
    let headers = header.iter().map(text).collect();
    let names = names.clone();
    let mut table = Table::new(path, headers).rows_are_rows();
    table.sheet = Some(name);
    table.sheets = names;
    let mut cells: Vec<String> = Vec::new();
    for (i, row) in rows {
        cells.clear();
        cells.extend(row.iter().map(text));
        table.push_row(cells.iter().map(|s| s.as_str()), first_row + i as u64 + 1);
    }
    Ok(table)
}

fn quoted(names: &[String]) -> String {
    names
        .iter()
        .map(|n| format!("'{n}'"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A cell as text: numbers exactly (shortest round-trip form), dates as ISO 8601 local times to
/// the millisecond, durations as seconds, errors as Excel shows them (`#N/A`: a gap).
fn text(c: &Data) -> String {
    match c {
        Data::Empty => String::new(),
        Data::String(s) | Data::DateTimeIso(s) | Data::DurationIso(s) => s.clone(),
        Data::Float(v) => format!("{v}"),
        Data::Int(v) => format!("{v}"),
        Data::Bool(b) => format!("{b}"),
        Data::Error(e) => e.to_string(),
        Data::DateTime(d) if d.is_duration() => format!("{}", d.as_f64() * 86_400.0),
        Data::DateTime(d) => {
            let (y, mo, da, h, mi, s, ms) = d.to_ymd_hms_milli();
            format!("{y:04}-{mo:02}-{da:02}T{h:02}:{mi:02}:{s:02}.{ms:03}")
        }
    }
}
