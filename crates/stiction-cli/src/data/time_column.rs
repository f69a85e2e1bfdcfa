//! The time column of a table: read in the forms historians write, and a column of times of
//! day alone joined with a date column beside it, or rolled over at midnight.

use super::missing::is_missing;
use super::table::{shown, Table};
use super::time::{self, TimeAxis, TimeError, TimeSpec};
use anyhow::Result;

impl Table {
    /// Parse a time column in the given form and zone: the seconds, the count of missing cells
    /// and what the reader noticed (epoch milliseconds, a daylight-saving repeat).
    ///
    /// A column of times of day alone (`23:50:05`) is read with a column named date or day
    /// beside it (`01.03.2024`), or else as times on one day that roll over at midnight; with a
    /// note.
    pub fn time_axis(&self, col: usize, spec: &TimeSpec) -> Result<TimeAxis> {
        let own: Vec<&str> = (0..self.len()).map(|i| self.cell(i, col)).collect();
        let day = own
            .iter()
            .find(|c| !is_missing(c))
            .is_some_and(|c| time_of_day(c))
            .then(|| ["date", "day"].iter().find_map(|n| self.find(n)))
            .map(|date| date.filter(|&d| d != col));
        let joined: Vec<String> = match day {
            Some(Some(d)) => (0..self.len())
                .map(|i| match (self.cell(i, d), own[i]) {
                    (a, b) if is_missing(a) || is_missing(b) => String::new(),
                    (a, b) => format!("{a} {b}"),
                })
                .collect(),
            // times of day alone: on one day (1970-01-01), rolled over below
            Some(None) => own
                .iter()
                .map(|c| match is_missing(c) {
                    true => String::new(),
                    // the 12-hour clock is read in the US form of dates
                    false if c.ends_with(['M', 'm']) => format!("01/01/1970 {c}"),
                    false => format!("1970-01-01 {c}"),
                })
                .collect(),
            None => Vec::new(),
        };
        let cells: Vec<&str> = match day {
            Some(_) => joined.iter().map(String::as_str).collect(),
            None => own.clone(),
        };
        let name = &self.headers[col];
        let mut axis = self.parse_time(&cells, col, spec)?;
        match day {
            Some(Some(d)) => axis.notes.push(format!(
                "the time is read from the columns '{}' and '{name}' together",
                self.headers[d]
            )),
            Some(None) => {
                let days = roll_over_midnight(&mut axis.seconds);
                axis.notes.push(format!(
                    "column '{name}' holds times of day without a date (and no date column beside it): read as one day{}",
                    match days {
                        0 => String::new(),
                        1 => ", past midnight once".to_string(),
                        k => format!(", past midnight {k} times"),
                    }
                ));
            }
            None => {}
        }
        Ok(axis)
    }

    fn parse_time(&self, cells: &[&str], col: usize, spec: &TimeSpec) -> Result<TimeAxis> {
        let name = &self.headers[col];
        let file = self.path.display();
        time::parse_column(cells, &|c: &str| is_missing(c), spec).map_err(|e| match e {
            TimeError::Cell { row, expected } => anyhow::anyhow!(
                "{file}: {}, column '{name}': '{}' is not {expected}",
                self.at(row),
                shown(cells[row])
            ),
            TimeError::Repeat { row, back } => {
                let before = (0..row).rev().find(|&r| !is_missing(cells[r])).unwrap_or(0);
                anyhow::anyhow!(
                    "{file}: {}, column '{name}': the local time steps back by {:.0} minutes ('{}' then '{}'), as when daylight saving ends; \
                     give the zone of the times with --tz ZONE (e.g. --tz Europe/Berlin)",
                    self.at(row),
                    back / 60.0,
                    shown(cells[before]),
                    shown(cells[row])
                )
            }
        })
    }
}

/// Whether a cell is a time of day alone: `23:50`, `23:50:05`, `23:50:05.250`, `11:50:05 PM`.
fn time_of_day(cell: &str) -> bool {
    let c = cell.trim();
    let c = c
        .strip_suffix("AM")
        .or_else(|| c.strip_suffix("PM"))
        .or_else(|| c.strip_suffix("am"))
        .or_else(|| c.strip_suffix("pm"))
        .unwrap_or(c)
        .trim_end();
    let parts: Vec<&str> = c.split(':').collect();
    let digits = |p: &str| !p.is_empty() && p.len() <= 2 && p.bytes().all(|b| b.is_ascii_digit());
    match parts.as_slice() {
        [h, m] => digits(h) && digits(m),
        [h, m, s] => {
            let (whole, frac) = s.split_once('.').unwrap_or((s, "0"));
            digits(h) && digits(m) && digits(whole) && frac.bytes().all(|b| b.is_ascii_digit())
        }
        _ => false,
    }
}

/// Times of day in order: a step back by more than 12 hours is the next day. The days passed.
fn roll_over_midnight(seconds: &mut [f64]) -> usize {
    let (mut days, mut last) = (0usize, f64::NAN);
    for s in seconds.iter_mut().filter(|s| s.is_finite()) {
        let raw = *s;
        if last.is_finite() && raw < last - 43_200.0 {
            days += 1;
        }
        last = raw;
        *s = raw + days as f64 * 86_400.0;
    }
    days
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_of_day_and_midnight() {
        for c in [
            "23:50",
            "23:50:05",
            "23:50:05.250",
            "11:50:05 PM",
            "1:05:00am",
        ] {
            assert!(time_of_day(c), "{c}");
        }
        for c in ["2024-03-01 23:50:05", "12.5", "23:5x", "1:2:3:4", ""] {
            assert!(!time_of_day(c), "{c}");
        }
        let mut s = vec![86_390.0, f64::NAN, 86_399.0, 5.0, 10.0];
        assert_eq!(roll_over_midnight(&mut s), 1);
        assert_eq!(s[3], 86_405.0);
        assert!(s[1].is_nan());
    }
}
