//! Parquet files (pandas, polars, Spark, historian exports) read with the `parquet` crate's row
//! reader: flat schemas of numbers, text, booleans and timestamps. Timestamps become ISO 8601
//! text (with `Z` when the file marks them as UTC instants, else local times for `--tz`).

use super::table::Table;
use anyhow::{bail, Context, Result};
use jiff::Timestamp;
use parquet::basic::{LogicalType, TimeUnit};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;
use std::path::Path;

/// How a column's 64-bit integers are to be read.
#[derive(Clone, Copy)]
struct Stamp {
    /// Units per second.
    per_second: i64,
    utc: bool,
}

/// A table from a Parquet file's bytes.
pub fn read(path: &Path, bytes: &[u8]) -> Result<Table> {
    let file = path.display();
    let reader = SerializedFileReader::new(bytes::Bytes::copy_from_slice(bytes)).map_err(|e| {
        anyhow::anyhow!(
            "{file}: this looks like a Parquet file but it cannot be read ({e}); write it again, or export CSV"
        )
    })?;
    let schema = reader.metadata().file_metadata().schema_descr_ptr();
    let fields = schema.root_schema().get_fields();
    if let Some(f) = fields.iter().find(|f| f.is_group()) {
        bail!(
            "{file}: column '{}' is nested (a struct, list or map); write the file with flat columns of numbers, text and timestamps",
            f.name()
        );
    }
    let headers: Vec<String> = fields.iter().map(|f| f.name().to_string()).collect();
    let stamps: Vec<Option<Stamp>> = (0..headers.len())
        .map(|i| match schema.column(i).logical_type_ref() {
            Some(LogicalType::Timestamp(t)) => Some(Stamp {
                per_second: match t.unit {
                    TimeUnit::MILLIS => 1_000,
                    TimeUnit::MICROS => 1_000_000,
                    _ => 1_000_000_000,
                },
                utc: t.is_adjusted_to_u_t_c,
            }),
            _ => None,
        })
        .collect();
    let mut table = Table::new(path, headers).rows_are_rows();
    let rows = reader
        .get_row_iter(None)
        .with_context(|| format!("{file}: the Parquet rows cannot be read"))?;
    let mut cells: Vec<String> = Vec::new();
    for (i, row) in rows.enumerate() {
        let row = row.with_context(|| format!("{file}: row {} cannot be read", i + 1))?;
        cells.clear();
        cells.extend(
            row.get_column_iter()
                .enumerate()
                .map(|(j, (_, f))| text(f, stamps.get(j).copied().flatten())),
        );
        table.push_row(cells.iter().map(|s| s.as_str()), i as u64 + 1);
    }
    Ok(table)
}

/// A value as text; timestamps in ISO 8601.
fn text(f: &Field, stamp: Option<Stamp>) -> String {
    let instant = |v: i64, st: Stamp| {
        let (s, sub) = (v.div_euclid(st.per_second), v.rem_euclid(st.per_second));
        let nanos = sub * (1_000_000_000 / st.per_second);
        match Timestamp::new(s, nanos as i32) {
            Ok(t) if st.utc => t.to_string(),
            Ok(t) => jiff::tz::Offset::UTC.to_datetime(t).to_string(),
            Err(_) => format!("{v}"),
        }
    };
    match (f, stamp) {
        (Field::Null, _) => String::new(),
        (Field::Str(s), _) => s.clone(),
        (Field::Long(v), Some(st)) => instant(*v, st),
        (Field::TimestampMillis(v), st) => instant(
            *v,
            Stamp {
                per_second: 1_000,
                utc: st.is_none_or(|s| s.utc),
            },
        ),
        (Field::TimestampMicros(v), st) => instant(
            *v,
            Stamp {
                per_second: 1_000_000,
                utc: st.is_none_or(|s| s.utc),
            },
        ),
        (Field::Date(d), _) => jiff::civil::date(1970, 1, 1)
            .checked_add(jiff::Span::new().days(*d as i64))
            .map_or_else(|_| format!("{d}"), |d| d.to_string()),
        (Field::Double(v), _) => format!("{v}"),
        (Field::Float(v), _) => format!("{v}"),
        (Field::Bytes(b), _) => String::from_utf8_lossy(b.data()).into_owned(),
        (other, _) => other.to_string(),
    }
}
