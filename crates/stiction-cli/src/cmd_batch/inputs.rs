//! What a batch reads: the INPUT arguments turned into sources (single-loop files, wide files
//! holding several loops' columns, long-format files holding many loops' rows), loop ids that are
//! safe file names and unique, and the stream of jobs, one loop at a time, that the workers
//! diagnose.

use super::layout::{LoopList, LoopSpec};
use super::long::{stream_long, LongFile};
use super::stop::Stop;
use crate::data::Table;
use crate::loop_file::Columns;
use anyhow::{bail, Context, Result};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::mpsc::SyncSender;
use std::sync::Arc;

/// A loop found among a file's columns (by a loop list or a tag pattern).
pub struct WideLoop {
    pub raw_id: String,
    pub source: String,
    pub spec: LoopSpec,
    /// Why the loop cannot be read (a column it names is missing), found from the header.
    pub fail: Option<String>,
}

pub enum Source {
    /// One loop per file, the flags' columns; the loop id is the file stem.
    File(PathBuf),
    /// The loops among one file's columns, each with its own.
    Wide {
        path: PathBuf,
        loops: Vec<WideLoop>,
    },
    Long(LongFile),
    /// A loop of the loop list that cannot be read at all (its file does not exist).
    Fail {
        raw_id: String,
        source: String,
        why: String,
    },
}

/// Everything the INPUT arguments name, in order, each file once.
pub struct Inputs {
    pub sources: Vec<Source>,
    /// Total size of the input files, bytes (the progress of long-format files is measured in bytes).
    pub total_bytes: u64,
    /// What the classification noticed (files holding none of the listed loops).
    pub notes: Vec<String>,
    /// The loop list, and which of its loops were found so far.
    pub list: Option<(Arc<LoopList>, Vec<bool>)>,
}

impl Inputs {
    /// Number of loops when known in advance (no long-format file).
    pub fn known_loops(&self) -> Option<usize> {
        let mut n = 0;
        for s in &self.sources {
            n += match s {
                Source::File(_) | Source::Fail { .. } => 1,
                Source::Wide { loops, .. } => loops.len(),
                Source::Long(_) => return None,
            };
        }
        let unmatched = self
            .list
            .as_ref()
            .map_or(0, |(_, used)| used.iter().filter(|u| !**u).count());
        Some(n + unmatched)
    }
}

/// One loop to diagnose.
pub struct Job {
    pub id: String,
    /// Where it came from, in words: a path, or a path and line range.
    pub source: String,
    /// Bytes of input it stands for (for the progress).
    pub weight: u64,
    /// Its columns and options.
    pub spec: LoopSpec,
    pub data: JobData,
}

pub enum JobData {
    /// A CSV file to read.
    File(PathBuf),
    /// The rows of one loop of a long-format file, as a small CSV (header and rows), with the line
    /// of the long file each row comes from.
    Rows {
        file: PathBuf,
        csv: Vec<u8>,
        lines: Vec<u64>,
    },
    /// One loop's columns of a file read once for all its loops; `hash` of the file's bytes.
    Wide {
        file: PathBuf,
        table: Arc<Table>,
        hash: String,
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
    /// Was `id` handed out (as a file name: ignoring case)?
    pub fn contains(&self, id: &str) -> bool {
        self.used.contains(&id.to_lowercase())
    }

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

/// Stream every loop of every source into `tx`, one at a time, then a failed row for each loop
/// of the loop list found nowhere. Returns the ids handed out (with their notes) when done, or
/// early when the batch is asked to stop or the receiver hung up.
pub fn stream(inputs: Inputs, flags: Columns, tx: SyncSender<Job>, stop: &Stop) -> Ids {
    let mut ids = Ids::default();
    let mut list = inputs.list;
    let mut out = Out {
        ids: &mut ids,
        tx: &tx,
        stop,
    };
    for source in inputs.sources {
        let more = match source {
            Source::File(path) => {
                let stem = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                let shown = path.display().to_string();
                let weight = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
                out.send(
                    &stem,
                    shown,
                    weight,
                    LoopSpec::flags(&flags),
                    JobData::File(path),
                )
            }
            Source::Wide { path, loops } => stream_wide(path, loops, &mut out),
            Source::Long(long) => stream_long(&long, &flags, list.as_mut(), &mut out),
            Source::Fail {
                raw_id,
                source,
                why,
            } => out.send(
                &raw_id,
                source,
                0,
                LoopSpec::flags(&flags),
                JobData::Fail(why),
            ),
        };
        if !more {
            return ids;
        }
    }
    if let Some((list, used)) = list {
        for (e, _) in list.entries.iter().zip(used).filter(|(_, u)| !*u) {
            let why = format!(
                "loop '{}' ({}): no input file has its op column '{}' and no long-format file has a loop '{}'; check the loop list and the inputs",
                e.id, e.at, e.spec.columns.op, e.id
            );
            if !out.send(&e.id, e.at.clone(), 0, e.spec.clone(), JobData::Fail(why)) {
                break;
            }
        }
    }
    ids
}

/// Where the jobs go.
pub struct Out<'a> {
    pub ids: &'a mut Ids,
    pub tx: &'a SyncSender<Job>,
    pub stop: &'a Stop,
}

impl Out<'_> {
    /// Hand out a loop under a unique id; false when the batch stops or nobody listens.
    pub fn send(
        &mut self,
        raw_id: &str,
        source: String,
        weight: u64,
        spec: LoopSpec,
        data: JobData,
    ) -> bool {
        if self.stop.requested() {
            return false;
        }
        let id = self.ids.assign(raw_id, &source);
        self.tx
            .send(Job {
                id,
                source,
                weight,
                spec,
                data,
            })
            .is_ok()
    }
}

/// The loops of a wide file: the file is read and parsed once, its table shared by its loops (a
/// single loop reads its file itself, in a worker).
fn stream_wide(path: PathBuf, loops: Vec<WideLoop>, out: &mut Out) -> bool {
    let size = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
    let weight = size / loops.len().max(1) as u64;
    let usable = loops.iter().filter(|l| l.fail.is_none()).count();
    let shared = if usable > 1 {
        let read = std::fs::read(&path)
            .map_err(|e| format!("{}: cannot be read: {e}", path.display()))
            .and_then(|bytes| {
                let hash = super::resume::hash(&bytes);
                Table::parse(&path, &bytes)
                    .map(|t| (Arc::new(t), hash))
                    .map_err(|e| format!("{e:#}"))
            });
        Some(read)
    } else {
        None
    };
    for l in loops {
        let data = match (l.fail, &shared) {
            (Some(why), _) => JobData::Fail(why),
            (None, None) => JobData::File(path.clone()),
            (None, Some(Ok((table, hash)))) => JobData::Wide {
                file: path.clone(),
                table: Arc::clone(table),
                hash: hash.clone(),
            },
            (None, Some(Err(why))) => JobData::Fail(why.clone()),
        };
        if !out.send(&l.raw_id, l.source, weight, l.spec, data) {
            return false;
        }
    }
    true
}
