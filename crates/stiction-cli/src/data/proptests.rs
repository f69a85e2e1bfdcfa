//! The reader never panics: on random bytes, and on random rows built from the pieces real
//! exports are made of. Each column is then read as numbers, modes and times. 2,000 cases per
//! property by default; `STICTION_READER_CASES=200000 cargo test -p stiction-cli --release
//! reader_never_panics` for a long run.

use super::{Table, TimeSpec};
use proptest::prelude::*;
use std::path::Path;

fn cases() -> u32 {
    std::env::var("STICTION_READER_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(2_000)
}

/// Read every column every way; errors are fine, panics are not.
fn read_everything(bytes: &[u8]) {
    let Ok(t) = Table::parse(Path::new("x.csv"), bytes) else {
        return;
    };
    let zone = TimeSpec {
        tz: super::time::zone("Europe/Berlin").ok(),
        ..TimeSpec::default()
    };
    for c in 0..t.headers.len() {
        let _ = t.numbers(c);
        let _ = t.modes(c);
        let _ = t.times(c);
        let _ = t.time_axis(c, &zone);
        let _ = t.missing(c);
    }
    let _ = super::time_column(&t, None);
}

/// Pieces of cells: numbers, dates in many forms (also broken ones), historian states, quotes,
/// non-ASCII dashes and delimiters.
fn cell() -> impl Strategy<Value = String> {
    prop_oneof![
        any::<f64>().prop_map(|v| v.to_string()),
        (0i64..4_000_000_000_000).prop_map(|v| v.to_string()),
        "[0-9]{1,4}[-/.–][0-9]{1,2}[-/.–][0-9]{1,4}[ T][0-9]{1,2}:[0-9]{1,2}(:[0-9]{1,2}(\\.[0-9]{1,9})?)?( ?[AP]M)?(Z|[+-][0-9]{2}:?[0-9]{2})?",
        Just(String::new()),
        Just("Bad Input".to_string()),
        Just("#N/A".to_string()),
        Just("auto".to_string()),
        "[\"';,\t a-zA-Zé–0-9.:/-]{0,12}",
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), ..ProptestConfig::default() })]

    #[test]
    fn reader_never_panics_on_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        read_everything(&bytes);
    }

    /// Random bytes behind the magic numbers of every format, so each reader meets junk.
    #[test]
    fn reader_never_panics_on_damaged_files(
        magic in prop_oneof![
            Just(&b"PK\x03\x04"[..]),
            Just(&b"PAR1"[..]),
            Just(&[0x1f, 0x8b][..]),
            Just(&[0xD0, 0xCF, 0x11, 0xE0, 0xA1, 0xB1, 0x1A, 0xE1][..]),
            Just(&[0xFF, 0xFE][..]),
        ],
        rest in proptest::collection::vec(any::<u8>(), 0..300),
    ) {
        let mut bytes = magic.to_vec();
        bytes.extend(rest);
        read_everything(&bytes);
    }

    #[test]
    fn reader_never_panics_on_rows(
        header in proptest::collection::vec("[a-zA-Z_.]{0,6}", 1..5),
        rows in proptest::collection::vec(proptest::collection::vec(cell(), 0..6), 0..12),
        delimiter in prop_oneof![Just(","), Just(";"), Just("\t")],
        prefix in prop_oneof![Just(""), Just("\u{feff}"), Just("sep=;\n")],
    ) {
        let mut text = String::from(prefix);
        text.push_str(&header.join(delimiter));
        for r in &rows {
            text.push('\n');
            text.push_str(&r.join(delimiter));
        }
        read_everything(text.as_bytes());
    }
}

#[test]
fn the_en_dash_date_of_the_issue_is_an_error_not_a_panic() {
    let t = Table::parse(
        Path::new("d.csv"),
        "time,op,pv\n2024–03–01 12:00:00,1,2\n2024–03–01 12:00:01,1,2\n".as_bytes(),
    )
    .unwrap();
    let e = t.times(0).unwrap_err().to_string();
    assert!(e.contains("line 2, column 'time'"), "{e}");
}
