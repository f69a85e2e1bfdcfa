//! Missing values as plant historians write them: blank cells, `NaN`, `#N/A`, and the digital
//! states a historian puts where a reading failed (`Bad Input`, `I/O Timeout`, `Comm Fail`, ...).
//! They are gaps in the record, not a reason to reject the file.

pub use stiction_core::record::is_missing;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use stiction_core::record::longest_clean;

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
