//! Zone abbreviations after the time (`2024-03-01 12:00:05 CET`), as some historians write
//! them: the abbreviation is taken off and its offset applied, so the end of daylight saving
//! (CEST then CET) steps forward as it should. A single abbreviation the table does not know
//! only shifts every time alike, which no step sees.

/// Offsets from UTC, in minutes, of common zone abbreviations (the US readings of the
/// ambiguous CST and EST).
const OFFSETS: &[(&str, i32)] = &[
    ("UTC", 0),
    ("GMT", 0),
    ("Z", 0),
    ("WET", 0),
    ("WEST", 60),
    ("BST", 60),
    ("CET", 60),
    ("CEST", 120),
    ("MET", 60),
    ("MEST", 120),
    ("EET", 120),
    ("EEST", 180),
    ("MSK", 180),
    ("AST", -240),
    ("ADT", -180),
    ("EST", -300),
    ("EDT", -240),
    ("CST", -360),
    ("CDT", -300),
    ("MST", -420),
    ("MDT", -360),
    ("PST", -480),
    ("PDT", -420),
    ("AKST", -540),
    ("AKDT", -480),
    ("HST", -600),
    ("JST", 540),
    ("KST", 540),
    ("SGT", 480),
    ("HKT", 480),
    ("AWST", 480),
    ("ACST", 570),
    ("AEST", 600),
    ("AEDT", 660),
    ("NZST", 720),
    ("NZDT", 780),
];

/// The cells without their zone abbreviations, and each abbreviation's offset in seconds
/// (`None` for a missing cell), when every present cell ends in one (2 to 5 capital letters
/// after a space) and they are known, or all the same; with a note. `None` otherwise.
pub(super) fn strip(
    cells: &[&str],
    missing: &dyn Fn(&str) -> bool,
) -> Option<(Vec<String>, Vec<Option<f64>>, String)> {
    let mut stripped = Vec::with_capacity(cells.len());
    let mut offsets = Vec::with_capacity(cells.len());
    let mut seen: Vec<&str> = Vec::new();
    for c in cells {
        if missing(c) {
            stripped.push(String::new());
            offsets.push(None);
            continue;
        }
        let (rest, abbrev) = c.trim().rsplit_once(' ')?;
        let ok = (2..=5).contains(&abbrev.len()) && abbrev.bytes().all(|b| b.is_ascii_uppercase());
        if !ok || abbrev == "AM" || abbrev == "PM" {
            return None;
        }
        if !seen.contains(&abbrev) {
            seen.push(abbrev);
        }
        let known = OFFSETS.iter().find(|(a, _)| *a == abbrev).map(|(_, m)| *m);
        stripped.push(rest.trim_end().to_string());
        offsets.push(Some(f64::from(known.unwrap_or(0)) * 60.0));
    }
    let unknown: Vec<&str> = seen
        .iter()
        .copied()
        .filter(|a| !OFFSETS.iter().any(|(k, _)| k == a))
        .collect();
    if seen.is_empty() || (!unknown.is_empty() && seen.len() > 1) {
        return None;
    }
    let note = if unknown.is_empty() {
        format!(
            "the times end in a zone abbreviation ({}): read with its offset from UTC",
            seen.join(", ")
        )
    } else {
        format!(
            "the times end in a zone abbreviation this reader does not know ({}): all read alike, as UTC (the steps between them are right)",
            seen.join(", ")
        )
    };
    Some((stripped, offsets, note))
}
