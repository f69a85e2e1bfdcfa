//! The time axis: seconds, epoch milliseconds, Excel serial days and text timestamps as
//! historians write them (ISO 8601 with or without a zone, `YYYY-MM-DD HH:MM:SS`,
//! `DD.MM.YYYY HH:MM:SS`, `MM/DD/YYYY hh:mm:ss AM`, `01-Mar-2024 12:00:05`, ...), all parsed by
//! `jiff`. Local times take their zone from `--tz`, so the hour that repeats when daylight saving
//! ends and the hour that is skipped when it starts come out right.

mod abbrev;
mod forms;
#[cfg(test)]
mod tests;
mod zone;

use forms::{auto_text, stamps, Form};
use jiff::tz::TimeZone;
use jiff::Timestamp;
use std::str::FromStr;
use zone::{check_repeats, local_seconds, DstCount};

/// How the time column is written (`--time-format`).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum TimeFormat {
    /// Numbers are seconds (epoch milliseconds when every value is past 1e11); text is tried
    /// against the forms in [`forms::PATTERNS`] and ISO 8601.
    #[default]
    Auto,
    /// Numbers of seconds (since 1970 or since any start).
    Seconds,
    /// Milliseconds since 1970-01-01 UTC.
    EpochMillis,
    /// Excel serial days (1 = 1900-01-01; days since 1899-12-30), local times.
    ExcelDays,
    /// A strftime pattern such as `%d.%m.%Y %H:%M:%S`.
    Pattern(String),
}

impl FromStr for TimeFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Ok(match s.trim().to_ascii_lowercase().as_str() {
            "auto" => TimeFormat::Auto,
            "seconds" | "s" | "epoch" | "epoch-s" | "unix" => TimeFormat::Seconds,
            "epoch-ms" | "ms" | "unix-ms" | "milliseconds" => TimeFormat::EpochMillis,
            "excel" | "excel-days" | "serial" => TimeFormat::ExcelDays,
            _ if s.contains('%') => TimeFormat::Pattern(s.to_string()),
            _ => {
                return Err(format!(
                "'{s}' is not a time format; give a strftime pattern such as '%d.%m.%Y %H:%M:%S', \
                     or one of auto, seconds, epoch-ms, excel"
            ))
            }
        })
    }
}

/// The form of the time column and the zone of its local times.
#[derive(Debug, Clone, Default)]
pub struct TimeSpec {
    pub format: TimeFormat,
    /// The zone of local times (`--tz`); `None`: local times are read as UTC, which keeps every
    /// difference right except across a daylight-saving change.
    pub tz: Option<TimeZone>,
}

/// A `--tz` value: an IANA zone (`Europe/Berlin`), `UTC`, or a fixed offset (`+01:00`).
pub fn zone(name: &str) -> Result<TimeZone, String> {
    jiff::fmt::temporal::DateTimeParser::new()
        .parse_time_zone(name.trim())
        .map_err(|_| {
            format!(
                "--tz {name}: not a time zone; give an IANA name such as Europe/Berlin or America/Chicago, UTC, or an offset such as +01:00"
            )
        })
}

/// What was wrong with the time column.
#[derive(Debug, Clone, PartialEq)]
pub enum TimeError {
    /// The cell at this row cannot be read in the column's form (`expected` describes it).
    Cell { row: usize, expected: String },
    /// Local times step back by about an hour at this row without `--tz`: the end of daylight
    /// saving.
    Repeat { row: usize, back: f64 },
}

/// A parsed time column.
#[derive(Debug, Clone, Default)]
pub struct TimeAxis {
    /// Seconds (since 1970 for dates); NaN where the cell is missing.
    pub seconds: Vec<f64>,
    /// Cells read as missing.
    pub missing: usize,
    /// What the reader decided that a person should know (the form, a daylight-saving repeat).
    pub notes: Vec<String>,
    /// The cells were local times (no zone in the text).
    pub local: bool,
}

pub(crate) fn secs(t: Timestamp) -> f64 {
    t.as_second() as f64 + t.subsec_nanosecond() as f64 * 1e-9
}

/// A number of seconds, with a decimal point or a decimal comma.
pub(crate) fn number(cell: &str) -> Option<f64> {
    super::parse_number(cell).filter(|v| v.is_finite())
}

/// Parse a time column: `cells[i]` is row i's text, `missing(i)` whether it is a gap.
pub fn parse_column(
    cells: &[&str],
    missing: &dyn Fn(&str) -> bool,
    spec: &TimeSpec,
) -> Result<TimeAxis, TimeError> {
    let first = cells.iter().position(|c| !missing(c));
    let mut axis = TimeAxis {
        missing: cells.iter().filter(|c| missing(c)).count(),
        ..TimeAxis::default()
    };
    let Some(first) = first else {
        axis.seconds = vec![f64::NAN; cells.len()];
        return Ok(axis);
    };
    let numeric = |scale: f64, what: &str| {
        numbers(cells, missing, what).map(|v| v.into_iter().map(|x| x * scale).collect())
    };
    axis.seconds = match &spec.format {
        TimeFormat::Seconds => numeric(1.0, "a number of seconds")?,
        TimeFormat::EpochMillis => numeric(1e-3, "a number of milliseconds since 1970")?,
        TimeFormat::ExcelDays => {
            axis.local = true;
            excel_days(cells, missing, spec.tz.as_ref(), &mut axis.notes)?
        }
        TimeFormat::Pattern(p) => {
            axis.local = true;
            let expected = format!("a time in the form --time-format '{p}'");
            stamps(
                cells,
                missing,
                Form::Pattern(p),
                spec.tz.as_ref(),
                &mut axis.notes,
            )
            .map_err(|row| TimeError::Cell { row, expected })?
        }
        TimeFormat::Auto if number(cells[first]).is_some() => {
            let v = numbers(
                cells,
                missing,
                "a number of seconds like the first time value",
            )?;
            let finite = || v.iter().copied().filter(|x| x.is_finite());
            let (lo, hi) = finite().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                (l.min(x), h.max(x))
            });
            if looks_like_excel_days(&v, lo, hi) {
                axis.local = true;
                axis.notes.push(
                    "the time column is read as Excel serial days, as a spreadsheet stores dates (its values lie between 20,000 and 80,000 and step by less than 0.01: as seconds that would be sampling faster than 100 Hz); give --time-format seconds if they are seconds"
                        .into(),
                );
                excel_days(cells, missing, spec.tz.as_ref(), &mut axis.notes)?
            } else if lo >= 1e11 && hi < 1e14 {
                // seconds past 1e11 would be the year 5138: these are epoch milliseconds
                axis.notes.push(
                    "the time column is read as milliseconds since 1970 (its values are past 1e11); \
                     give --time-format seconds if they are seconds"
                        .into(),
                );
                v.into_iter().map(|x| x * 1e-3).collect()
            } else {
                v
            }
        }
        TimeFormat::Auto => match abbrev::strip(cells, missing) {
            // zone abbreviations: each time read as UTC, then moved by its zone's offset
            Some((stripped, offsets, note)) => {
                let plain: Vec<&str> = stripped.iter().map(String::as_str).collect();
                let utc = TimeSpec {
                    format: TimeFormat::Auto,
                    tz: Some(TimeZone::UTC),
                };
                let mut inner = parse_column(&plain, missing, &utc)?;
                axis.notes.append(&mut inner.notes);
                axis.notes.push(note);
                inner
                    .seconds
                    .iter()
                    .zip(&offsets)
                    .map(|(s, o)| s - o.unwrap_or(0.0))
                    .collect()
            }
            None => {
                axis.local = true;
                auto_text(cells, missing, first, spec.tz.as_ref(), &mut axis.notes)?
            }
        },
    };
    if axis.local && spec.tz.is_none() {
        check_repeats(&axis.seconds)?;
    }
    Ok(axis)
}

/// Numbers between 20,000 and 80,000 (Excel serial days of the years 1954 to 2119) whose median
/// step is under 0.01: as seconds that would be sampling faster than 100 Hz, which no historian
/// export holds; as days it is under 15 minutes.
fn looks_like_excel_days(v: &[f64], lo: f64, hi: f64) -> bool {
    if !(lo >= 20_000.0 && hi <= 80_000.0) {
        return false;
    }
    let finite: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    let mut steps: Vec<f64> = finite
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|s| *s > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    steps.get(steps.len() / 2).is_some_and(|&s| s < 0.01)
}

fn numbers(
    cells: &[&str],
    missing: &dyn Fn(&str) -> bool,
    expected: &str,
) -> Result<Vec<f64>, TimeError> {
    cells
        .iter()
        .enumerate()
        .map(|(row, c)| match missing(c) {
            true => Ok(f64::NAN),
            false => number(c).ok_or_else(|| TimeError::Cell {
                row,
                expected: expected.into(),
            }),
        })
        .collect()
}

fn excel_days(
    cells: &[&str],
    missing: &dyn Fn(&str) -> bool,
    tz: Option<&TimeZone>,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, TimeError> {
    let days = numbers(cells, missing, "a number of Excel serial days")?;
    let epoch = jiff::civil::date(1899, 12, 30).at(0, 0, 0, 0);
    let mut out = Vec::with_capacity(days.len());
    let mut dst = DstCount::default();
    for (row, d) in days.into_iter().enumerate() {
        if d.is_nan() {
            out.push(f64::NAN);
            continue;
        }
        // to the millisecond, as Excel keeps them
        let ms = (d * 86_400_000.0).round();
        let dt = jiff::SignedDuration::from_millis(ms as i64);
        let Ok(dt) = epoch.checked_add(dt) else {
            return Err(TimeError::Cell {
                row,
                expected: "a number of Excel serial days between 1900 and 9999".into(),
            });
        };
        let prev = out.iter().rev().copied().find(|x: &f64| x.is_finite());
        let (s, kind) = local_seconds(dt, tz, prev.unwrap_or(f64::NAN));
        dst.add(kind);
        out.push(s);
    }
    dst.notes(tz, notes);
    Ok(out)
}
