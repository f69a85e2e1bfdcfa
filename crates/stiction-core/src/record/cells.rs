//! The cells of plant exports: missing values as historians write them and controller modes in
//! words. Blank cells, `NaN`, `#N/A` and historian states are gaps, not errors.

/// Cell texts read as a missing value (compared case-insensitively, after trimming). The last
/// ones are OSIsoft PI's system digital states for a failed or absent reading, and Excel's cell
/// errors.
const MISSING_MARKERS: &[&str] = &[
    "",
    "nan",
    "-nan",
    "#n/a",
    "null",
    "none",
    "bad",
    "bad input",
    "bad data",
    "bad quality",
    "i/o timeout",
    "shutdown",
    "comm fail",
    "no data",
    "no sample",
    "calc failed",
    "scan off",
    "scan timeout",
    "pt created",
    "configure",
    "not connected",
    "intf shut",
    "out of serv",
    "invalid data",
    "#value!",
    "#div/0!",
    "#ref!",
    "#num!",
    "#null!",
    "#name?",
];

/// Whether a cell's text stands for a missing value.
pub fn is_missing(cell: &str) -> bool {
    let c = cell.trim();
    c.len() <= 13 && MISSING_MARKERS.iter().any(|m| m.eq_ignore_ascii_case(c))
}

/// A controller mode cell in words: `Some(true)` for automatic (auto, automatic, aut, a, 1, true,
/// on, cascade, cas), `Some(false)` for manual (manual, man, m, 0, false, off), any case;
/// `None` for anything else (a missing cell is the front end's to judge).
pub fn mode_word(cell: &str) -> Option<bool> {
    match cell.trim().to_ascii_lowercase().as_str() {
        "auto" | "automatic" | "aut" | "a" | "1" | "true" | "on" | "cascade" | "cas" => Some(true),
        "manual" | "man" | "m" | "0" | "false" | "off" => Some(false),
        _ => None,
    }
}
