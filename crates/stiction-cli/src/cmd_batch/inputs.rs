//! What a batch reads: the INPUT arguments turned into sources (single-loop files and long-format
//! files holding many loops), loop ids that are safe file names and unique, and the stream of
//! jobs, one loop at a time, that the workers diagnose.

use crate::cmd_diagnose::Columns;
use anyhow::{bail, Context, Result};
use std::collections::{HashMap, HashSet};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::sync::mpsc::SyncSender;

/// A long-format file: many loops, the rows of each together, a column naming the loop.
pub struct LongFile {
    pub path: PathBuf,
    pub delimiter: u8,
    pub headers: Vec<String>,
    /// Index of the loop id column.
    pub id_col: usize,
}

pub enum Source {
    /// One loop per file; the loop id is the file stem.
    File(PathBuf),
    Long(LongFile),
}

/// Everything the INPUT arguments name, in order, each file once.
pub struct Inputs {
    pub sources: Vec<Source>,
    /// Total size of the input files, bytes (the progress of long-format files is measured in bytes).
    pub total_bytes: u64,
}

impl Inputs {
    /// Number of loops when known in advance (no long-format file).
    pub fn known_loops(&self) -> Option<usize> {
        self.sources
            .iter()
            .all(|s| matches!(s, Source::File(_)))
            .then_some(self.sources.len())
    }
}

/// One loop to diagnose.
pub struct Job {
    pub id: String,
    /// Where it came from, in words: a path, or a path and line range.
    pub source: String,
    /// Bytes of input it stands for (for the progress).
    pub weight: u64,
    pub data: JobData,
}

pub enum JobData {
    /// A single-loop CSV file.
    File(PathBuf),
    /// The rows of one loop of a long-format file, as a small CSV (header and rows), with the line
    /// of the long file each row comes from.
    Rows {
        file: PathBuf,
        csv: Vec<u8>,
        lines: Vec<u64>,
    },
    /// The loop cannot be read at all; the sentence says why.
    Fail(String),
}

fn has_glob_chars(s: &str) -> bool {
    s.contains(['*', '?', '['])
}

fn is_csv(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("csv"))
}

/// Expand the INPUT arguments: a folder gives every *.csv directly inside (by name), a pattern
/// every file it matches, a file itself. An argument that gives nothing is an error.
pub fn expand(args: &[String]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut seen = HashSet::new();
    for arg in args {
        let path = Path::new(arg);
        let found: Vec<PathBuf> = if path.is_dir() {
            let entries = std::fs::read_dir(path)
                .with_context(|| format!("{arg}: the folder cannot be read"))?;
            let mut v: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file() && is_csv(p))
                .collect();
            v.sort();
            if v.is_empty() {
                bail!("{arg}: no .csv files directly inside this folder; give the folder that holds the loop files, or a pattern such as '{arg}/**/*.csv'");
            }
            v
        } else if path.is_file() {
            vec![path.to_path_buf()]
        } else if has_glob_chars(arg) {
            let paths = glob::glob(arg).map_err(|e| {
                anyhow::anyhow!("'{arg}' is not a valid file pattern ({e}); quote patterns such as 'plant/*.csv'")
            })?;
            let v: Vec<PathBuf> = paths
                .filter_map(|p| p.ok())
                .filter(|p| p.is_file())
                .collect();
            if v.is_empty() {
                bail!("'{arg}' matches no file; check the folder and the pattern");
            }
            v
        } else {
            bail!("{arg}: no such file or folder; check the path");
        };
        for f in found {
            // the same file named twice (a folder and a pattern over it) is read once
            let key = std::fs::canonicalize(&f).unwrap_or_else(|_| f.clone());
            if seen.insert(key) {
                files.push(f);
            }
        }
    }
    Ok(files)
}

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

/// Sort the files into single-loop and long-format sources. A long-format file (one with the
/// loop id column) must name the columns the flags ask for: it is checked here, once, rather than
/// failing every one of its loops.
pub fn classify(files: Vec<PathBuf>, loop_id_col: &str, columns: &Columns) -> Result<Inputs> {
    let mut sources = Vec::with_capacity(files.len());
    let mut total_bytes = 0;
    for path in files {
        total_bytes += std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        let Some(line) = header_line(&path) else {
            sources.push(Source::File(path));
            continue;
        };
        let delimiter = crate::data::sniff_delimiter(&line);
        let headers = split_header(&line, delimiter);
        let find = |name: &str| {
            headers
                .iter()
                .position(|h| h.eq_ignore_ascii_case(name.trim()))
        };
        let Some(id_col) = find(loop_id_col) else {
            sources.push(Source::File(path));
            continue;
        };
        let mut wanted = vec![
            (columns.op.as_str(), "--op", "controller output op"),
            (columns.pv.as_str(), "--pv", "process variable pv"),
        ];
        if let Some(c) = &columns.sp {
            wanted.push((c, "--sp", "setpoint sp"));
        }
        if let Some(c) = &columns.mode {
            wanted.push((c, "--mode", "controller mode"));
        }
        if let Some(c) = &columns.time {
            wanted.push((c, "--time", "time"));
        }
        for (name, flag, role) in wanted {
            if find(name).is_none() {
                bail!(
                    "{}: no column '{name}' for the {role} in this long-format file (it has a '{}' column); the columns are {}. Name the right one with {flag} COLUMN",
                    path.display(),
                    headers[id_col],
                    headers.join(", ")
                );
            }
        }
        sources.push(Source::Long(LongFile {
            path,
            delimiter,
            headers,
            id_col,
        }));
    }
    Ok(Inputs {
        sources,
        total_bytes,
    })
}

/// A loop id as a file name: letters, digits and `- _ . + ~` kept, anything else `_`; never
/// empty, never hidden, at most 120 characters.
pub fn file_key(raw: &str) -> String {
    let mut s: String = raw
        .trim()
        .chars()
        .map(|c| {
            if c.is_alphanumeric() || "-_.+~".contains(c) {
                c
            } else {
                '_'
            }
        })
        .take(120)
        .collect();
    if s.starts_with('.') {
        s.replace_range(0..1, "_");
    }
    if s.is_empty() {
        s.push('_');
    }
    s
}

/// Unique loop ids, handed out in input order (so the same inputs always give the same ids): a
/// second loop with the id `X` is `X~2`, a third `X~3`. Ids differing only in case count as the
/// same (they would share a file on some file systems).
#[derive(Default)]
pub struct Ids {
    used: HashSet<String>,
    /// The first loop of each id (lower case): its id and source, to name both in the note.
    first: HashMap<String, (String, String)>,
    pub notes: Vec<String>,
    pub duplicates: usize,
}

impl Ids {
    pub fn assign(&mut self, raw: &str, source: &str) -> String {
        let key = file_key(raw);
        if self.used.insert(key.to_lowercase()) {
            self.first
                .insert(key.to_lowercase(), (key.clone(), source.to_string()));
            return key;
        }
        let mut n = 2;
        let id = loop {
            let candidate = format!("{key}~{n}");
            if self.used.insert(candidate.to_lowercase()) {
                break candidate;
            }
            n += 1;
        };
        self.duplicates += 1;
        if self.notes.len() < 5 {
            let (first_id, first_source) = self
                .first
                .get(&key.to_lowercase())
                .cloned()
                .unwrap_or_default();
            self.notes.push(if first_id == key {
                format!("loop id '{key}' is used by {first_source} and by {source}; the second is named '{id}'")
            } else {
                format!("loop ids '{first_id}' ({first_source}) and '{key}' ({source}) differ only in case; the second is named '{id}'")
            });
        }
        id
    }
}

/// Stream every loop of every source into `tx`, one at a time. Returns the ids handed out (with
/// their notes) when done, or early if the receiver hung up.
pub fn stream(sources: Vec<Source>, tx: SyncSender<Job>) -> Ids {
    let mut ids = Ids::default();
    for source in sources {
        let more = match source {
            Source::File(path) => {
                let stem = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                let shown = path.display().to_string();
                let job = Job {
                    id: ids.assign(&stem, &shown),
                    source: shown,
                    weight: std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0),
                    data: JobData::File(path),
                };
                tx.send(job).is_ok()
            }
            Source::Long(long) => stream_long(&long, &mut ids, &tx),
        };
        if !more {
            break;
        }
    }
    ids
}

/// The rows of one loop being gathered.
struct Group {
    raw_id: String,
    writer: csv::Writer<Vec<u8>>,
    lines: Vec<u64>,
    start_byte: u64,
    /// The loop's id was seen earlier in the file: its rows are not together.
    split: bool,
}

/// Read a long-format file once, front to back, and send each loop as soon as its last row is
/// read: only one loop's rows are held at a time.
fn stream_long(long: &LongFile, ids: &mut Ids, tx: &SyncSender<Job>) -> bool {
    let shown = long.path.display().to_string();
    let size = std::fs::metadata(&long.path).map(|m| m.len()).unwrap_or(0);
    let fail_rest = |ids: &mut Ids, why: String, weight: u64| {
        let stem = long
            .path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let id = ids.assign(&format!("{stem}~unread"), &shown);
        tx.send(Job {
            id,
            source: shown.clone(),
            weight,
            data: JobData::Fail(why),
        })
        .is_ok()
    };
    let mut file = match std::fs::File::open(&long.path) {
        Ok(f) => BufReader::with_capacity(1 << 20, f),
        Err(e) => {
            return fail_rest(ids, format!("{shown}: cannot be read: {e}"), size);
        }
    };
    if file
        .fill_buf()
        .is_ok_and(|b| b.starts_with(b"\xEF\xBB\xBF"))
    {
        file.consume(3);
    }
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(long.delimiter)
        .flexible(true)
        .has_headers(true)
        .from_reader(file);
    let mut seen: HashSet<String> = HashSet::new();
    let mut group: Option<Group> = None;
    let mut record = csv::ByteRecord::new();
    let id_name = &long.headers[long.id_col];

    // send the gathered loop; false if the receiver hung up
    let emit = |group: Group, end_byte: u64, ids: &mut Ids| -> bool {
        let first = group.lines.first().copied().unwrap_or(0);
        let last = group.lines.last().copied().unwrap_or(0);
        let mut source = format!("{shown} lines {first}-{last}");
        if file_key(&group.raw_id) != group.raw_id {
            source.push_str(&format!(" ({id_name} '{}')", group.raw_id));
        }
        let id = ids.assign(&group.raw_id, &source);
        let data = if group.raw_id.is_empty() {
            JobData::Fail(format!(
                "{shown}: lines {first} to {last} have an empty '{id_name}' cell; fill in the loop id of every row"
            ))
        } else if group.split {
            JobData::Fail(format!(
                "{shown}: the rows of loop '{}' at lines {first} to {last} come after rows of other loops; \
                 the rows of each loop must be together: sort the file by '{id_name}', keeping time order within each loop",
                group.raw_id
            ))
        } else {
            match group.writer.into_inner() {
                Ok(csv) => JobData::Rows {
                    file: long.path.clone(),
                    csv,
                    lines: group.lines,
                },
                Err(e) => JobData::Fail(format!("{shown}: lines {first} to {last}: {e}")),
            }
        };
        tx.send(Job {
            id,
            source,
            weight: end_byte.saturating_sub(group.start_byte),
            data,
        })
        .is_ok()
    };

    loop {
        let more = match reader.read_byte_record(&mut record) {
            Ok(more) => more,
            Err(e) => {
                let at = e.position().map_or(0, |p| p.byte());
                let line = e.position().map_or(0, |p| p.line());
                if let Some(g) = group.take() {
                    if !emit(g, at, ids) {
                        return false;
                    }
                }
                return fail_rest(
                    ids,
                    format!("{shown}: line {line} is not readable CSV ({e}); the loops from this line on were not read: repair the file"),
                    size.saturating_sub(at),
                );
            }
        };
        if !more {
            break;
        }
        if record.iter().all(|c| c.trim_ascii().is_empty()) {
            continue; // a blank line
        }
        let (line, byte) = record.position().map_or((0, 0), |p| (p.line(), p.byte()));
        let raw = record
            .get(long.id_col)
            .map(|c| String::from_utf8_lossy(c).trim().to_string())
            .unwrap_or_default();
        if group.as_ref().is_none_or(|g| g.raw_id != raw) {
            if let Some(g) = group.take() {
                if !emit(g, byte, ids) {
                    return false;
                }
            }
            let split = !seen.insert(raw.clone());
            let mut writer = csv::WriterBuilder::new()
                .delimiter(long.delimiter)
                .flexible(true)
                .from_writer(Vec::with_capacity(1 << 17));
            // cannot fail: the writer writes to memory
            let _ = writer.write_record(&long.headers);
            group = Some(Group {
                raw_id: raw,
                writer,
                lines: Vec::with_capacity(4096),
                start_byte: byte,
                split,
            });
        }
        if let Some(g) = group.as_mut() {
            if !g.split {
                let _ = g.writer.write_byte_record(&record);
            }
            g.lines.push(line);
        }
    }
    match group.take() {
        Some(g) => emit(g, size, ids),
        None => true,
    }
}
