//! Reading what plants export: workbooks, Parquet, gzip, standard input, text timestamps in
//! many forms with zones and daylight saving, missing values, and files that are not tables.
//! The same loop in every form must give the same answer.

use crate::common;
use common::{closed_stenman, fails, json, ok, stiction};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// A closed loop with a sticky valve (d = 2): the rows t,sp,op,mv,pv of `stiction simulate`.
pub(crate) fn sticky(dir: &Path) -> (PathBuf, Vec<Vec<f64>>) {
    let p = dir.join("loop.csv");
    closed_stenman(&p, "2", &[]);
    let text = std::fs::read_to_string(&p).unwrap();
    let rows = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().unwrap()).collect())
        .collect();
    (p, rows)
}

/// A flag clap refuses: exit 2, the reason on standard error.
fn usage_error(args: &[&str], needles: &[&str]) {
    let out = stiction(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' missing from: {err}");
    }
}

pub(crate) fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The band quantify finds, from its JSON.
pub(crate) fn band(args: &[&str]) -> f64 {
    let mut a = vec!["quantify"];
    a.extend_from_slice(args);
    a.push("--json");
    let v = json(&ok(&a));
    assert_eq!(v["status"], "ok", "{v:#}");
    v["params"]["d"].as_f64().unwrap()
}

#[test]
fn a_workbook_reads_like_its_csv() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, rows) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    // an xlsx with a notes sheet first and the data on "Data", times as Excel dates
    let mut book = rust_xlsxwriter::Workbook::new();
    let notes = book.add_worksheet().set_name("Notes").unwrap();
    notes.write(0, 0, "exported from the historian").unwrap();
    let data = book.add_worksheet().set_name("Data").unwrap();
    let date = rust_xlsxwriter::Format::new().set_num_format("yyyy-mm-dd hh:mm:ss");
    for (c, h) in ["Time", "OP", "PV"].iter().enumerate() {
        data.write(0, c as u16, *h).unwrap();
    }
    for (i, r) in rows.iter().enumerate() {
        let row = i as u32 + 1;
        let t = rust_xlsxwriter::ExcelDateTime::from_ymd(2024, 3, 1)
            .unwrap()
            .and_hms(12, 0, 0)
            .unwrap();
        // Excel keeps dates as serial days: 1 s is 1/86400 of a day
        let serial = t.to_excel() + r[0] / 86_400.0;
        data.write_number_with_format(row, 0, serial, &date)
            .unwrap();
        data.write_number(row, 1, r[2]).unwrap();
        data.write_number(row, 2, r[4]).unwrap();
    }
    let xlsx = dir.path().join("loop.xlsx");
    book.save(&xlsx).unwrap();
    let args = [s(&xlsx), "--sheet", "data", "--op", "OP", "--pv", "PV"];
    assert_eq!(band(&args), reference);
    let v = json(&ok(&[
        "quantify",
        s(&xlsx),
        "--sheet",
        "Data",
        "--op",
        "OP",
        "--pv",
        "PV",
        "--json",
    ]));
    assert_eq!(v["ts"], 1.0, "the Excel dates give the sampling time");
    // the first sheet has no such columns; a sheet that does not exist names the sheets
    fails(
        &["quantify", s(&xlsx), "--op", "OP", "--pv", "PV"],
        &[
            "loop.xlsx",
            "sheet 'Notes' has no data rows",
            "'Notes', 'Data'",
            "--sheet",
        ],
    );
    fails(
        &["quantify", s(&xlsx), "--sheet", "Trends"],
        &[
            "loop.xlsx",
            "no sheet 'Trends'",
            "'Notes', 'Data'",
            "--sheet NAME",
        ],
    );
    // a workbook with a .csv name is still read as a workbook
    let disguised = dir.path().join("really_a_workbook.csv");
    std::fs::copy(&xlsx, &disguised).unwrap();
    assert_eq!(
        band(&[s(&disguised), "--sheet", "Data", "--op", "OP", "--pv", "PV"]),
        reference
    );
    // --sheet on a CSV is a mistake worth saying
    fails(
        &["quantify", s(&csv), "--sheet", "Data"],
        &["--sheet applies to workbooks"],
    );
}

#[test]
fn gzip_and_standard_input_read_like_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let bytes = std::fs::read(&csv).unwrap();
    let gz = dir.path().join("loop.csv.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(&bytes).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    assert_eq!(band(&[s(&gz)]), reference);
    // standard input, `-`
    let mut child = Command::new(env!("CARGO_BIN_EXE_stiction"))
        .args(["quantify", "-", "--json"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(&bytes).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json(&String::from_utf8_lossy(&out.stdout));
    assert_eq!(v["params"]["d"].as_f64().unwrap(), reference);
    // a truncated gzip says so
    let cut = std::fs::read(&gz).unwrap();
    let bad = dir.path().join("cut.csv.gz");
    std::fs::write(&bad, &cut[..cut.len() / 2]).unwrap();
    fails(
        &["quantify", s(&bad)],
        &["cut.csv.gz", "gzip", "cannot be decompressed"],
    );
}

#[cfg(feature = "parquet")]
fn write_parquet(path: &Path, schema: &str, t: &[i64], op: &[f64], pv: &[Option<f64>]) {
    use parquet::data_type::{DoubleType, Int64Type};
    use parquet::file::properties::WriterProperties;
    use parquet::file::writer::SerializedFileWriter;
    use std::sync::Arc;
    let schema = Arc::new(parquet::schema::parser::parse_message_type(schema).unwrap());
    let props = Arc::new(
        WriterProperties::builder()
            .set_compression(parquet::basic::Compression::SNAPPY)
            .build(),
    );
    let file = std::fs::File::create(path).unwrap();
    let mut w = SerializedFileWriter::new(file, schema, props).unwrap();
    let mut rg = w.next_row_group().unwrap();
    let mut i = 0;
    while let Some(mut col) = rg.next_column().unwrap() {
        match i {
            0 => {
                col.typed::<Int64Type>().write_batch(t, None, None).unwrap();
            }
            1 => {
                col.typed::<DoubleType>()
                    .write_batch(op, None, None)
                    .unwrap();
            }
            _ => {
                let values: Vec<f64> = pv.iter().flatten().copied().collect();
                let def: Vec<i16> = pv.iter().map(|v| v.is_some() as i16).collect();
                col.typed::<DoubleType>()
                    .write_batch(&values, Some(&def), None)
                    .unwrap();
            }
        }
        col.close().unwrap();
        i += 1;
    }
    rg.close().unwrap();
    w.close().unwrap();
}

#[cfg(feature = "parquet")]
#[test]
fn parquet_reads_like_its_csv() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, rows) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let op: Vec<f64> = rows.iter().map(|r| r[2]).collect();
    let mut pv: Vec<Option<f64>> = rows.iter().map(|r| Some(r[4])).collect();
    // pandas writes local nanosecond timestamps; Spark UTC milliseconds
    let t0 = 1_709_294_400_i64; // 2024-03-01 12:00:00 UTC
    let ns: Vec<i64> = rows
        .iter()
        .map(|r| (t0 + r[0] as i64) * 1_000_000_000)
        .collect();
    let ms: Vec<i64> = rows.iter().map(|r| (t0 + r[0] as i64) * 1_000).collect();
    let pandas = dir.path().join("pandas.parquet");
    write_parquet(
        &pandas,
        "message m { required int64 timestamp (TIMESTAMP(NANOS,false)); required double op; optional double pv; }",
        &ns,
        &op,
        &pv,
    );
    let v = json(&ok(&["quantify", s(&pandas), "--json"]));
    assert_eq!(v["params"]["d"].as_f64().unwrap(), reference);
    assert_eq!(v["ts"], 1.0);
    // a null is a gap: the longest stretch without one is used (a gap of 4, past a bridge)
    for v in &mut pv[1000..1004] {
        *v = None;
    }
    let spark = dir.path().join("spark.parquet");
    write_parquet(
        &spark,
        "message m { required int64 time (TIMESTAMP(MILLIS,true)); required double op; optional double pv; }",
        &ms,
        &op,
        &pv,
    );
    let out = stiction(&["quantify", s(&spark)]);
    let err = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        err.contains("4 cells treated as missing (pv 4") && err.contains("using row 1 to 1000"),
        "{err}"
    );
}

#[test]
fn files_that_are_not_tables_say_what_they_are() {
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[u8], &[&str]); 6] = [
        (
            "report.csv",
            b"%PDF-1.7\n%\xe2\xe3\xcf\xd3\n1 0 obj",
            &["this is a PDF document", "export"],
        ),
        (
            "export.xls",
            b"<html><body><table><tr><td>op</td></tr></table></body></html>",
            &["this is an HTML page", "save it as xlsx or CSV"],
        ),
        (
            "data.zip",
            b"PK\x03\x04\x14\x00\x00\x00\x08\x00notes.txt",
            &["zip archive, not a workbook", "unpack"],
        ),
        (
            "blob.csv",
            b"t,op\x00\x01\x02\x03,pv\n1,2,3\n",
            &["binary file, not text"],
        ),
        ("loop.csv.bz2", b"BZh91AY&SY", &["bzip2", "bunzip2"]),
        ("trend.png", b"\x89PNG\r\n\x1a\n\x00\x00", &["PNG image"]),
    ];
    for (name, bytes, needles) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let mut all = vec![name];
        all.extend_from_slice(needles);
        fails(&["diagnose", s(&p)], &all);
        fails(&["quantify", s(&p)], &all);
    }
}

#[test]
fn utf16_text_and_excel_sep_lines_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = sticky(dir.path());
    let reference = band(&[s(&csv)]);
    let text = std::fs::read_to_string(&csv).unwrap();
    // Excel's "Unicode text": UTF-16 little-endian with a byte-order mark, tab separated
    let tabbed = text.replace(',', "\t");
    let mut bytes = vec![0xFF, 0xFE];
    bytes.extend(tabbed.encode_utf16().flat_map(|u| u.to_le_bytes()));
    let u16 = dir.path().join("unicode.txt");
    std::fs::write(&u16, bytes).unwrap();
    assert_eq!(band(&[s(&u16)]), reference);
    let sep = dir.path().join("sep.csv");
    std::fs::write(&sep, format!("sep=;\n{}", text.replace(',', ";"))).unwrap();
    assert_eq!(band(&[s(&sep)]), reference);
}

/// Writes sample k's timestamp.
type Stamper = Box<dyn Fn(usize) -> String>;

/// The loop's rows with text timestamps written by `stamp(k)` for sample k.
fn with_times(
    dir: &Path,
    name: &str,
    rows: &[Vec<f64>],
    stamp: &dyn Fn(usize) -> String,
) -> PathBuf {
    let mut out = String::from("time,op,pv\n");
    for (k, r) in rows.iter().enumerate() {
        out.push_str(&format!("{},{},{}\n", stamp(k), r[2], r[4]));
    }
    let p = dir.join(name);
    std::fs::write(&p, out).unwrap();
    p
}

#[test]
fn timestamps_in_the_forms_historians_write() {
    let dir = tempfile::tempdir().unwrap();
    let (_, rows) = sticky(dir.path());
    let rows = &rows[..1200];
    let clock = |k: usize| (10 + k / 3600, (k / 60) % 60, k % 60);
    let forms: Vec<(&str, Stamper)> = vec![
        (
            "german.csv",
            Box::new(move |k| {
                let (h, m, s) = clock(2 * k);
                format!("01.03.2024 {h:02}:{m:02}:{s:02}")
            }),
        ),
        (
            "us.csv",
            Box::new(move |k| {
                let (h, m, s) = clock(2 * k);
                format!(
                    "03/01/2024 {:02}:{m:02}:{s:02} {}",
                    if h > 12 { h - 12 } else { h },
                    if h >= 12 { "PM" } else { "AM" }
                )
            }),
        ),
        (
            "iso_zone.csv",
            Box::new(move |k| {
                let (h, m, s) = clock(2 * k);
                format!("2024-03-01T{h:02}:{m:02}:{s:02}.000+01:00")
            }),
        ),
        (
            "epoch_ms.csv",
            Box::new(move |k| format!("{}", 1_709_294_400_000_u64 + 2000 * k as u64)),
        ),
    ];
    for (name, stamp) in &forms {
        let p = with_times(dir.path(), name, rows, stamp.as_ref());
        let v = json(&ok(&["quantify", s(&p), "--json"]));
        assert_eq!(v["ts"], 2.0, "{name}");
    }
    // Excel serial days and a strftime pattern, named with --time-format
    let excel = with_times(dir.path(), "serial.csv", rows, &|k| {
        format!("{}", 45352.5 + 2.0 * k as f64 / 86_400.0)
    });
    let v = json(&ok(&[
        "quantify",
        s(&excel),
        "--time-format",
        "excel",
        "--json",
    ]));
    assert_eq!(v["ts"], 2.0);
    let odd = with_times(dir.path(), "odd.csv", rows, &|k| {
        let (h, m, s) = clock(2 * k);
        format!("2024|03|01 {h:02}h{m:02}m{s:02}")
    });
    fails(
        &["quantify", s(&odd)],
        &[
            "odd.csv",
            "line 2",
            "'2024|03|01 10h00m00'",
            "--time-format",
        ],
    );
    let v = json(&ok(&[
        "quantify",
        s(&odd),
        "--time-format",
        "%Y|%m|%d %Hh%Mm%S",
        "--json",
    ]));
    assert_eq!(v["ts"], 2.0);
    usage_error(
        &["quantify", s(&odd), "--time-format", "ymd"],
        &["--time-format", "strftime"],
    );
    usage_error(
        &["quantify", s(&odd), "--tz", "Mars/Olympus"],
        &["--tz", "IANA"],
    );
}

#[test]
fn the_en_dash_date_of_the_issue_is_one_sentence() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("d.csv");
    std::fs::write(
        &p,
        "time,op,pv\n2024–03–01 12:00:00,1,2\n2024–03–01 12:00:01,1,2\n",
    )
    .unwrap();
    for cmd in ["diagnose", "quantify", "report"] {
        let mut args = vec![cmd, s(&p)];
        if cmd == "report" {
            args.extend_from_slice(&["-o", "r.html"]);
        }
        fails(
            &args,
            &["d.csv", "line 2", "column 'time'", "'2024–03–01 12:00:00'"],
        );
    }
}

#[test]
fn daylight_saving_end_with_and_without_the_zone() {
    let dir = tempfile::tempdir().unwrap();
    let (_, rows) = sticky(dir.path());
    // Berlin local times every 10 s across 2024-10-27 03:00 CEST -> 02:00 CET: 02:00 to 02:59:50
    // appears twice
    let start = 1_729_985_400_i64; // 2024-10-27 01:30:00 CEST = 23:30:00 UTC
    let berlin = |k: usize| {
        let utc = start + 10 * k as i64;
        let offset = if utc < 1_729_990_800 { 7200 } else { 3600 }; // 01:00 UTC: the change
        let local = utc + offset;
        let (d, r) = (local.div_euclid(86_400), local.rem_euclid(86_400));
        let day = 27 + (d - 20_023);
        format!(
            "2024-10-{day:02} {:02}:{:02}:{:02}",
            r / 3600,
            (r / 60) % 60,
            r % 60
        )
    };
    let p = with_times(dir.path(), "dst.csv", &rows[..1500], &berlin);
    fails(
        &["diagnose", s(&p), "--no-quantify"],
        &[
            "dst.csv",
            "column 'time'",
            "steps back by 60 minutes",
            "--tz",
        ],
    );
    let out = ok(&["diagnose", s(&p), "--tz", "Europe/Berlin", "--no-quantify"]);
    assert!(out.contains("1500 samples at 10 s"), "{out}");
    assert!(
        out.contains("repeats when daylight saving ends in Europe/Berlin"),
        "{out}"
    );
    let v = json(&ok(&[
        "diagnose",
        s(&p),
        "--tz",
        "Europe/Berlin",
        "--no-quantify",
        "--json",
    ]));
    // with the zone the repeated hour is no break: no failed time gate, one stretch
    let broken = v["quality"]
        .as_array()
        .unwrap()
        .iter()
        .find(|g| g["gate"] == "time_gaps" && g["passed"] == false);
    assert!(broken.is_none(), "{broken:#?}");
    assert_eq!(
        v["stretches"].as_array().unwrap().len(),
        1,
        "{:#}",
        v["stretches"]
    );
}

#[test]
fn rows_out_of_time_order_are_sorted() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, _) = sticky(dir.path());
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines.swap(100, 101);
    let p = dir.path().join("swapped.csv");
    std::fs::write(&p, lines.join("\n")).unwrap();
    let out = ok(&["diagnose", s(&p), "--sp", "sp", "--no-quantify"]);
    assert!(
        out.contains("not in time order (1 step goes back): sorted by time"),
        "{out}"
    );
    assert_eq!(
        ok(&["diagnose", s(&p), "--sp", "sp", "--no-quantify", "--json"])
            .replace(char::is_numeric, ""),
        ok(&["diagnose", s(&csv), "--sp", "sp", "--no-quantify", "--json"])
            .replace(char::is_numeric, ""),
    );
}

/// The loop with a few blank, `Bad` and `#N/A` cells: `na_lines` lines of `#N/A` from line 901.
fn with_gaps(dir: &Path, na_lines: usize) -> PathBuf {
    let (csv, _) = sticky(dir);
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut c: Vec<String> = l.split(',').map(String::from).collect();
            match i {
                300 => c[2] = String::new(),
                301 => c[4] = "Bad".into(),
                i if (900..900 + na_lines).contains(&i) => c[4] = "#N/A".into(),
                _ => {}
            }
            c.join(",")
        })
        .collect();
    let p = dir.join("gaps.csv");
    std::fs::write(&p, lines.join("\n") + "\n").unwrap();
    p
}

#[test]
fn quantify_bridges_short_gaps_and_uses_the_longest_stretch_past_long_ones() {
    let dir = tempfile::tempdir().unwrap();
    // gaps of 2 and 1 samples: bridged, the whole record is fitted
    let p = with_gaps(dir.path(), 1);
    let out = ok(&["quantify", s(&p)]);
    assert!(
        out.contains("2 short gaps (3 samples with a missing value) bridged by straight lines"),
        "{out}"
    );
    assert!(out.contains("1500 samples at 1 s"), "{out}");
    // a gap of 4 samples splits the record: the longest stretch beside it is fitted
    let p = with_gaps(dir.path(), 4);
    let out = ok(&["quantify", s(&p)]);
    assert!(
        out.contains("1 short gap (2 samples with a missing value) bridged")
            && out.contains("4 cells treated as missing (pv 4")
            && out.contains(
                "using line 2 to 900, the longest stretch without gaps (899 samples of 1500)"
            ),
        "{out}"
    );
    assert!(out.contains("899 samples at 1 s"), "{out}");
}

#[test]
fn diagnose_passes_gaps_to_the_core() {
    let dir = tempfile::tempdir().unwrap();
    let p = with_gaps(dir.path(), 1);
    let out = ok(&["diagnose", s(&p), "--sp", "sp"]);
    assert!(
        out.contains("3 cells treated as missing (op 1, pv 2"),
        "{out}"
    );
    let v = json(&ok(&["diagnose", s(&p), "--sp", "sp", "--json"]));
    assert_eq!(v["samples"], 1500);
    assert_eq!(v["verdict"], "stiction", "{v:#}");
}
