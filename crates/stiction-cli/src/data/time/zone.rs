//! Local times in a zone: the hour that repeats when daylight saving ends is read as its
//! first pass, then its second, in the order of the file; the skipped hour as if the clock had
//! already moved. Without a zone, a step back of about an hour is refused with the fix.

use super::{secs, TimeError};
use jiff::civil::DateTime;
use jiff::tz::TimeZone;

/// Seconds since 1970 of a local time read in `tz` (UTC without one), and whether it falls in
/// a repeated (`Some(true)`) or skipped (`Some(false)`) hour.
pub(super) fn local_seconds(dt: DateTime, tz: Option<&TimeZone>, prev: f64) -> (f64, Option<bool>) {
    let Some(tz) = tz else {
        let t = jiff::tz::Offset::UTC.to_timestamp(dt).ok();
        return (t.map_or(f64::NAN, secs), None);
    };
    let amb = tz.to_ambiguous_timestamp(dt);
    if !amb.is_ambiguous() {
        return (amb.compatible().map_or(f64::NAN, secs), None);
    }
    let fold = matches!(amb.offset(), jiff::tz::AmbiguousOffset::Fold { .. });
    if fold {
        // the first pass through a repeated hour is the earlier offset; once the record has
        // passed it, the same wall-clock times are the second pass
        let early = amb.earlier().map_or(f64::NAN, secs);
        let late = amb.later().map_or(f64::NAN, secs);
        let second_pass = prev.is_finite() && early <= prev && late > prev;
        return (if second_pass { late } else { early }, Some(true));
    }
    (amb.compatible().map_or(f64::NAN, secs), Some(false))
}

/// Rows that fell in a repeated or a skipped hour of the zone.
#[derive(Default)]
pub(super) struct DstCount {
    repeated: usize,
    skipped: usize,
}

impl DstCount {
    pub(super) fn add(&mut self, kind: Option<bool>) {
        match kind {
            Some(true) => self.repeated += 1,
            Some(false) => self.skipped += 1,
            None => {}
        }
    }

    pub(super) fn notes(&self, tz: Option<&TimeZone>, notes: &mut Vec<String>) {
        let name = tz.and_then(|z| z.iana_name()).unwrap_or("the zone");
        if self.repeated > 0 {
            notes.push(format!(
                "{} in the hour that repeats when daylight saving ends in {name}: each read as its first or second pass, in the order of the file",
                crate::words::count(self.repeated, "row falls", "rows fall")
            ));
        }
        if self.skipped > 0 {
            notes.push(format!(
                "{} at a time that does not exist in {name} (the hour skipped when daylight saving starts): read as if the clock had already moved",
                crate::words::count(self.skipped, "row is", "rows are")
            ));
        }
    }
}

/// Without `--tz`, local times that step back by about an hour are the end of daylight saving:
/// read as UTC they would overlap, so the reader asks for the zone.
pub(super) fn check_repeats(s: &[f64]) -> Result<(), TimeError> {
    let mut prev = f64::NAN;
    for (row, &v) in s.iter().enumerate() {
        if v.is_nan() {
            continue;
        }
        let back = prev - v;
        if (1800.0..=3601.0).contains(&back) {
            return Err(TimeError::Repeat { row, back });
        }
        prev = v;
    }
    Ok(())
}
