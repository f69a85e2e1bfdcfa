//! What `--resume` needs to trust an earlier result: each `loops/<id>.json` records where its
//! loop came from (path, size, modification time, a fast hash of the bytes read) and the settings
//! it was diagnosed with. A loop is kept only when both are unchanged; otherwise it is diagnosed
//! again.

use crate::loop_file::Columns;
use serde::{Deserialize, Serialize};
use std::path::Path;
use stiction_core::diagnose::Diagnosis;

/// The columns and options a loop was diagnosed with.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoopSettings {
    pub op: String,
    pub pv: String,
    pub sp: Option<String>,
    pub mode: Option<String>,
    /// The valve position, when recorded.
    pub mv: Option<String>,
    /// The OP values of a closed and an open valve.
    #[serde(default)]
    pub op_range: Option<[f64; 2]>,
    pub time: Option<String>,
    pub ts: Option<f64>,
    pub integrating: bool,
    /// `--self-regulating`.
    #[serde(default)]
    pub self_regulating: bool,
    pub estimate_start: bool,
    /// The hidden-valve family (`--thorough`).
    #[serde(default)]
    pub thorough: bool,
    pub quantify: bool,
}

impl LoopSettings {
    pub fn new(c: &Columns, quantify: bool) -> LoopSettings {
        LoopSettings {
            op: c.op.clone(),
            pv: c.pv.clone(),
            sp: c.sp.clone(),
            mode: c.mode.clone(),
            mv: c.mv.clone(),
            op_range: c.op_range,
            time: c.time.clone(),
            ts: c.ts,
            integrating: c.integrating,
            self_regulating: c.self_regulating,
            estimate_start: c.estimate_start,
            thorough: c.thorough,
            quantify,
        }
    }
}

/// Where a loop came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Input {
    /// In words, as in the summary's source column.
    pub source: String,
    pub path: String,
    /// Of the file, bytes.
    pub size: u64,
    /// Of the file (RFC 3339), when the file system tells.
    pub modified: Option<String>,
    /// XXH3-64 of the bytes read for this loop (of a long-format file: of this loop's rows), hex.
    pub hash: String,
    pub settings: LoopSettings,
}

impl Input {
    /// The stamp of `bytes` read from `path` (whose metadata is looked up here).
    pub fn of(source: &str, path: &Path, bytes: &[u8], settings: LoopSettings) -> Input {
        let meta = std::fs::metadata(path).ok();
        let modified = meta
            .as_ref()
            .and_then(|m| m.modified().ok())
            .and_then(|t| jiff::Timestamp::try_from(t).ok())
            .map(|t| t.to_string());
        Input {
            source: source.to_string(),
            path: path.display().to_string(),
            size: meta.map_or(0, |m| m.len()),
            modified,
            hash: hash(bytes),
            settings,
        }
    }

    /// Does an earlier result still stand for this input? The same bytes and settings (the
    /// path, size and time may differ: a file copied unchanged is the same loop).
    pub fn same_loop(&self, earlier: &Input) -> bool {
        self.hash == earlier.hash && self.settings == earlier.settings
    }
}

pub fn hash(bytes: &[u8]) -> String {
    format!("{:016x}", xxhash_rust::xxh3::xxh3_64(bytes))
}

/// `loops/<id>.json`: the loop's input, then the diagnosis' own fields (so the file reads as a
/// `Diagnosis` too).
#[derive(Serialize, Deserialize)]
pub struct LoopJson {
    /// Absent in the files of earlier versions.
    #[serde(default)]
    pub input: Option<Input>,
    #[serde(flatten)]
    pub diagnosis: Diagnosis,
}

/// The same, borrowed, for writing.
#[derive(Serialize)]
pub struct LoopJsonRef<'a> {
    pub input: &'a Input,
    #[serde(flatten)]
    pub diagnosis: &'a Diagnosis,
}

/// An earlier run's result for a loop.
pub enum Earlier {
    /// No file.
    None,
    /// A file that is not a loop result of this version (or cannot be read).
    Unusable,
    Found(Box<LoopJson>),
}

pub fn earlier(path: &Path) -> Earlier {
    match std::fs::read(path) {
        Err(_) => Earlier::None,
        Ok(bytes) => match parse(&bytes) {
            Some(j) if j.input.is_some() => Earlier::Found(Box::new(j)),
            _ => Earlier::Unusable,
        },
    }
}

/// A loop JSON as written. `Diagnosis` leaves out an empty `windows` list when written but needs
/// it when read (the core has no `serde(default)` on it): it is put back first.
pub fn parse(bytes: &[u8]) -> Option<LoopJson> {
    let mut v: serde_json::Value = serde_json::from_slice(bytes).ok()?;
    v.as_object_mut()?
        .entry("windows")
        .or_insert_with(|| serde_json::Value::Array(Vec::new()));
    serde_json::from_value(v).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use stiction_core::diagnose::{diagnose, DiagnoseRequest, LoopRecord};
    use stiction_core::models::{Model, Stenman};
    use stiction_core::sim::ClosedLoop;

    /// What --resume reads back is the diagnosis that was written, to the last bit.
    #[test]
    fn a_loop_json_reads_back_as_written() {
        let mut cl = ClosedLoop::new(Model::Stenman(Stenman::new(2.0).unwrap()));
        cl.samples = 1500;
        cl.noise = 0.05;
        let data = cl.run().unwrap();
        let record = LoopRecord {
            op: &data.op,
            pv: &data.pv,
            sp: Some(&data.sp),
            mv: None,
            time: None,
            auto: None,
        };
        let d = diagnose(&record, &DiagnoseRequest::default()).unwrap();
        let c = Columns {
            op: "op".into(),
            pv: "pv".into(),
            sp: None,
            mode: None,
            time: None,
            ts: Some(1.0),
            integrating: false,
            self_regulating: false,
            estimate_start: false,
            thorough: false,
            mv: Some("mv".into()),
            op_range: None,
            reading: Default::default(),
        };
        let input = Input::of(
            "x.csv",
            Path::new("x.csv"),
            b"t,op,pv",
            LoopSettings::new(&c, true),
        );
        let bytes = serde_json::to_vec_pretty(&LoopJsonRef {
            input: &input,
            diagnosis: &d,
        })
        .unwrap();
        let back = parse(&bytes).expect("reads back");
        // the traces the JSON leaves out aside, the same diagnosis: written again, the same text
        let again = serde_json::to_vec_pretty(&LoopJsonRef {
            input: back.input.as_ref().unwrap(),
            diagnosis: &back.diagnosis,
        })
        .unwrap();
        assert_eq!(
            String::from_utf8(again).unwrap(),
            String::from_utf8(bytes).unwrap()
        );
        assert_eq!(
            stiction_core::fleet::Row::from_diagnosis("x", "x.csv", &back.diagnosis),
            stiction_core::fleet::Row::from_diagnosis("x", "x.csv", &d)
        );
        assert!(parse(b"{\"verdict\": \"stiction\"}").is_none());
    }
}
