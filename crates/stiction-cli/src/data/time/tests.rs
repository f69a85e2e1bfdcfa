//! The time axis in the forms historians write.

use super::*;

fn parse(cells: &[&str], spec: &TimeSpec) -> Result<TimeAxis, TimeError> {
    parse_column(cells, &|c: &str| c.trim().is_empty(), spec)
}

fn auto(cells: &[&str]) -> Vec<f64> {
    parse(cells, &TimeSpec::default()).unwrap().seconds
}

#[test]
fn forms_historians_write() {
    let t0 = 1_709_294_400.0; // 2024-03-01 12:00:00 UTC
    for (a, b) in [
        ("2024-03-01 12:00:00", "2024-03-01 12:00:05"),
        ("2024-03-01T12:00:00Z", "2024-03-01T12:00:05Z"),
        ("2024-03-01T13:00:00+01:00", "2024-03-01T13:00:05+01:00"),
        ("2024-03-01T12:00:00.000", "2024-03-01T12:00:05.000"),
        ("01.03.2024 12:00:00", "01.03.2024 12:00:05"),
        ("03/01/2024 12:00:00 PM", "03/01/2024 12:00:05 PM"),
        ("2024/03/01 12:00:00", "2024/03/01 12:00:05"),
        ("01-Mar-2024 12:00:00", "01-Mar-2024 12:00:05"),
    ] {
        assert_eq!(auto(&[a, b]), vec![t0, t0 + 5.0], "{a}");
    }
    assert_eq!(auto(&["0", "0.5", "1"]), vec![0.0, 0.5, 1.0]);
    assert_eq!(
        auto(&["1709294400000", "1709294400500"]),
        vec![t0, t0 + 0.5]
    );
}

#[test]
fn day_and_month_are_told_apart_by_the_axis() {
    // 12/01 then 13/01: only day-first reads both
    assert_eq!(
        auto(&["12/01/2024 00:00:00", "13/01/2024 00:00:00"]),
        auto(&["2024-01-12 00:00:00", "2024-01-13 00:00:00"])
    );
    // 01/02 then 02/02: both forms read it; month-first steps 31 days (Jan 2 to Feb 2),
    // day-first 1 day (Feb 1 to Feb 2): the smaller step wins
    assert_eq!(
        auto(&["01/02/2024 00:00:00", "02/02/2024 00:00:00"]),
        auto(&["2024-02-01 00:00:00", "2024-02-02 00:00:00"])
    );
}

#[test]
fn explicit_forms() {
    let spec = |f: &str| TimeSpec {
        format: f.parse().unwrap(),
        tz: None,
    };
    let t = parse(&["45352.5", "45352.5000578704"], &spec("excel"))
        .unwrap()
        .seconds;
    assert_eq!(t, vec![1_709_294_400.0, 1_709_294_405.0]);
    let t = parse(&["1000", "3000"], &spec("epoch-ms")).unwrap().seconds;
    assert_eq!(t, vec![1.0, 3.0]);
    let t = parse(&["2024|03|01 12h00"], &spec("%Y|%m|%d %Hh%M"))
        .unwrap()
        .seconds;
    assert_eq!(t, vec![1_709_294_400.0]);
    assert!(matches!(
        parse(&["2024-03-01 12:00"], &spec("%d.%m.%Y %H:%M")),
        Err(TimeError::Cell { row: 0, .. })
    ));
    assert!("ymd".parse::<TimeFormat>().is_err());
}

#[test]
fn daylight_saving_with_and_without_the_zone() {
    // Europe/Berlin leaves summer time on 2024-10-27 at 03:00 CEST -> 02:00 CET
    let cells = [
        "2024-10-27 01:30:00",
        "2024-10-27 02:00:00",
        "2024-10-27 02:30:00",
        "2024-10-27 02:00:00",
        "2024-10-27 02:30:00",
        "2024-10-27 03:00:00",
    ];
    let berlin = TimeSpec {
        format: TimeFormat::Auto,
        tz: Some(zone("Europe/Berlin").unwrap()),
    };
    let axis = parse(&cells, &berlin).unwrap();
    let steps: Vec<f64> = axis.seconds.windows(2).map(|w| w[1] - w[0]).collect();
    assert_eq!(steps, vec![1800.0; 5]);
    assert!(axis.notes[0].contains("repeats"), "{:?}", axis.notes);
    assert!(matches!(
        parse(&cells, &TimeSpec::default()),
        Err(TimeError::Repeat { row: 3, .. })
    ));
    // spring: 02:00 to 03:00 does not exist on 2024-03-31; the export jumps over it
    let axis = parse(&["2024-03-31 01:30:00", "2024-03-31 03:00:00"], &berlin).unwrap();
    assert_eq!(axis.seconds[1] - axis.seconds[0], 1800.0);
    assert!(zone("+01:00").is_ok() && zone("Mars/Olympus").is_err());
}

#[test]
fn no_text_panics_and_unknown_forms_name_the_row() {
    for bad in [
        "2024–03–01 12:00:00",
        "yesterday",
        "2024-13-01",
        "é",
        "12:00",
    ] {
        assert!(
            matches!(
                parse(&[bad], &TimeSpec::default()),
                Err(TimeError::Cell { row: 0, .. })
            ),
            "{bad}"
        );
    }
    assert!(matches!(
        parse(&["2024-03-01 12:00:00", "later"], &TimeSpec::default()),
        Err(TimeError::Cell { row: 1, .. })
    ));
}

#[test]
fn excel_serial_days_are_found_without_being_named() {
    // a spreadsheet's dates as numbers: read as seconds, they gave "2000 samples at 0.000012 s"
    let a = parse(
        &["45352.5", "45352.5000578704", "45352.5001157407"],
        &TimeSpec::default(),
    )
    .unwrap();
    assert_eq!(a.seconds[0], 1_709_294_400.0);
    assert!(
        (a.seconds[2] - a.seconds[0] - 10.0).abs() < 1e-3,
        "{:?}",
        a.seconds
    );
    assert!(a
        .notes
        .iter()
        .any(|n| n.contains("read as Excel serial days")));
    // plain seconds in that range, stepping by a second or more, stay seconds
    let b = parse(&["45352", "45353", "45354"], &TimeSpec::default()).unwrap();
    assert_eq!(b.seconds, vec![45352.0, 45353.0, 45354.0]);
    assert!(b.notes.is_empty());
}

#[test]
fn zone_abbreviations_are_read_with_their_offsets() {
    // daylight saving ends: 02:59:59 CEST is followed by 02:00:00 CET, one second later
    let a = auto(&[
        "2024-10-27 02:59:58 CEST",
        "2024-10-27 02:59:59 CEST",
        "2024-10-27 02:00:00 CET",
    ]);
    assert_eq!(a[1] - a[0], 1.0);
    assert_eq!(a[2] - a[1], 1.0);
    assert_eq!(a[0], 1_729_990_798.0); // 00:59:58 UTC
                                       // one unknown abbreviation: read alike, the steps right
    let b = parse(
        &["2024-03-01 12:00:05 XYZT", "2024-03-01 12:00:15 XYZT"],
        &TimeSpec::default(),
    )
    .unwrap();
    assert_eq!(b.seconds[1] - b.seconds[0], 10.0);
    assert!(b.notes.iter().any(|n| n.contains("does not know (XYZT)")));
    // AM/PM is not a zone
    assert_eq!(
        auto(&["03/01/2024 12:00:05 PM", "03/01/2024 12:00:06 PM"]).len(),
        2
    );
}
