//! The real labelled records the verdict is judged on first: the 20 plant windows of
//! `../shared/data/plant-dev` (Xue et al.'s StictionGPT study, Apache 2.0) and the 14 ISDB loops
//! with OP and PV of `../shared/data/isdb` (Jelali and Huang 2010; labels as Damarla et al.'s test
//! set). Read as `stiction diagnose FILE --op op --pv pv --sp sp --mode mode` reads them; absent
//! data give `None` (a user's clone has no `../shared`).

use crate::isdb::{column, read_csv};
use std::path::Path;
use stiction_core::diagnose::{DiagnoseRequest, LoopRecord};

/// Where a real record comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RealSource {
    /// A plant window of plant-dev.
    Plant,
    /// An ISDB loop.
    Isdb,
}

/// One real record and its label.
#[derive(Debug, Clone)]
pub struct RealRecord {
    /// The file's name without `.csv` (`ISDB_` before an ISDB loop's name).
    pub name: String,
    /// The loop (tag) it belongs to: every window of one tag is left out together.
    pub group: String,
    /// Labelled sticky.
    pub sticky: bool,
    /// Its source.
    pub source: RealSource,
    /// Flow, level, pressure, ... as labelled.
    pub measurement: String,
    /// Controller output.
    pub op: Vec<f64>,
    /// Process variable.
    pub pv: Vec<f64>,
    /// Setpoint, when recorded.
    pub sp: Option<Vec<f64>>,
    /// Automatic mode, when recorded.
    pub auto: Option<Vec<bool>>,
    /// Time, seconds.
    pub time: Vec<f64>,
    /// Sampling time, seconds (the median step of `time`).
    pub ts: f64,
}

impl RealRecord {
    /// The record as `diagnose` reads it.
    pub fn record(&self) -> LoopRecord<'_> {
        LoopRecord {
            op: &self.op,
            pv: &self.pv,
            sp: self.sp.as_deref(),
            mv: None,
            time: Some(&self.time),
            auto: self.auto.as_deref(),
        }
    }

    /// The request the CLI builds for it (no flag beyond the columns).
    pub fn request(&self) -> DiagnoseRequest {
        DiagnoseRequest {
            ts: self.ts,
            ..DiagnoseRequest::default()
        }
    }
}

/// Seconds since 1970 of `YYYY-MM-DD HH:MM:SS`.
fn seconds(text: &str) -> Option<f64> {
    let (date, time) = text.trim().split_once(' ')?;
    let d: Vec<i64> = date
        .split('-')
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    let t: Vec<f64> = time
        .split(':')
        .map(|p| p.parse().ok())
        .collect::<Option<_>>()?;
    let [y, m, day] = d[..] else { return None };
    let [hh, mm, ss] = t[..] else { return None };
    // days from the civil date (Howard Hinnant's algorithm)
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some(days as f64 * 86_400.0 + hh * 3600.0 + mm * 60.0 + ss)
}

fn median_step(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    d.sort_by(f64::total_cmp);
    d.get(d.len() / 2).copied().unwrap_or(1.0)
}

/// The plant windows of `dir` (plant-dev), with their labels.
pub fn plant_dev(dir: &Path) -> Option<Vec<RealRecord>> {
    let (h, rows) = read_csv(&dir.join("labels.csv"))?;
    let mut out = Vec::new();
    for r in &rows {
        let get = |name: &str| h.iter().position(|c| c == name).map(|i| r[i].clone());
        let file = get("file")?;
        let (hd, data) = read_csv(&dir.join(&file))?;
        let ti = hd.iter().position(|c| c.eq_ignore_ascii_case("time"))?;
        let time: Vec<f64> = data
            .iter()
            .map(|row| seconds(&row[ti]))
            .collect::<Option<_>>()?;
        let t0 = time[0];
        let time: Vec<f64> = time.iter().map(|t| t - t0).collect();
        let name = file.trim_end_matches(".csv").to_string();
        // the tag: the name without its date and index
        let parts: Vec<&str> = name.rsplitn(3, '_').collect();
        let group = parts.last().copied().unwrap_or(&name).to_string();
        out.push(RealRecord {
            group,
            sticky: sticky_label(&get("label")?)?,
            source: RealSource::Plant,
            measurement: get("loop_kind")?,
            op: column(&hd, &data, "op"),
            pv: column(&hd, &data, "pv"),
            sp: Some(column(&hd, &data, "sp")),
            auto: Some(
                column(&hd, &data, "mode")
                    .iter()
                    .map(|m| *m == 1.0)
                    .collect(),
            ),
            ts: median_step(&time),
            time,
            name,
        });
    }
    Some(out)
}

/// The ISDB loops of `dir` with OP and PV, labelled as Damarla et al.'s test set.
pub fn isdb(dir: &Path) -> Option<Vec<RealRecord>> {
    let (h, rows) = read_csv(&dir.join("isdb_labels.csv"))?;
    let at = |name: &str| h.iter().position(|c| c == name);
    let (li, di, mi) = (at("loop")?, at("damarla20")?, at("measurement")?);
    let mut out = Vec::new();
    for r in &rows {
        let path = dir.join("op_pv").join(format!("{}.csv", r[li]));
        let Some((hd, data)) = read_csv(&path) else {
            continue;
        };
        let time = column(&hd, &data, "t");
        out.push(RealRecord {
            name: format!("ISDB_{}", r[li]),
            group: format!("ISDB_{}", r[li]),
            sticky: r[di] == "Y",
            source: RealSource::Isdb,
            measurement: r[mi].clone(),
            op: column(&hd, &data, "OP"),
            pv: column(&hd, &data, "PV"),
            sp: None,
            auto: None,
            ts: median_step(&time),
            time,
        });
    }
    Some(out)
}

/// Every real record under `shared` (`../shared` of the repository), plant windows first; `None`
/// when the data are absent.
pub fn all(shared: &Path) -> Option<Vec<RealRecord>> {
    let mut out = plant_dev(&shared.join("data/plant-dev"))?;
    out.extend(isdb(&shared.join("data/isdb"))?);
    Some(out)
}

/// A plant window's label: `stiction` is a sticky valve, `no_stiction` a healthy one; any other
/// label is none of this study's.
fn sticky_label(label: &str) -> Option<bool> {
    match label {
        "stiction" => Some(true),
        "no_stiction" => Some(false),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn civil_times_count_seconds() {
        assert_eq!(super::seconds("1970-01-02 00:00:10"), Some(86_410.0));
        assert_eq!(
            super::seconds("2024-03-01 00:00:00").unwrap()
                - super::seconds("2024-02-28 00:00:00").unwrap(),
            2.0 * 86_400.0
        );
    }
}
