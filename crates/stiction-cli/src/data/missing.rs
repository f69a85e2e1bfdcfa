//! Missing values as plant historians write them: blank cells, `NaN`, `#N/A`, and the digital
//! states a historian puts where a reading failed (`Bad Input`, `I/O Timeout`, `Comm Fail`, ...).
//! They are gaps in the record, not a reason to reject the file.

/// Cell texts read as a missing value (compared case-insensitively, after trimming). The last
/// ones are OSIsoft PI's system digital states for a failed or absent reading, and Excel's cell
/// errors.
pub const MISSING_MARKERS: &[&str] = &[
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

/// The longest run of rows `[start, end)` where every column holds a finite value (the first such
/// run when several are equally long); `None` when no row does.
pub fn longest_clean(columns: &[&[f64]]) -> Option<(usize, usize)> {
    let n = columns.iter().map(|c| c.len()).min()?;
    let clean = |k: usize| columns.iter().all(|c| c[k].is_finite());
    let mut best: Option<(usize, usize)> = None;
    let mut start = None;
    for k in 0..=n {
        match (start, k < n && clean(k)) {
            (None, true) => start = Some(k),
            (Some(s), false) => {
                if best.is_none_or(|(a, b)| k - s > b - a) {
                    best = Some((s, k));
                }
                start = None;
            }
            _ => {}
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn historian_states_are_missing() {
        for m in [
            "",
            " ",
            "NaN",
            "nan",
            "#N/A",
            "Bad Input",
            "BAD",
            "I/O Timeout",
            "Shutdown",
        ] {
            assert!(is_missing(m), "{m}");
        }
        for v in ["0", "12.5", "Badger", "-", "manual", "1e400"] {
            assert!(!is_missing(v), "{v}");
        }
    }

    #[test]
    fn the_longest_clean_run() {
        let nan = f64::NAN;
        let a = [1.0, nan, 1.0, 1.0, 1.0, 1.0, nan];
        let b = [1.0, 1.0, 1.0, nan, 1.0, 1.0, 1.0];
        assert_eq!(longest_clean(&[&a, &b]), Some((4, 6)));
        assert_eq!(longest_clean(&[&a]), Some((2, 6)));
        assert_eq!(longest_clean(&[&[nan, nan]]), None);
        assert_eq!(longest_clean(&[&[]]), None);
    }

    proptest! {
        /// The run is clean, and no clean run is longer.
        #[test]
        fn longest_clean_is_clean_and_longest(mask in proptest::collection::vec(any::<bool>(), 0..200)) {
            let v: Vec<f64> = mask.iter().map(|&ok| if ok { 1.0 } else { f64::NAN }).collect();
            match longest_clean(&[&v]) {
                None => prop_assert!(mask.iter().all(|&ok| !ok)),
                Some((a, b)) => {
                    prop_assert!(a < b && mask[a..b].iter().all(|&ok| ok));
                    let longest = mask.split(|&ok| !ok).map(|r| r.len()).max().unwrap_or(0);
                    prop_assert_eq!(b - a, longest);
                }
            }
        }
    }
}
