//! The table every reader produces: header names and rows of cells as text, with the line or
//! row each came from, so every message can name the file, the column and the row.

use super::missing::is_missing;
use super::time::TimeSpec;
use super::ReadOptions;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use stiction_core::record::{parse_number_grouped, Grouping};

/// What a row of a table is called in messages: a line of a text file, a row of a sheet or a
/// Parquet file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowWord {
    Line,
    Row,
}

impl std::fmt::Display for RowWord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RowWord::Line => "line",
            RowWord::Row => "row",
        })
    }
}

impl RowWord {
    /// `text` (written of lines) in these words.
    pub fn words(self, text: String) -> String {
        match self {
            RowWord::Line => text,
            RowWord::Row => text.replace(" line", " row"),
        }
    }
}

/// A data file read as text: header names and rows of cells.
pub struct Table {
    pub path: PathBuf,
    pub headers: Vec<String>,
    /// Every cell's trimmed text, one after the other (one allocation for the whole file) ...
    text: String,
    /// ... and where each is: row after row, each row as long as the header (missing trailing
    /// cells are empty).
    spans: Vec<(usize, usize)>,
    /// Line (text files) or row (sheets, Parquet) number of each row; the header is 1 in a
    /// text file.
    pub(super) lines: Vec<u64>,
    /// What a row is called in messages.
    pub(super) row_word: RowWord,
    /// The sheet read from a workbook ...
    pub sheet: Option<String>,
    /// ... and every sheet it has.
    pub sheets: Vec<String>,
    /// What reading decided that a person should know (a header found below a preamble).
    pub notes: Vec<String>,
}

impl Table {
    /// An empty table with these headers; rows are added with [`Table::push_row`].
    pub(super) fn new(path: &Path, headers: Vec<String>) -> Table {
        Table {
            path: path.to_path_buf(),
            headers,
            text: String::new(),
            spans: Vec::new(),
            lines: Vec::new(),
            row_word: RowWord::Line,
            sheet: None,
            sheets: Vec::new(),
            notes: Vec::new(),
        }
    }

    /// An empty table from the same file with other headers: its row words, sheets and notes
    /// kept (for a table laid out anew, [`Table::for_columns`]).
    pub(super) fn with_headers(&self, headers: Vec<String>) -> Table {
        let mut t = Table::new(&self.path, headers);
        t.row_word = self.row_word;
        t.sheet = self.sheet.clone();
        t.sheets = self.sheets.clone();
        t.notes = self.notes.clone();
        t
    }

    /// Messages call rows "row N" (sheets, Parquet) instead of "line N".
    pub(super) fn rows_are_rows(mut self) -> Table {
        self.row_word = RowWord::Row;
        self
    }

    /// Add one row (at most as many cells as headers; missing trailing cells are empty). A row
    /// of empty cells is skipped.
    pub(super) fn push_row<'a>(&mut self, cells: impl IntoIterator<Item = &'a str>, line: u64) {
        let start = self.spans.len();
        let mut any = false;
        for c in cells.into_iter().take(self.headers.len()) {
            let c = c.trim();
            any |= !c.is_empty();
            let a = self.text.len();
            self.text.push_str(c);
            self.spans.push((a, self.text.len()));
        }
        if !any {
            self.spans.truncate(start);
            return;
        }
        self.spans.resize(start + self.headers.len(), (0, 0));
        self.lines.push(line);
    }

    /// Read a file (`-`: standard input) in any format this tool reads, found from its bytes,
    /// with a sheet of a workbook chosen.
    pub fn read_with(path: &Path, opts: &ReadOptions) -> Result<Table> {
        if path.as_os_str() == "-" {
            let mut bytes = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin(), &mut bytes)
                .context("standard input cannot be read")?;
            return Self::parse_with(Path::new("<stdin>"), &bytes, opts);
        }
        match std::fs::read(path) {
            Ok(bytes) => Self::parse_with(path, &bytes, opts),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                bail!("{}: no such file; check the path", path.display())
            }
            Err(e) if e.kind() == std::io::ErrorKind::IsADirectory || path.is_dir() => bail!(
                "{}: is a folder; give a data file (batch takes folders)",
                path.display()
            ),
            Err(e) => bail!("{}: cannot be read: {e}", path.display()),
        }
    }

    /// A table from a file's bytes already in memory (CSV text, gzip, a workbook, Parquet);
    /// `path` names it in messages.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Table> {
        Self::parse_with(path, bytes, &ReadOptions::default())
    }

    /// As [`Table::parse`], with a sheet of a workbook chosen.
    pub fn parse_with(path: &Path, bytes: &[u8], opts: &ReadOptions) -> Result<Table> {
        super::format::parse(path, bytes, opts, 0)
    }

    pub fn len(&self) -> usize {
        self.lines.len()
    }

    /// The error for a table without data rows; a workbook's names its sheets.
    pub fn no_rows(&self) -> anyhow::Error {
        let file = self.path.display();
        match &self.sheet {
            Some(sheet) if self.sheets.len() > 1 => anyhow::anyhow!(
                "{file}: sheet '{sheet}' has no data rows; the sheets are {}: choose one with --sheet NAME",
                self.sheets
                    .iter()
                    .map(|n| format!("'{n}'"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => anyhow::anyhow!("{file}: the file has a header but no data rows"),
        }
    }

    /// Index of a column by name, case-insensitive.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.headers
            .iter()
            .position(|h| h.eq_ignore_ascii_case(name.trim()))
    }

    /// The column `name`, or an error naming the flag that chooses it.
    pub fn require(&self, name: &str, flag: &str, role: &str) -> Result<usize> {
        self.find(name).with_context(|| {
            // a narrow export (tag, time, value): the flags name tags, not columns
            let narrow = self.find("value").is_some() && self.headers.len() <= 4;
            format!(
                "{}: no column '{name}' for the {role}; the columns are {}. Name the right one with {flag} {}",
                self.path.display(),
                self.headers.join(", "),
                if narrow {
                    "TAG (the file looks narrow, a row per tag and time: give each signal's tag as it appears in the file, e.g. --op FIC101.OP --pv FIC101.PV)"
                } else {
                    "COLUMN"
                }
            )
        })
    }

    /// The trimmed text of a cell.
    pub fn cell(&self, row: usize, col: usize) -> &str {
        let (a, b) = self.spans[row * self.headers.len() + col];
        &self.text[a..b]
    }

    /// Where row `row` is, in words: "line 12" or "row 12".
    pub fn at(&self, row: usize) -> String {
        format!("{} {}", self.row_word, self.lines[row])
    }

    /// The line or row number of row `row` in the file.
    pub fn line(&self, row: usize) -> u64 {
        self.lines[row]
    }

    /// Parse a column as numbers: NaN where a cell is missing (blank, NaN, #N/A, a historian
    /// state such as Bad Input); an error for any other text.
    /// A unit written after every number of the column (`12.5 m3/h`, `45.2%`) is dropped
    /// ([`Table::unit`]).
    pub fn numbers<'t>(&'t self, col: usize) -> Result<Vec<f64>> {
        let name = &self.headers[col];
        let file = self.path.display();
        let mut out = Vec::with_capacity(self.len());
        let unit = self.unit(col);
        let bare = |cell: &'t str| -> &'t str {
            match &unit {
                Some(u) => cell.strip_suffix(u.as_str()).unwrap_or(cell).trim_end(),
                None => cell,
            }
        };
        // digits grouped by thousands: the convention the column's unambiguous cells show
        let cells: Vec<&str> = (0..self.len()).map(|i| bare(self.cell(i, col))).collect();
        let grouping = Grouping::of(cells.iter().copied());
        for (i, &cell) in cells.iter().enumerate() {
            if is_missing(cell) {
                out.push(f64::NAN);
                continue;
            }
            // a decimal comma (European historian exports, semicolon separated) reads as a point
            let v = parse_number_grouped(cell, grouping).with_context(|| {
                format!(
                    "{file}: {}, column '{name}': '{}' is not a number; use plain decimal numbers such as 12.5 \
                     (blank cells, NaN, #N/A and historian states such as Bad Input are read as gaps)",
                    self.at(i),
                    shown(cell)
                )
            })?;
            if !v.is_finite() {
                bail!(
                    "{file}: {}, column '{name}' is {cell}; a value must be a finite number: fill the cell or leave it blank (a gap)",
                    self.at(i)
                );
            }
            out.push(v);
        }
        Ok(out)
    }

    /// The unit every present cell of a column writes after its number (`12.5 m3/h`, `45.2 %`,
    /// `45.2%`): the same text of at most 12 characters, starting with neither a digit nor a
    /// sign; `None` when a cell has none or another.
    pub fn unit(&self, col: usize) -> Option<String> {
        let mut unit: Option<&str> = None;
        for i in 0..self.len() {
            let cell = self.cell(i, col);
            if is_missing(cell) {
                continue;
            }
            // the number ends at the first character no number holds (an e or E only as an
            // exponent, before a digit or a sign)
            let bytes = cell.as_bytes();
            let at = cell
                .char_indices()
                .find(|&(k, c)| {
                    let exponent = (c == 'e' || c == 'E')
                        && k > 0
                        && bytes
                            .get(k + 1)
                            .is_some_and(|b| b.is_ascii_digit() || *b == b'-' || *b == b'+');
                    !(c.is_ascii_digit() || ".,+- '".contains(c) || exponent)
                })
                .map(|(k, _)| k)?;
            let (number, u) = cell.split_at(at);
            let u = u.trim();
            let ok = !number.trim().is_empty()
                && u.len() <= 12
                && !u.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+');
            match unit {
                _ if !ok => return None,
                None => unit = Some(u),
                Some(v) if v != u => return None,
                Some(_) => {}
            }
        }
        unit.map(str::to_string)
    }

    /// How many cells of a column are missing values.
    pub fn missing(&self, col: usize) -> usize {
        (0..self.len())
            .filter(|&i| is_missing(self.cell(i, col)))
            .count()
    }

    /// Parse a mode column as `true` where the loop is in automatic: auto / manual (also AUT, MAN,
    /// cascade, CAS), 1 / 0, true / false, on / off. A missing cell is not automatic.
    pub fn modes(&self, col: usize) -> Result<Vec<bool>> {
        let name = &self.headers[col];
        let file = self.path.display();
        let mut out = Vec::with_capacity(self.len());
        for i in 0..self.len() {
            let cell = self.cell(i, col);
            let auto = match stiction_core::record::mode_word(cell) {
                Some(auto) => auto,
                None if is_missing(cell) => false,
                None => bail!(
                    "{file}: {}, column '{name}': '{}' is not a controller mode; use auto or manual (also 1 or 0)",
                    self.at(i),
                    shown(cell)
                ),
            };
            out.push(auto);
        }
        Ok(out)
    }

    /// Parse a time column as seconds (text timestamps: since 1970), in any form
    /// [`TimeSpec`]'s default reads; NaN where a cell is missing.
    #[allow(dead_code)] // part of the reading API the commands share; loops read time_axis
    pub fn times(&self, col: usize) -> Result<Vec<f64>> {
        Ok(self.time_axis(col, &TimeSpec::default())?.seconds)
    }
}

/// A cell's text as shown in a message: at most 40 characters.
pub(super) fn shown(cell: &str) -> String {
    let mut s: String = cell.chars().take(40).collect();
    if s.len() < cell.len() {
        s.push_str("...");
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column(cells: &[&str]) -> Table {
        let mut t = Table::new(Path::new("t.csv"), vec!["pv".into()]);
        for (i, c) in cells.iter().enumerate() {
            t.push_row([*c], i as u64 + 2);
        }
        t
    }

    #[test]
    fn a_unit_after_every_number_is_dropped() {
        let t = column(&["12.5 m3/h", "Bad Input", "1,234.5 m3/h", "-3e2 m3/h"]);
        assert_eq!(t.unit(0).as_deref(), Some("m3/h"));
        let v = t.numbers(0).unwrap();
        assert_eq!((v[0], v[2], v[3]), (12.5, 1234.5, -300.0));
        assert!(v[1].is_nan());
        assert_eq!(
            column(&["45.2%", "50%"]).numbers(0).unwrap(),
            vec![45.2, 50.0]
        );
        assert_eq!(
            column(&["12.5 EUR", "13 EUR"]).unit(0).as_deref(),
            Some("EUR")
        );
        // no unit, or units that differ: none dropped
        assert_eq!(column(&["12.5", "1e-3"]).unit(0), None);
        assert_eq!(column(&["12.5 m3/h", "13 kg/h"]).unit(0), None);
        assert!(column(&["12.5 m3/h", "13"]).numbers(0).is_err());
    }
}
