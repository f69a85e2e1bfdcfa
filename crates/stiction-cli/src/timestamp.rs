//! Timestamps as historians export them: plain seconds, or text dates and times
//! (`2024-03-01 12:00:05`, `2024-03-01T12:00:05.250Z`, `2024-03-01T12:00:05+01:00`, `2024/03/01 12:00`).

/// Seconds since 1970-01-01 00:00:00 UTC of a text timestamp; `None` if it is not one.
/// Without a zone the time is taken as given (all that matters is the differences).
pub fn parse(text: &str) -> Option<f64> {
    let t = text.trim();
    let (date, rest) = if t.len() >= 10 {
        t.split_at(10)
    } else {
        return None;
    };
    let sep = date.as_bytes()[4];
    if !(sep == b'-' || sep == b'/') || date.as_bytes()[7] != sep {
        return None;
    }
    let year: i64 = date[0..4].parse().ok()?;
    let month: u32 = date[5..7].parse().ok()?;
    let day: u32 = date[8..10].parse().ok()?;
    if !(1..=12).contains(&month) || day == 0 || day > days_in_month(year, month) {
        return None;
    }
    let mut seconds = days_from_civil(year, month, day) as f64 * 86_400.0;
    let rest = rest.trim_start_matches(['T', ' ']);
    if rest.is_empty() {
        return Some(seconds);
    }
    // the zone, if any: Z or +HH:MM / -HH:MM at the end
    let (clock, zone) = split_zone(rest)?;
    let parts: Vec<&str> = clock.split(':').collect();
    if parts.len() < 2 || parts.len() > 3 {
        return None;
    }
    let hour: u32 = parts[0].parse().ok()?;
    let minute: u32 = parts[1].parse().ok()?;
    let second: f64 = match parts.get(2) {
        Some(s) => s.parse().ok().filter(|v: &f64| (0.0..61.0).contains(v))?,
        None => 0.0,
    };
    if hour > 23 || minute > 59 {
        return None;
    }
    seconds += hour as f64 * 3600.0 + minute as f64 * 60.0 + second - zone;
    Some(seconds)
}

/// The clock part and the zone offset in seconds.
fn split_zone(rest: &str) -> Option<(&str, f64)> {
    if let Some(clock) = rest.strip_suffix('Z') {
        return Some((clock, 0.0));
    }
    if rest.len() > 6 {
        let (clock, zone) = rest.split_at(rest.len() - 6);
        let b = zone.as_bytes();
        if (b[0] == b'+' || b[0] == b'-') && b[3] == b':' {
            let h: f64 = zone[1..3].parse().ok()?;
            let m: f64 = zone[4..6].parse().ok()?;
            let sign = if b[0] == b'-' { -1.0 } else { 1.0 };
            return Some((clock, sign * (h * 3600.0 + m * 60.0)));
        }
    }
    Some((rest, 0.0))
}

fn days_in_month(year: i64, month: u32) -> u32 {
    match month {
        2 if (year % 4 == 0 && year % 100 != 0) || year % 400 == 0 => 29,
        2 => 28,
        4 | 6 | 9 | 11 => 30,
        _ => 31,
    }
}

/// Days since 1970-01-01 of a civil date (Howard Hinnant's algorithm).
fn days_from_civil(year: i64, month: u32, day: u32) -> i64 {
    let y = if month <= 2 { year - 1 } else { year };
    let era = if y >= 0 { y } else { y - 399 } / 400;
    let yoe = y - era * 400;
    let m = month as i64;
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + day as i64 - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    era * 146_097 + doe - 719_468
}

#[cfg(test)]
mod tests {
    use super::parse;

    #[test]
    fn formats_historians_write() {
        assert_eq!(parse("1970-01-01 00:00:00"), Some(0.0));
        assert_eq!(parse("1970-01-02"), Some(86_400.0));
        assert_eq!(parse("2000-03-01T00:00:00Z"), Some(951_868_800.0));
        assert_eq!(parse("2024-02-29 12:30:15.5"), Some(1_709_209_815.5));
        assert_eq!(parse("2024/02/29 12:30"), Some(1_709_209_800.0));
        // a zone moves the instant
        assert_eq!(
            parse("2024-02-29T13:30:15+01:00"),
            parse("2024-02-29T12:30:15Z")
        );
        assert_eq!(
            parse("2024-02-29T11:30:15-01:00"),
            parse("2024-02-29 12:30:15")
        );
    }

    #[test]
    fn what_is_not_a_timestamp() {
        for bad in [
            "",
            "12.5",
            "2023-02-29 00:00:00",
            "2024-13-01",
            "2024-01-01 25:00:00",
            "yesterday",
            "2024-01-01 10",
        ] {
            assert_eq!(parse(bad), None, "{bad}");
        }
    }
}
