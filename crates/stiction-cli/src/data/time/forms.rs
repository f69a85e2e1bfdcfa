//! Text timestamps: ISO 8601 (with or without a zone) or strftime patterns, the column's form
//! chosen once from its cells.

use super::zone::{local_seconds, DstCount};
use super::{secs, TimeError};
use jiff::civil::DateTime;
use jiff::fmt::strtime;
use jiff::tz::TimeZone;
use jiff::Timestamp;

/// Text forms tried when `--time-format` is not given (after ISO 8601), in this order. When
/// more than one reads the whole column (day and month both up to 12), the one whose time runs
/// forwards in the smallest steps wins.
pub(super) const PATTERNS: &[&str] = &[
    "%Y/%m/%d %H:%M:%S%.f",
    "%Y/%m/%d %H:%M",
    "%d.%m.%Y %H:%M:%S%.f",
    "%d.%m.%Y %H:%M",
    "%d.%m.%Y",
    "%m/%d/%Y %I:%M:%S%.f %p",
    "%m/%d/%Y %I:%M %p",
    "%m/%d/%Y %H:%M:%S%.f",
    "%m/%d/%Y %H:%M",
    "%d/%m/%Y %H:%M:%S%.f",
    "%d/%m/%Y %H:%M",
    "%d-%b-%Y %H:%M:%S%.f",
    "%d-%b-%y %H:%M:%S%.f",
    "%d-%b-%Y %H:%M",
    "%d %b %Y %H:%M:%S%.f",
    "%Y%m%d %H%M%S",
];

/// A text form of a column: ISO 8601 (with or without a zone) or a strftime pattern.
#[derive(Debug, Clone, Copy)]
pub(super) enum Form<'a> {
    Iso,
    Pattern(&'a str),
}

/// A timestamp read from text: an instant, or a local (civil) time.
pub(super) enum Stamp {
    Instant(Timestamp),
    Local(DateTime),
}

pub(super) fn read_form(form: Form, cell: &str) -> Option<Stamp> {
    match form {
        Form::Iso => {
            if let Ok(t) = cell.parse::<Timestamp>() {
                return Some(Stamp::Instant(t));
            }
            cell.parse::<DateTime>().ok().map(Stamp::Local)
        }
        Form::Pattern(p) => {
            let tm = strtime::parse(p, cell).ok()?;
            if tm.offset().is_some() {
                return tm.to_timestamp().ok().map(Stamp::Instant);
            }
            tm.to_datetime().ok().map(Stamp::Local)
        }
    }
}

/// Parse every cell in one text form; the first row that does not fit on failure.
pub(super) fn stamps(
    cells: &[&str],
    missing: &dyn Fn(&str) -> bool,
    form: Form,
    tz: Option<&TimeZone>,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, usize> {
    let mut out = Vec::with_capacity(cells.len());
    let mut prev = f64::NAN;
    let mut dst = DstCount::default();
    for (row, c) in cells.iter().enumerate() {
        if missing(c) {
            out.push(f64::NAN);
            continue;
        }
        let s = match read_form(form, c.trim()).ok_or(row)? {
            Stamp::Instant(t) => secs(t),
            Stamp::Local(dt) => {
                let (s, kind) = local_seconds(dt, tz, prev);
                dst.add(kind);
                s
            }
        };
        if !s.is_finite() {
            return Err(row);
        }
        prev = s;
        out.push(s);
    }
    dst.notes(tz, notes);
    Ok(out)
}

/// The text forms that read the whole column; ISO 8601 first, then the first pattern (or the
/// best of several that all fit).
pub(super) fn auto_text(
    cells: &[&str],
    missing: &dyn Fn(&str) -> bool,
    first: usize,
    tz: Option<&TimeZone>,
    notes: &mut Vec<String>,
) -> Result<Vec<f64>, TimeError> {
    let cell = cells[first].trim();
    let unknown = |row: usize| {
        TimeError::Cell {
        row,
        expected: "a number of seconds or a date and time such as 2024-03-01 12:00:05, \
                   01.03.2024 12:00:05 or 03/01/2024 12:00:05 PM (else give its form with --time-format, \
                   e.g. --time-format '%d.%m.%Y %H:%M:%S')"
            .into(),
    }
    };
    if read_form(Form::Iso, cell).is_some() {
        return stamps(cells, missing, Form::Iso, tz, notes).map_err(|row| TimeError::Cell {
            row,
            expected: format!("a date and time in the same form as the first one ('{cell}')"),
        });
    }
    let mut fits: Vec<(&str, Vec<f64>, Vec<String>)> = Vec::new();
    let mut first_failure = None;
    for p in PATTERNS {
        if read_form(Form::Pattern(p), cell).is_none() {
            continue;
        }
        let mut n = Vec::new();
        match stamps(cells, missing, Form::Pattern(p), tz, &mut n) {
            Ok(v) => fits.push((p, v, n)),
            Err(row) => {
                first_failure.get_or_insert(row);
            }
        }
    }
    let Some(best) = fits.into_iter().min_by(|a, b| {
        score(&a.1)
            .partial_cmp(&score(&b.1))
            .unwrap_or(std::cmp::Ordering::Equal)
    }) else {
        return Err(match first_failure {
            Some(row) => TimeError::Cell {
                row,
                expected: format!(
                    "a date and time in the same form as the first one ('{cell}'), or give its form with --time-format"
                ),
            },
            None => unknown(first),
        });
    };
    notes.extend(best.2);
    Ok(best.1)
}

/// Steps that go back, then the largest step forward: fewer and smaller is likelier to be the
/// right reading of day and month.
fn score(s: &[f64]) -> (usize, f64) {
    let mut back = 0;
    let mut largest: f64 = 0.0;
    let mut prev = f64::NAN;
    for &v in s.iter().filter(|v| v.is_finite()) {
        if prev.is_finite() {
            if v < prev {
                back += 1;
            }
            largest = largest.max(v - prev);
        }
        prev = v;
    }
    (back, largest)
}
