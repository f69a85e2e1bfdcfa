//! Reading the ISDB files (plain comma-separated numbers under a header), shared by the examples
//! that use `../shared/data/isdb`.

use std::path::Path;

/// A small CSV reader: header line, then numbers (the ISDB files are plain).
pub fn read_csv(path: &Path) -> Option<(Vec<String>, Vec<Vec<String>>)> {
    let text = std::fs::read_to_string(path).ok()?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()?
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let rows = lines
        .filter(|l| !l.trim().is_empty())
        .map(|l| l.split(',').map(|s| s.trim().to_string()).collect())
        .collect();
    Some((header, rows))
}

pub fn column(header: &[String], rows: &[Vec<String>], name: &str) -> Vec<f64> {
    let i = header
        .iter()
        .position(|h| h.eq_ignore_ascii_case(name))
        .expect("column");
    rows.iter().map(|r| r[i].parse().expect("number")).collect()
}
