//! Long-format files: many loops, one row per sample, a column naming the loop. The file is read
//! once, front to back, and each loop is handed out as soon as its last row is read, so only one
//! loop's rows are held at a time however large the file. The rows of each loop must be together
//! (the common export); rows of a loop that come after other loops' rows are a failed row asking
//! for the file to be sorted (its first stretch has already been diagnosed on its own).

use super::inputs::{JobData, Out};
use super::layout::{LoopList, LoopSpec};
use crate::loop_file::Columns;
use std::collections::HashSet;
use std::io::{BufRead, BufReader};
use std::path::PathBuf;
use std::sync::Arc;

/// A long-format file: many loops, the rows of each together, a column naming the loop.
pub struct LongFile {
    pub path: PathBuf,
    pub delimiter: u8,
    pub headers: Vec<String>,
    /// Index of the loop id column.
    pub id_col: usize,
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

/// What a long file's loops are read with: the flags, or a loop list's entry by loop id.
struct Specs<'a> {
    flags: &'a Columns,
    list: Option<&'a mut (Arc<LoopList>, Vec<bool>)>,
}

impl Specs<'_> {
    /// The loop's columns, and where a loop list names them.
    fn of(&mut self, raw_id: &str) -> (LoopSpec, Option<String>) {
        if let Some((list, used)) = self.list.as_mut() {
            if let Some(k) = list
                .entries
                .iter()
                .position(|e| e.file.is_none() && e.id.eq_ignore_ascii_case(raw_id))
            {
                used[k] = true;
                return (
                    list.entries[k].spec.clone(),
                    Some(list.entries[k].at.clone()),
                );
            }
        }
        (LoopSpec::flags(self.flags), None)
    }
}

/// Read a long-format file once and hand out each loop as soon as its last row is read.
/// False when the batch stops or nobody listens.
pub fn stream_long(
    long: &LongFile,
    flags: &Columns,
    list: Option<&mut (Arc<LoopList>, Vec<bool>)>,
    out: &mut Out,
) -> bool {
    let shown = long.path.display().to_string();
    let size = std::fs::metadata(&long.path).map(|m| m.len()).unwrap_or(0);
    let mut specs = Specs { flags, list };
    let stem = long
        .path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let fail_rest = |out: &mut Out, why: String, weight: u64| {
        out.send(
            &format!("{stem}~unread"),
            shown.clone(),
            weight,
            LoopSpec::flags(flags),
            JobData::Fail(why),
        )
    };
    let mut file = match std::fs::File::open(&long.path) {
        Ok(f) => BufReader::with_capacity(1 << 20, f),
        Err(e) => return fail_rest(out, format!("{shown}: cannot be read: {e}"), size),
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
    loop {
        let more = match reader.read_byte_record(&mut record) {
            Ok(more) => more,
            Err(e) => {
                let at = e.position().map_or(0, |p| p.byte());
                let line = e.position().map_or(0, |p| p.line());
                if let Some(g) = group.take() {
                    if !emit(long, g, at, &mut specs, out) {
                        return false;
                    }
                }
                return fail_rest(
                    out,
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
                if !emit(long, g, byte, &mut specs, out) {
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
        Some(g) => emit(long, g, size, &mut specs, out),
        None => true,
    }
}

/// Hand out a gathered loop; false if the batch stops or nobody listens.
fn emit(long: &LongFile, group: Group, end_byte: u64, specs: &mut Specs, out: &mut Out) -> bool {
    let shown = long.path.display();
    let id_name = &long.headers[long.id_col];
    let first = group.lines.first().copied().unwrap_or(0);
    let last = group.lines.last().copied().unwrap_or(0);
    let mut source = format!("{shown} lines {first}-{last}");
    if super::inputs::file_key(&group.raw_id) != group.raw_id {
        source.push_str(&format!(" ({id_name} '{}')", group.raw_id));
    }
    let (spec, listed) = specs.of(&group.raw_id);
    let missing = listed.and_then(|at| {
        spec.missing_column(&long.headers).map(|(col, role)| {
            format!(
                "{shown}: no column '{col}' for the {role} of loop '{}' ({at}); the columns are {}. Correct the loop list",
                group.raw_id,
                long.headers.join(", ")
            )
        })
    });
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
    } else if let Some(why) = missing {
        JobData::Fail(why)
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
    out.send(
        &group.raw_id,
        source,
        end_byte.saturating_sub(group.start_byte),
        spec,
        data,
    )
}
