//! A loop record read from a file: the column flags shared by diagnose, report and batch
//! ([`Columns`]), how to read the file ([`Reading`]: sheet, time format, zone), and the record
//! itself ([`LoopFile`]) with its gaps as NaN, its rows in time order and notes on what the
//! reader decided.

use crate::data::{self, ReadOptions, Table, TimeFormat, TimeSpec};
use crate::words::count;
use anyhow::{bail, Result};
use std::borrow::Cow;
use std::path::Path;
use stiction_core::diagnose::{DiagnoseRequest, LoopRecord};
use stiction_core::record::{self, PrepareError};
use stiction_report::{ColumnNames, LoopData};

/// How to read a data file beyond its columns: the sheet of a workbook, the form and the zone
/// of its times.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct Reading {
    /// Sheet of a workbook (xlsx, xls, ods) to read [default: the first]
    #[arg(long, value_name = "NAME")]
    pub sheet: Option<String>,
    /// Form of the time column: a strftime pattern such as '%d.%m.%Y %H:%M:%S', or seconds,
    /// epoch-ms, excel (serial days) [default: auto: numbers are seconds (milliseconds past
    /// 1e11), text is ISO 8601, DD.MM.YYYY, MM/DD/YYYY hh:mm:ss AM and other common forms]
    #[arg(long, value_name = "FMT", value_parser = check_time_format)]
    pub time_format: Option<String>,
    /// Time zone of local times without a zone in the text: an IANA name (Europe/Berlin), UTC
    /// or an offset (+01:00); needed where daylight saving changes [default: read as UTC]
    #[arg(long, value_name = "ZONE", value_parser = check_zone)]
    pub tz: Option<String>,
}

fn check_time_format(s: &str) -> Result<String, String> {
    s.parse::<TimeFormat>().map(|_| s.to_string())
}

fn check_zone(s: &str) -> Result<String, String> {
    data::time::zone(s).map(|_| s.to_string())
}

impl Reading {
    pub fn options(&self) -> ReadOptions {
        ReadOptions {
            sheet: self.sheet.clone(),
        }
    }

    /// Read a data file (or `-`, standard input) with these options.
    pub fn open(&self, path: &Path) -> Result<Table> {
        Table::read_with(path, &self.options())
    }

    /// The form and zone of the time column.
    pub fn time_spec(&self) -> Result<TimeSpec> {
        let format = match &self.time_format {
            Some(f) => f
                .parse()
                .map_err(|e| anyhow::anyhow!("--time-format: {e}"))?,
            None => TimeFormat::Auto,
        };
        let tz = self
            .tz
            .as_deref()
            .map(data::time::zone)
            .transpose()
            .map_err(|e| anyhow::anyhow!(e))?;
        Ok(TimeSpec { format, tz })
    }
}

/// The columns of a loop record and how to read them (shared by diagnose, report and batch).
#[derive(clap::Args, Clone)]
pub struct Columns {
    /// Column of the controller output
    #[arg(long, default_value = "op")]
    pub op: String,
    /// Column of the process variable
    #[arg(long, default_value = "pv")]
    pub pv: String,
    /// Column of the setpoint [default: none; the error is then PV's deviation from its mean]
    #[arg(long)]
    pub sp: Option<String>,
    /// Column of the controller mode (auto/manual or 1/0); only automatic stretches are judged
    #[arg(long)]
    pub mode: Option<String>,
    /// Column of the valve position, when recorded: direct evidence that outweighs the rest
    #[arg(long)]
    pub mv: Option<String>,
    /// OP values of a closed and a fully open valve, LO:HI (e.g. 0:1 or -1:1); the band is
    /// reported in % of this span [default: 0:100, OP in %]
    #[arg(long, value_name = "LO:HI", value_parser = parse_op_range)]
    pub op_range: Option<[f64; 2]>,
    /// Column of time (seconds, or dates such as 2024-03-01 12:00:05) [default: the first of t, time, timestamp, datetime, date and other common names, if present]
    #[arg(long)]
    pub time: Option<String>,
    /// Sampling time in seconds [default: the median step of the time column, else 1]
    #[arg(long)]
    pub ts: Option<f64>,
    /// The process is integrating (a level loop): the indices and the fits use their integrating
    /// variants [default: a column named by a tag (LIC..., FIC...) hints it, else the record's
    /// behaviour decides]
    #[arg(long, conflicts_with = "self_regulating")]
    pub integrating: bool,
    /// The process is self-regulating (not a level), whatever its tag or behaviour suggest
    #[arg(long)]
    pub self_regulating: bool,
    /// Closed-loop estimate: estimate where the valve stood at the first sample (as quantify
    /// --estimate-start; about 3-4x the estimate's time)
    #[arg(long)]
    pub estimate_start: bool,
    /// Also the hidden-valve family: a particle filter over a sticky valve that slips between
    /// the samples, on a loop that oscillates (about 1 s more on two cores, 3 s where it finds
    /// one: the median of three draws); it reports beside the verdict, which does not read it
    #[arg(long)]
    pub thorough: bool,
    #[command(flatten)]
    pub reading: Reading,
}

/// A loop record read from a file. Gaps (missing cells) are NaN in op, pv and sp, and not
/// automatic in `auto`; rows are in time order.
pub struct LoopFile {
    pub op: Vec<f64>,
    pub pv: Vec<f64>,
    pub sp: Option<Vec<f64>>,
    pub mv: Option<Vec<f64>>,
    pub time: Option<Vec<f64>>,
    pub auto: Option<Vec<bool>>,
    pub ts: f64,
    /// Cells treated as missing, per column (name, count), columns without any left out.
    pub missing: Vec<(String, usize)>,
    /// What the reader decided that a person should know (time order, time form, zone).
    pub notes: Vec<String>,
    /// The table row of each sample, when the rows were sorted by time or put on a grid (else
    /// sample k is row k).
    pub rows: Option<Vec<usize>>,
    /// The signals were stored at their own times and put on a regular grid: their blank cells
    /// stand for "nothing stored here" (the core's note says so), not for gaps.
    pub on_grid: bool,
}

impl LoopFile {
    pub fn record(&self) -> LoopRecord<'_> {
        LoopRecord {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            mv: self.mv.as_deref(),
            time: self.time.as_deref(),
            auto: self.auto.as_deref(),
        }
    }

    /// The signals as the HTML pages draw them.
    pub fn data(&self) -> LoopData<'_> {
        LoopData {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            time: self.time.as_deref(),
            auto: self.auto.as_deref(),
            ts: self.ts,
        }
    }

    /// The table row of sample `k`.
    pub fn row_of(&self, k: usize) -> usize {
        self.rows.as_ref().map_or(k, |r| r[k])
    }

    /// What reading decided, in words: the missing-cells note and the reader's notes.
    pub fn reading_notes(&self) -> Vec<String> {
        self.missing_note()
            .into_iter()
            .chain(self.notes.iter().cloned())
            .collect()
    }

    /// All cells treated as missing.
    pub fn missing_total(&self) -> usize {
        self.missing.iter().map(|(_, k)| k).sum()
    }

    /// One sentence on the missing cells, if any (for diagnose, report and batch); none when the
    /// signals were put on a grid (the blanks were between stored values).
    pub fn missing_note(&self) -> Option<String> {
        let total = self.missing_total();
        (total > 0 && !self.on_grid).then(|| {
            let which: Vec<String> = self
                .missing
                .iter()
                .map(|(name, k)| format!("{name} {k}"))
                .collect();
            format!(
                "{} treated as missing ({}: blank, NaN, #N/A or a historian state such as Bad Input): gaps in the record (short ones bridged, longer ones split it)",
                count(total, "cell", "cells"),
                which.join(", ")
            )
        })
    }
}

/// Which columns make a loop record: (column name, flag, role) of each signal.
pub struct Signals<'a> {
    pub op: &'a str,
    pub pv: &'a str,
    pub sp: Option<&'a str>,
    pub mv: Option<&'a str>,
    pub mode: Option<&'a str>,
    pub time: Option<&'a str>,
    pub ts: Option<f64>,
}

impl Columns {
    /// Read the file these columns come from (with `--sheet`), laid out so that they are
    /// named if need be (a header below a preamble, a narrow export: [`Table::for_columns`]).
    pub fn open(&self, path: &Path) -> Result<Table> {
        let t = self.reading.open(path)?;
        Ok(self.laid_out(&t).unwrap_or(t))
    }

    /// `table` laid out so that these columns are named ([`Table::for_columns`]), if need be.
    fn laid_out(&self, table: &Table) -> Option<Table> {
        let mut signals = vec![self.op.as_str(), self.pv.as_str()];
        signals.extend(
            [&self.sp, &self.mv, &self.mode]
                .into_iter()
                .flatten()
                .map(String::as_str),
        );
        let mut wanted = signals.clone();
        wanted.extend(self.time.as_deref());
        table.for_columns(&wanted, &signals, self.time.as_deref())
    }

    pub fn read(&self, table: &Table) -> Result<LoopFile> {
        if let (Some(want), Some(got)) = (&self.reading.sheet, &table.sheet) {
            if !want.trim().eq_ignore_ascii_case(got) {
                bail!(
                    "{}: sheet '{got}' was read, not '{want}' as --sheet asks (a bug: please report it)",
                    table.path.display()
                );
            }
        }
        let signals = Signals {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            mv: self.mv.as_deref(),
            mode: self.mode.as_deref(),
            time: self.time.as_deref(),
            ts: self.ts,
        };
        let spec = self.reading.time_spec()?;
        match self.laid_out(table) {
            Some(t) => read_loop(&t, &signals, &spec),
            None => read_loop(table, &signals, &spec),
        }
    }

    /// The column names as a loop's page shows them in its header.
    pub fn names(&self) -> ColumnNames {
        ColumnNames {
            op: self.op.clone(),
            pv: self.pv.clone(),
            sp: self.sp.clone(),
            mode: self.mode.clone(),
            time: self.time.clone(),
            integrating: self.integrating,
        }
    }

    /// The loop's kind as the flags say, else as a column's ISA-5.1 tag hints (PV's name first,
    /// then OP's), with the tag; `None` lets the record's behaviour decide.
    pub fn kind(&self) -> (Option<bool>, Option<String>) {
        if self.integrating {
            return (Some(true), None);
        }
        if self.self_regulating {
            return (Some(false), None);
        }
        [&self.pv, &self.op]
            .into_iter()
            .find_map(|name| stiction_core::diagnose::loop_kind::hinted_by_tag(name))
            .map_or((None, None), |(integrating, tag)| {
                (Some(integrating), Some(tag))
            })
    }

    pub fn request(&self, ts: f64) -> DiagnoseRequest {
        let (integrating, integrating_tag) = self.kind();
        DiagnoseRequest {
            ts,
            integrating,
            integrating_tag,
            estimate_start: self.estimate_start,
            thorough: self.thorough,
            op_range: self.op_range.unwrap_or([0.0, 100.0]),
            ..DiagnoseRequest::default()
        }
    }
}

/// `LO:HI` with LO < HI.
fn parse_op_range(text: &str) -> Result<[f64; 2], String> {
    let (lo, hi) = text
        .split_once(':')
        .ok_or_else(|| format!("'{text}' is not LO:HI (e.g. 0:100, 0:1 or -1:1)"))?;
    let num = |s: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("'{s}' in '{text}' is not a number"))
    };
    let (lo, hi) = (num(lo)?, num(hi)?);
    if hi <= lo {
        return Err(format!(
            "'{text}': the value of a fully open valve ({hi}) must exceed that of a closed one ({lo})"
        ));
    }
    Ok([lo, hi])
}

/// Blank cells of a mode column take the mode stored before them (in the order of the file).
fn hold_modes(table: &Table, col: usize, modes: &mut [bool]) {
    let mut last = false;
    for (i, m) in modes.iter_mut().enumerate() {
        if record::is_missing(table.cell(i, col)) {
            *m = last;
        } else {
            last = *m;
        }
    }
}

/// Read a loop record: numbers with gaps as NaN, the time axis in the given form and zone
/// (missing times filled in between their neighbours, their rows gaps), rows sorted by time.
pub fn read_loop(table: &Table, s: &Signals, spec: &TimeSpec) -> Result<LoopFile> {
    if let Some(ts) = s.ts {
        if !(ts > 0.0 && ts.is_finite()) {
            bail!("--ts {ts}: the sampling time must be a positive number of seconds");
        }
    }
    let file = table.path.display();
    if table.len() == 0 {
        return Err(table.no_rows());
    }
    let mut missing = Vec::new();
    let mut units = Vec::new();
    let mut column = |name: &str, flag: &str, role: &str| -> Result<Vec<f64>> {
        let c = table.require(name, flag, role)?;
        let v = table.numbers(c)?;
        if let Some(u) = table.unit(c) {
            units.push(format!(
                "'{u}' after every number of column '{}'",
                table.headers[c]
            ));
        }
        let k = v.iter().filter(|x| x.is_nan()).count();
        if k > 0 {
            missing.push((table.headers[c].clone(), k));
        }
        Ok(v)
    };
    let op = column(s.op, "--op", "controller output op")?;
    let pv = column(s.pv, "--pv", "process variable pv")?;
    let sp = s.sp.map(|c| column(c, "--sp", "setpoint sp")).transpose()?;
    let mv =
        s.mv.map(|c| column(c, "--mv", "valve position mv"))
            .transpose()?;
    let mut notes = table.notes.clone();
    if !units.is_empty() {
        notes.push(format!("{}: dropped, the numbers read", units.join("; ")));
    }
    let auto = match s.mode {
        Some(c) => {
            let col = table.require(c, "--mode", "controller mode")?;
            let k = table.missing(col);
            let mut modes = table.modes(col)?;
            if k < table.len() && k as f64 >= record::OWN_TIMES_SHARE * table.len() as f64 {
                // a mode stored only when it changes (a step tag): each held until the next
                hold_modes(table, col, &mut modes);
                notes.push(format!(
                    "the mode in column '{}' is stored only when it changes ({} blank): each mode is held until the next (manual before the first)",
                    table.headers[col],
                    count(k, "cell", "cells")
                ));
            } else if k > 0 {
                missing.push((table.headers[col].clone(), k));
            }
            Some(modes)
        }
        None => None,
    };
    let time_col = data::time_column(table, s.time)?;
    let time = match time_col {
        Some(c) => {
            let axis = table.time_axis(c, spec)?;
            notes.extend(axis.notes);
            if axis.missing > 0 {
                missing.push((table.headers[c].clone(), axis.missing));
            }
            Some(axis.seconds)
        }
        None => None,
    };
    // gaps in time, time order and the sampling time: the core's preparation, shared with Python
    let signals = record::Signals {
        op: Cow::Owned(op),
        pv: Cow::Owned(pv),
        sp: sp.map(Cow::Owned),
        mv: mv.map(Cow::Owned),
        auto: auto.map(Cow::Owned),
        time: time.map(Cow::Owned),
    };
    let p = record::prepare(signals, s.ts).map_err(|e| match e {
        PrepareError::Ts(ts) => {
            anyhow::anyhow!("--ts {ts}: the sampling time must be a positive number of seconds")
        }
        PrepareError::TimeNotIncreasing => anyhow::anyhow!(
            "{file}: the time column '{}' does not increase; give the sampling time with --ts SECONDS",
            table.headers[time_col.unwrap_or(0)]
        ),
        e => anyhow::anyhow!("{file}: {e}"),
    })?;
    notes.extend(p.notes);
    let on_grid = p.on_grid;
    if p.setpoint_held {
        // the setpoint's blanks were between stored values (the core's note says so)
        if let Some(c) = s.sp.and_then(|c| table.find(c)) {
            missing.retain(|(name, _)| *name != table.headers[c]);
        }
    }
    let v = p.signals;
    Ok(LoopFile {
        op: v.op.into_owned(),
        pv: v.pv.into_owned(),
        sp: v.sp.map(Cow::into_owned),
        mv: v.mv.map(Cow::into_owned),
        time: v.time.map(Cow::into_owned),
        auto: v.auto.map(Cow::into_owned),
        ts: p.ts,
        missing,
        notes,
        rows: p.rows,
        on_grid,
    })
}
