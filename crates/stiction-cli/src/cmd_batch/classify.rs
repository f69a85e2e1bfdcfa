//! Sorting the input files into sources by the layout: long-format files (with the loop id
//! column), wide files (the loops a loop list or a tag pattern finds among their columns) and
//! single-loop files. Only each file's header is read here.

use super::inputs::{Inputs, Source, WideLoop};
use super::layout::{Layout, LoopList, LoopSpec, TagPattern};
use super::long::LongFile;
use crate::loop_file::Columns;
use anyhow::{bail, Result};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The header line of a file (without a byte-order mark), or `None` when it cannot be read.
fn header_line(path: &Path) -> Option<String> {
    let mut r = BufReader::new(std::fs::File::open(path).ok()?);
    let mut bytes = Vec::new();
    r.read_until(b'\n', &mut bytes).ok()?;
    let line = String::from_utf8_lossy(&bytes).into_owned();
    Some(line.trim_start_matches('\u{feff}').trim_end().to_string())
}

fn split_header(line: &str, delimiter: u8) -> Vec<String> {
    let mut r = csv::ReaderBuilder::new()
        .delimiter(delimiter)
        .has_headers(false)
        .flexible(true)
        .from_reader(line.as_bytes());
    r.records()
        .next()
        .and_then(|x| x.ok())
        .map(|rec| rec.iter().map(|h| h.trim().to_string()).collect())
        .unwrap_or_default()
}

/// Sort the files into sources by the layout.
/// A long-format file read with the flags must name the columns they ask for: checked here, once,
/// rather than failing every one of its loops.
pub fn classify(
    mut files: Vec<PathBuf>,
    loop_id_col: &str,
    flags: &Columns,
    layout: Layout,
) -> Result<Inputs> {
    let mut sources = Vec::with_capacity(files.len());
    let mut notes = Vec::new();
    let (list, tags) = match layout {
        Layout::Flags => (None, None),
        Layout::List(list) => (Some(list), None),
        Layout::Tags(tags) => (None, Some(tags)),
    };
    let mut used = vec![false; list.as_ref().map_or(0, |l| l.entries.len())];
    if let Some(list) = &list {
        add_listed_files(list, &mut files, &mut used, &mut sources);
    }
    let mut total_bytes = 0;
    for path in files {
        total_bytes += std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        let Some(line) = header_line(&path) else {
            sources.push(Source::File(path));
            continue;
        };
        let delimiter = crate::data::sniff_delimiter(&line);
        let headers = split_header(&line, delimiter);
        if let Some(id_col) = find(&headers, loop_id_col) {
            if list.is_none() {
                check_long_columns(&path, &headers, id_col, flags)?;
            }
            sources.push(Source::Long(LongFile {
                path,
                delimiter,
                headers,
                id_col,
            }));
        } else if let Some(list) = &list {
            let loops = listed_loops(list, &path, &headers, &mut used);
            if loops.is_empty() {
                notes.push(format!(
                    "{}: holds none of the loops of {}; it was not read",
                    path.display(),
                    list.path.display()
                ));
            } else {
                sources.push(Source::Wide { path, loops });
            }
        } else if let Some(tags) = &tags {
            let loops = tagged_loops(tags, &path, &headers, flags);
            sources.push(if loops.is_empty() {
                Source::File(path)
            } else {
                Source::Wide { path, loops }
            });
        } else {
            sources.push(Source::File(path));
        }
    }
    Ok(Inputs {
        sources,
        total_bytes,
        notes,
        list: list.map(|l| (Arc::new(l), used)),
    })
}

fn find(headers: &[String], name: &str) -> Option<usize> {
    headers
        .iter()
        .position(|h| h.eq_ignore_ascii_case(name.trim()))
}

fn check_long_columns(path: &Path, headers: &[String], id_col: usize, c: &Columns) -> Result<()> {
    let mut wanted = vec![
        (c.op.as_str(), "--op", "controller output op"),
        (c.pv.as_str(), "--pv", "process variable pv"),
    ];
    for (col, flag, role) in [
        (&c.sp, "--sp", "setpoint sp"),
        (&c.mode, "--mode", "controller mode"),
        (&c.time, "--time", "time"),
    ] {
        if let Some(col) = col {
            wanted.push((col, flag, role));
        }
    }
    for (name, flag, role) in wanted {
        if find(headers, name).is_none() {
            bail!(
                "{}: no column '{name}' for the {role} in this long-format file (it has a '{}' column); the columns are {}. Name the right one with {flag} COLUMN",
                path.display(),
                headers[id_col],
                headers.join(", ")
            );
        }
    }
    Ok(())
}

fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => a == b,
    }
}

/// The files a loop list names are read even when not among the INPUT arguments; a loop whose
/// file does not exist is a failed row.
fn add_listed_files(
    list: &LoopList,
    files: &mut Vec<PathBuf>,
    used: &mut [bool],
    sources: &mut Vec<Source>,
) {
    for (k, e) in list.entries.iter().enumerate() {
        let Some(file) = &e.file else { continue };
        if !file.is_file() {
            used[k] = true;
            sources.push(Source::Fail {
                raw_id: e.id.clone(),
                source: e.at.clone(),
                why: format!(
                    "{}: no such file for loop '{}' ({}); correct its file in the loop list",
                    file.display(),
                    e.id,
                    e.at
                ),
            });
        } else if !files.iter().any(|f| same_file(f, file)) {
            files.push(file.clone());
        }
    }
}

/// The loops of a loop list in one file: those naming it, and those naming no file whose op
/// column it has (or whose id is its stem). A loop naming a column the file lacks fails here.
fn listed_loops(
    list: &LoopList,
    path: &Path,
    headers: &[String],
    used: &mut [bool],
) -> Vec<WideLoop> {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut loops = Vec::new();
    for (k, e) in list.entries.iter().enumerate() {
        let here = match &e.file {
            Some(f) => same_file(f, path),
            None => find(headers, &e.spec.columns.op).is_some() || e.id == stem,
        };
        if !here {
            continue;
        }
        used[k] = true;
        // a narrow file (tag, time, value) names its signals in a column, not in its header:
        // reading pivots it and names a missing tag
        let narrow = find(headers, "value").is_some() && headers.len() <= 6;
        let fail = (!narrow).then(|| e.spec.missing_column(headers)).flatten().map(|(col, role)| {
            format!(
                "{}: no column '{col}' for the {role} of loop '{}' ({}); the columns are {}. Correct the loop list",
                path.display(),
                e.id,
                e.at,
                headers.join(", ")
            )
        });
        loops.push(WideLoop {
            raw_id: e.id.clone(),
            source: format!("{} ({})", path.display(), e.at),
            spec: e.spec.clone(),
            fail,
        });
    }
    loops
}

/// The loops a tag pattern finds among a file's columns; one without an op or pv column fails.
fn tagged_loops(
    tags: &TagPattern,
    path: &Path,
    headers: &[String],
    flags: &Columns,
) -> Vec<WideLoop> {
    tags.split(headers)
        .into_iter()
        .map(|t| {
            let col = |role: &str| t.columns.get(role).cloned();
            let fail = ["op", "pv"].into_iter().find(|r| col(r).is_none()).map(|role| {
                let found: Vec<&str> = t.columns.values().map(String::as_str).collect();
                format!(
                    "{}: loop '{}' has no {role} column (--tags '{}' looks for '{}'; the loop's columns are {})",
                    path.display(),
                    t.loop_name,
                    tags.text,
                    tags.expected(&t.loop_name, role),
                    found.join(", ")
                )
            });
            let found: Vec<&str> = t.columns.values().map(String::as_str).collect();
            WideLoop {
                source: format!("{} columns {}", path.display(), found.join(", ")),
                spec: LoopSpec {
                    columns: Columns {
                        op: col("op").unwrap_or_default(),
                        pv: col("pv").unwrap_or_default(),
                        sp: col("sp"),
                        mode: col("mode"),
                        mv: col("mv"),
                        ..flags.clone()
                    },
                },
                raw_id: t.loop_name,
                fail,
            }
        })
        .collect()
}
