//! Reading loop data from CSV: delimiter sniffing, case-insensitive column lookup, and one clear
//! sentence for every way a file can be wrong (naming the file, the column and the line).

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// A CSV file read as text: header names and rows of cells.
pub struct Table {
    pub path: PathBuf,
    pub headers: Vec<String>,
    /// Every cell's trimmed text, one after the other (one allocation for the whole file) ...
    text: String,
    /// ... and where each is: row after row, each row as long as the header (missing trailing
    /// cells are empty).
    spans: Vec<(usize, usize)>,
    /// File line number of each row (the header is line 1).
    lines: Vec<u64>,
}

impl Table {
    pub fn read(path: &Path) -> Result<Table> {
        match std::fs::read(path) {
            Ok(bytes) => Self::parse(path, &bytes),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                bail!("{}: no such file; check the path", path.display())
            }
            Err(e) => bail!("{}: cannot be read: {e}", path.display()),
        }
    }

    /// A table from CSV text already in memory; `path` names it in messages.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Table> {
        let text = String::from_utf8_lossy(bytes);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let first_line = text.lines().next().unwrap_or("");
        if first_line.trim().is_empty() {
            bail!(
                "{}: the file is empty or its first line is blank; it needs a header line naming the columns (e.g. t,op,mv)",
                path.display()
            );
        }
        let delimiter = sniff_delimiter(first_line);
        let mut reader = csv::ReaderBuilder::new()
            .delimiter(delimiter)
            .flexible(true)
            .has_headers(true)
            .from_reader(text.as_bytes());
        let headers: Vec<String> = reader
            .headers()
            .with_context(|| format!("{}: the header line cannot be read", path.display()))?
            .iter()
            .map(|h| h.trim().to_string())
            .collect();
        let mut cells = String::with_capacity(text.len());
        let mut spans = Vec::new();
        let mut lines = Vec::new();
        let mut record = csv::StringRecord::new();
        loop {
            let more = reader
                .read_record(&mut record)
                .with_context(|| format!("{}: not a readable CSV file", path.display()))?;
            if !more {
                break;
            }
            let line = record.position().map(|p| p.line()).unwrap_or(0);
            if record.iter().all(|c| c.trim().is_empty()) {
                continue; // blank line
            }
            if record.len() > headers.len() {
                bail!(
                    "{}: line {line} has {} cells but the header names {} columns; remove the extra cells or name the column",
                    path.display(),
                    record.len(),
                    headers.len()
                );
            }
            for c in record.iter() {
                let start = cells.len();
                cells.push_str(c.trim());
                spans.push((start, cells.len()));
            }
            spans.resize(spans.len() + headers.len() - record.len(), (0, 0));
            lines.push(line);
        }
        Ok(Table {
            path: path.to_path_buf(),
            headers,
            text: cells,
            spans,
            lines,
        })
    }

    pub fn len(&self) -> usize {
        self.lines.len()
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
            format!(
                "{}: no column '{name}' for the {role}; the columns are {}. Name the right one with {flag} COLUMN",
                self.path.display(),
                self.headers.join(", ")
            )
        })
    }

    /// The trimmed text of a cell.
    fn cell(&self, row: usize, col: usize) -> &str {
        let (a, b) = self.spans[row * self.headers.len() + col];
        &self.text[a..b]
    }

    /// Parse a column as finite numbers.
    pub fn numbers(&self, col: usize) -> Result<Vec<f64>> {
        let name = &self.headers[col];
        let file = self.path.display();
        let mut out = Vec::with_capacity(self.len());
        for i in 0..self.len() {
            let cell = self.cell(i, col);
            let line = self.lines[i];
            if cell.is_empty() {
                let rest_empty = (i..self.len()).all(|r| self.cell(r, col).is_empty());
                if rest_empty {
                    bail!(
                        "{file}: column '{name}' ends at line {line} with {} values while the file has {} rows; \
                         columns of different lengths cannot be paired sample by sample: trim the file to the rows where every column has a value",
                        out.len(),
                        self.len()
                    );
                }
                bail!("{file}: line {line}, column '{name}' is empty; fill in the value or remove the row");
            }
            // a decimal comma (European historian exports, semicolon separated) reads as a point
            let v: f64 = parse_number(cell).ok_or_else(|| {
                anyhow::anyhow!(
                    "{file}: line {line}, column '{name}': '{cell}' is not a number; use plain decimal numbers such as 12.5"
                )
            })?;
            if !v.is_finite() {
                bail!(
                    "{file}: line {line}, column '{name}' is {cell}; every value must be a finite number: remove or fill the row"
                );
            }
            out.push(v);
        }
        Ok(out)
    }

    /// Parse a mode column as `true` where the loop is in automatic: auto / manual (also AUT, MAN,
    /// cascade, CAS), 1 / 0, true / false, on / off.
    pub fn modes(&self, col: usize) -> Result<Vec<bool>> {
        let name = &self.headers[col];
        let file = self.path.display();
        let mut out = Vec::with_capacity(self.len());
        for i in 0..self.len() {
            let cell = self.cell(i, col).to_ascii_lowercase();
            let auto = match cell.as_str() {
                "auto" | "automatic" | "aut" | "a" | "1" | "true" | "on" | "cascade" | "cas" => true,
                "manual" | "man" | "m" | "0" | "false" | "off" => false,
                _ => bail!(
                    "{file}: line {}, column '{name}': '{}' is not a controller mode; use auto or manual (also 1 or 0)",
                    self.lines[i],
                    self.cell(i, col)
                ),
            };
            out.push(auto);
        }
        Ok(out)
    }

    /// Parse a time column: seconds as numbers, or text timestamps (ISO 8601, `YYYY-MM-DD HH:MM:SS`),
    /// returned as seconds (text timestamps: since 1970).
    pub fn times(&self, col: usize) -> Result<Vec<f64>> {
        let name = &self.headers[col];
        let file = self.path.display();
        let mut out = Vec::with_capacity(self.len());
        for i in 0..self.len() {
            let cell = self.cell(i, col);
            let line = self.lines[i];
            let v = cell
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .or_else(|| crate::timestamp::parse(cell));
            match v {
                Some(v) => out.push(v),
                None => bail!(
                    "{file}: line {line}, column '{name}': '{cell}' is neither a number of seconds nor a date and time \
                     such as 2024-03-01 12:00:05 or 2024-03-01T12:00:05Z"
                ),
            }
        }
        Ok(out)
    }
}

/// A number with a decimal point, or with a decimal comma and no point (`12,5`).
fn parse_number(cell: &str) -> Option<f64> {
    cell.parse().ok().or_else(|| {
        (cell.matches(',').count() == 1 && !cell.contains('.'))
            .then(|| cell.replace(',', ".").parse().ok())
            .flatten()
    })
}

/// The median step of a time column, if time increases.
pub fn sampling_time(t: &[f64]) -> Option<f64> {
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    let ts = steps[steps.len() / 2];
    (ts > 0.0 && ts.is_finite()).then_some(ts)
}

/// The delimiter the header line uses most: comma, semicolon or tab.
pub fn sniff_delimiter(header: &str) -> u8 {
    [b',', b';', b'\t']
        .into_iter()
        .max_by_key(|&d| header.bytes().filter(|&b| b == d).count())
        .unwrap_or(b',')
}

/// The time column: `--time COL` if given, else the first of t, time, timestamp.
pub fn time_column(table: &Table, explicit: Option<&str>) -> Result<Option<usize>> {
    match explicit {
        Some(name) => table.require(name, "--time", "time").map(Some),
        None => Ok(["t", "time", "timestamp"]
            .iter()
            .find_map(|n| table.find(n))),
    }
}

/// Read two columns (e.g. op and mv) ready for estimation, with the checks that apply to both.
/// A time column named with `--time` must exist and parse, though estimation does not use it.
pub fn read_pair(
    path: &Path,
    (a_name, a_flag, a_role): (&str, &str, &str),
    (b_name, b_flag, b_role): (&str, &str, &str),
    time: Option<&str>,
    min_samples: usize,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let table = Table::read(path)?;
    let a = table.require(a_name, a_flag, a_role)?;
    let b = table.require(b_name, b_flag, b_role)?;
    if let Some(col) = time
        .map(|name| time_column(&table, Some(name)))
        .transpose()?
        .flatten()
    {
        table.times(col)?;
    }
    if table.len() < min_samples {
        bail!(
            "{}: only {} rows of data; estimation needs at least {min_samples} samples",
            path.display(),
            table.len()
        );
    }
    let av = table.numbers(a)?;
    let bv = table.numbers(b)?;
    let (lo, hi) = av
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    if hi - lo <= 0.0 {
        bail!(
            "{}: column '{}' ({a_role}) is constant at {lo}; a valve whose command never moves shows no stiction, choose a stretch of data where {a_role} varies",
            path.display(),
            table.headers[a]
        );
    }
    Ok((av, bv))
}
