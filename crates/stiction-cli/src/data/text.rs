//! Delimited text (CSV, semicolon or tab separated; UTF-8 or UTF-16 with a byte-order mark, as
//! Excel's "Unicode text" writes; an Excel `sep=;` first line is honoured).

use super::table::Table;
use anyhow::{bail, Context, Result};
use std::borrow::Cow;
use std::path::Path;

/// The text of a file's bytes: UTF-16 when it starts with a UTF-16 byte-order mark, else UTF-8
/// (invalid bytes replaced), without a byte-order mark.
pub fn decode(bytes: &[u8]) -> Cow<'_, str> {
    let utf16 = |be: bool| -> String {
        let units = bytes[2..].chunks_exact(2).map(|c| {
            if be {
                u16::from_be_bytes([c[0], c[1]])
            } else {
                u16::from_le_bytes([c[0], c[1]])
            }
        });
        char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect()
    };
    match bytes {
        [0xFF, 0xFE, ..] => Cow::Owned(utf16(false)),
        [0xFE, 0xFF, ..] => Cow::Owned(utf16(true)),
        [0xEF, 0xBB, 0xBF, rest @ ..] => String::from_utf8_lossy(rest),
        _ => String::from_utf8_lossy(bytes),
    }
}

/// The delimiter the header line uses most: comma, semicolon or tab.
pub fn sniff_delimiter(header: &str) -> u8 {
    [b',', b';', b'\t']
        .into_iter()
        .max_by_key(|&d| header.bytes().filter(|&b| b == d).count())
        .unwrap_or(b',')
}

/// Line numbers from byte offsets, counted as the reading goes. (The csv reader's own line count
/// runs one short on files with CRLF line ends, as Windows programs write them: a record's
/// position there starts at the previous line's LF.)
#[derive(Default)]
struct LineCounter {
    byte: usize,
    newlines: u64,
}

impl LineCounter {
    /// The line (from 1) of the record at `byte` of `text` (offsets only grow).
    fn line_at(&mut self, text: &[u8], byte: usize) -> u64 {
        let start = byte
            + text[byte.min(text.len())..]
                .iter()
                .take_while(|&&c| c == b'\r' || c == b'\n')
                .count();
        let start = start.min(text.len());
        if start >= self.byte {
            self.newlines += text[self.byte..start]
                .iter()
                .filter(|&&c| c == b'\n')
                .count() as u64;
            self.byte = start;
        }
        self.newlines + 1
    }
}

/// A table from delimited text.
pub fn read(path: &Path, text: &str) -> Result<Table> {
    let file = path.display();
    let mut first_line = text.lines().next().unwrap_or("");
    let mut body = text;
    let mut line_offset = 0;
    // Excel's "sep=;" line names the delimiter and comes before the header
    let explicit = first_line
        .trim()
        .strip_prefix("sep=")
        .filter(|d| d.len() == 1)
        .map(|d| d.as_bytes()[0]);
    if explicit.is_some() {
        body = text.split_once('\n').map_or("", |(_, rest)| rest);
        first_line = body.lines().next().unwrap_or("");
        line_offset = 1;
    }
    if first_line.trim().is_empty() {
        bail!(
            "{file}: the file is empty or its first line is blank; it needs a header line naming the columns (e.g. t,op,mv)"
        );
    }
    let delimiter = explicit.unwrap_or_else(|| sniff_delimiter(first_line));
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .flexible(true)
        .has_headers(true)
        .from_reader(body.as_bytes());
    let headers: Vec<String> = reader
        .headers()
        .with_context(|| format!("{file}: the header line cannot be read"))?
        .iter()
        .map(|h| h.trim().to_string())
        .collect();
    let mut table = Table::new(path, headers);
    let width = table.headers.len();
    let mut record = csv::StringRecord::new();
    let mut lines = LineCounter::default();
    loop {
        let more = reader
            .read_record(&mut record)
            .with_context(|| format!("{file}: not a readable CSV file"))?;
        if !more {
            break;
        }
        let line = record
            .position()
            .map_or(0, |p| lines.line_at(body.as_bytes(), p.byte() as usize))
            + line_offset;
        if record.len() > width && record.iter().skip(width).any(|c| !c.trim().is_empty()) {
            bail!(
                "{file}: line {line} has {} cells but the header names {width} columns; remove the extra cells or name the column",
                record.len()
            );
        }
        table.push_row(record.iter(), line);
    }
    Ok(table)
}
