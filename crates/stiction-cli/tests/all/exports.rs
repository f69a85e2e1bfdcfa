//! Exports laid out otherwise: a header below a preamble or above units, a narrow export (a row
//! per tag and time), digits grouped by thousands, units after the numbers, a date and a time
//! column, the time column's common names, CRLF line ends. Each is read as a user would meet it,
//! and gives the same answer as the plain file.

use crate::common::{fails, ok, stiction};
use crate::reading::{band, s, sticky};

#[test]
fn a_header_below_a_preamble_or_above_units_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let text = std::fs::read_to_string(&csv).unwrap();
    let (header, body) = text.split_once('\n').unwrap();
    // PI DataLink style: tag names and units above the header
    let pre = dir.path().join("preamble.csv");
    let width = header.split(',').count();
    let tags = vec!["Tag"; width].join(",");
    let units = vec!["Units"; width].join(",");
    std::fs::write(&pre, format!("{tags}\n{units}\n{header}\n{body}")).unwrap();
    assert_eq!(band(&[s(&pre)]), reference);
    let out = ok(&["diagnose", s(&pre), "--no-quantify"]);
    assert!(
        out.contains("the header is line 3, below 2 lines the export put above it (Tag, "),
        "{out}"
    );
    // units below the header
    let below = dir.path().join("units.csv");
    let units = vec!["%"; width].join(",");
    std::fs::write(&below, format!("{header}\n{units}\n{body}")).unwrap();
    assert_eq!(band(&[s(&below)]), reference);
    let out = ok(&["diagnose", s(&below), "--no-quantify"]);
    assert!(
        out.contains("1 line of text below the header (%, %, %"),
        "{out}"
    );
    // no row names the columns: the error names them as before
    fails(
        &["quantify", s(&pre), "--op", "OUT"],
        &["no column 'OUT'", "the columns are Tag"],
    );
}

#[test]
fn digits_grouped_by_thousands_are_read() {
    // PV in kg/h as spreadsheets format it: "4,999.94" (or "4.999,94" with semicolons); a lone
    // "12,345" in such a column is twelve thousand
    let dir = tempfile::tempdir().unwrap();
    let (csv, rows) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let grouped = |v: f64, comma: bool| {
        let cents = (v * 10_000.0).round() as i64; // PV x 100, two decimals
        let (int, frac) = (cents / 100, cents % 100);
        let t = int.to_string();
        let mut g = String::new();
        for (k, ch) in t.chars().enumerate() {
            if k > 0 && (t.len() - k) % 3 == 0 {
                g.push(if comma { ',' } else { '.' });
            }
            g.push(ch);
        }
        format!("{g}{}{frac:02}", if comma { '.' } else { ',' })
    };
    for (name, comma, sep) in [("us.csv", true, ","), ("eu.csv", false, ";")] {
        let mut out = format!("t{sep}op{sep}pv\n");
        for r in &rows {
            let op = if comma {
                r[2].to_string()
            } else {
                r[2].to_string().replace('.', ",")
            };
            out.push_str(&format!(
                "{}{sep}{op}{sep}\"{}\"\n",
                r[0],
                grouped(r[4], comma)
            ));
        }
        let p = dir.path().join(name);
        std::fs::write(&p, out).unwrap();
        let d = band(&[s(&p)]);
        assert!(
            (d - reference).abs() < 0.01 * reference,
            "{name}: {d} vs {reference}"
        );
    }
}

#[test]
fn a_narrow_export_is_pivoted_by_the_tags_named() {
    // a row per tag and time, as historians export archive values
    let dir = tempfile::tempdir().unwrap();
    let (csv, rows) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let mut out = String::from("Tag,Timestamp,Value\n");
    for r in &rows {
        for (tag, k) in [("FIC101.OP", 2), ("FIC101.PV", 4), ("LIC7.PV", 4)] {
            out.push_str(&format!("{tag},{},{}\n", r[0], r[k]));
        }
    }
    let p = dir.path().join("narrow.csv");
    std::fs::write(&p, out).unwrap();
    let tags = [
        "--op",
        "fic101.op",
        "--pv",
        "FIC101.PV",
        "--time",
        "Timestamp",
    ];
    let mut args = vec![s(&p)];
    args.extend(tags);
    assert_eq!(band(&args), reference);
    let mut diagnose = vec!["diagnose", s(&p), "--no-quantify"];
    diagnose.extend(tags);
    let text = ok(&diagnose);
    assert!(
        text.contains(
            "the file is narrow (a row per tag and time: columns Tag, Timestamp and Value)"
        ) && text.contains("values of FIC101.OP, FIC101.PV turned into a column per tag at"),
        "{text}"
    );
    // without the tags: one sentence saying to name them
    fails(
        &["diagnose", s(&p)],
        &["no column 'op'", "the file looks narrow", "--op FIC101.OP"],
    );
}

#[test]
fn a_date_and_a_time_column_are_read_together() {
    // spreadsheets often split the timestamp in two; the times cross midnight
    let dir = tempfile::tempdir().unwrap();
    let (csv, rows) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let stamp = |k: usize| {
        let s = 23 * 3600 + 50 * 60 + k; // from 23:50:00 on 1 March 2024
        let (day, s) = (1 + s / 86_400, s % 86_400);
        (
            format!("{day:02}.03.2024"),
            format!("{:02}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60),
        )
    };
    let mut two = String::from("Date,Time,op,pv\n");
    let mut one = String::from("Time,op,pv\n");
    for (k, r) in rows.iter().enumerate() {
        let (d, t) = stamp(k);
        two.push_str(&format!("{d},{t},{},{}\n", r[2], r[4]));
        one.push_str(&format!("{t},{},{}\n", r[2], r[4]));
    }
    let p = dir.path().join("two.csv");
    std::fs::write(&p, two).unwrap();
    assert_eq!(band(&[s(&p)]), reference);
    let out = ok(&["diagnose", s(&p), "--no-quantify"]);
    assert!(
        out.contains("the time is read from the columns 'Date' and 'Time' together"),
        "{out}"
    );
    assert!(out.contains("samples at 1 s"), "{out}");
    // times of day alone roll over at midnight
    let p = dir.path().join("one.csv");
    std::fs::write(&p, one).unwrap();
    assert_eq!(band(&[s(&p)]), reference);
    let out = ok(&["diagnose", s(&p), "--no-quantify"]);
    assert!(out.contains("read as one day, past midnight once"), "{out}");
}

#[test]
fn time_columns_by_their_common_names_and_a_note_without_one() {
    let dir = tempfile::tempdir().unwrap();
    let (_, rows) = sticky(dir.path());
    let mut dated = String::from("DateTime;op;pv\n");
    let mut bare = String::from("op,pv\n");
    for (k, r) in rows.iter().enumerate() {
        let s = 10 * k; // every 10 s from 01.03.2024 00:00:00
        dated.push_str(&format!(
            "01.03.2024 {:02}:{:02}:{:02};{};{}\n",
            s / 3600,
            s / 60 % 60,
            s % 60,
            r[2],
            r[4]
        ));
        bare.push_str(&format!("{},{}\n", r[2], r[4]));
    }
    let p = dir.path().join("dated.csv");
    std::fs::write(&p, dated).unwrap();
    let out = ok(&["diagnose", s(&p), "--no-quantify"]);
    assert!(out.contains("samples at 10 s"), "{out}");
    assert!(!out.contains("no time column"), "{out}");
    let p = dir.path().join("bare.csv");
    std::fs::write(&p, bare).unwrap();
    let out = ok(&["diagnose", s(&p), "--no-quantify"]);
    assert!(
        out.contains(
            "no time column and no sampling time given: the samples are taken as 1 s apart"
        ),
        "{out}"
    );
}

#[test]
fn units_after_every_number_are_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, rows) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let mut out = String::from("t,op,pv\n");
    for r in &rows {
        out.push_str(&format!("{},{} %,{} m3/h\n", r[0], r[2], r[4]));
    }
    let p = dir.path().join("units.csv");
    std::fs::write(&p, out).unwrap();
    assert_eq!(band(&[s(&p)]), reference);
    let text = ok(&["diagnose", s(&p), "--no-quantify"]);
    assert!(
        text.contains("'%' after every number of column 'op'; 'm3/h' after every number of column 'pv': dropped"),
        "{text}"
    );
}

#[test]
fn crlf_files_name_the_right_line() {
    // Windows programs end lines with CRLF; the csv reader's own count ran one line short there
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = sticky(dir.path());
    let text = std::fs::read_to_string(&csv).unwrap();
    for (name, end) in [("lf.csv", "\n"), ("crlf.csv", "\r\n")] {
        let body: Vec<String> = text
            .lines()
            .enumerate()
            .map(|(i, l)| {
                if i == 41 {
                    l.replacen(',', ",n/a?,", 1)
                } else {
                    l.to_string()
                }
            })
            .collect();
        let p = dir.path().join(name);
        std::fs::write(&p, body.join(end) + end).unwrap();
        let out = stiction(&["quantify", s(&p)]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(err.contains("line 42"), "{name}: {err}");
    }
}
