//! `stiction batch` as a user runs it: the binary is spawned on simulated loops, its files read.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::SystemTime;

use crate::common;
use common::{closed_stenman, fails, stiction};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs a batch that must finish with exit status `code` (3: some loops failed); its stdout.
fn batch(args: &[&str], code: i32) -> String {
    let out = stiction(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(code), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    String::from_utf8(out.stdout).unwrap()
}

/// A closed loop of 1500 samples with Stenman stiction `d` (0: a healthy valve).
fn simulate(path: &Path, d: &str, seed: &str) {
    closed_stenman(path, d, &["--noise", "0.05", "--seed", seed]);
}

/// A folder with a sticky loop, a healthy loop and a file with a text cell in the op column.
fn plant(dir: &Path) -> PathBuf {
    let plant = dir.join("plant");
    std::fs::create_dir_all(&plant).unwrap();
    simulate(&plant.join("sticky.csv"), "2", "1");
    simulate(&plant.join("healthy.csv"), "0", "2");
    let healthy = std::fs::read_to_string(plant.join("healthy.csv")).unwrap();
    let bad: Vec<String> = healthy
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 41 {
                // t,sp,op,mv,pv: the op cell of line 42 is text
                let mut c: Vec<&str> = l.split(',').collect();
                c[2] = "n/a";
                c.join(",")
            } else {
                l.to_string()
            }
        })
        .collect();
    std::fs::write(plant.join("bad.csv"), bad.join("\n") + "\n").unwrap();
    std::fs::write(plant.join("notes.txt"), "not a loop").unwrap();
    plant
}

/// summary.csv as rows of column name -> cell.
fn summary(out: &Path) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(out.join("summary.csv")).unwrap();
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            headers
                .iter()
                .zip(rec.unwrap().iter())
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect()
        })
        .collect()
}

/// The summary without the timing column (the only one that differs between runs).
fn without_seconds(rows: Vec<BTreeMap<String, String>>) -> Vec<BTreeMap<String, String>> {
    rows.into_iter()
        .map(|mut r| {
            r.remove("seconds");
            r
        })
        .collect()
}

fn mtimes(dir: &Path) -> BTreeMap<String, SystemTime> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                e.metadata().unwrap().modified().unwrap(),
            )
        })
        .collect()
}

#[test]
fn a_folder_is_ranked_with_the_bad_loop_failed_and_the_rest_diagnosed() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path());
    let out = dir.path().join("out");
    // a failed loop: the batch finishes, writes everything, and exits 3
    let text = batch(&["batch", s(&plant), "-o", s(&out), "--sp", "sp"], 3);
    assert!(text.contains("3 loops"), "{text}");
    assert!(text.contains("1 loop failed"), "{text}");
    let rows = summary(&out);
    assert_eq!(rows.len(), 3, "one row per .csv file: {rows:?}");
    // the sticky loop first, with a positive severity from the closed-loop estimate
    assert_eq!(rows[0]["loop_id"], "sticky");
    assert_eq!(rows[0]["verdict"], "stiction");
    let severity: f64 = rows[0]["severity"].parse().unwrap();
    let band: f64 = rows[0]["band_percent_of_span"].parse().unwrap();
    let probability: f64 = rows[0]["probability"].parse().unwrap();
    assert!(band > 1.0 && band < 3.0, "band {band}");
    assert!((severity - band * probability).abs() < 1e-12);
    assert!(!rows[0]["reason"].is_empty());
    assert_eq!(rows[0]["samples"], "1500");
    assert_eq!(rows[0]["error"], "");
    assert_eq!(rows[1]["loop_id"], "healthy");
    // judged and not sticky (no_stiction or undetermined: the model's to say)
    assert!(
        ["no_stiction", "undetermined"].contains(&rows[1]["verdict"].as_str()),
        "{:?}",
        rows[1]
    );
    assert_eq!(rows[1]["severity"], "0");
    assert_eq!(rows[1]["error"], "");
    assert!(!rows[1]["reason"].is_empty());
    // the bad file: last, failed, one sentence naming file, line, column and the fix
    let bad = &rows[2];
    assert_eq!(bad["loop_id"], "bad");
    assert_eq!(bad["verdict"], "failed");
    for needle in ["bad.csv", "line 42", "column 'op'", "'n/a' is not a number"] {
        assert!(bad["error"].contains(needle), "{needle}: {}", bad["error"]);
    }
    assert_eq!(bad["reason"], bad["error"]);
    // per-loop JSON: the full diagnosis, for the loops that were diagnosed
    let d: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("loops/sticky.json")).unwrap()).unwrap();
    assert_eq!(d["verdict"], "stiction");
    assert!(d["quantification"]["params"]["d"].as_f64().is_some());
    assert!(out.join("loops/healthy.json").exists());
    assert!(!out.join("loops/bad.json").exists());
    // summary.json: the same rows, complete
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(j["complete"], true);
    assert_eq!(j["loops"], 3);
    assert_eq!(j["counts"]["failed"], 1);
    assert_eq!(j["rows"][0]["loop_id"], "sticky");
    assert_eq!(j["rows"][2]["verdict"], "failed");
}

#[test]
fn one_or_two_threads_give_the_same_summary() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path());
    simulate(&plant.join("sticky_b.csv"), "3", "5");
    let one = dir.path().join("one");
    let two = dir.path().join("two");
    for (dir, threads) in [(&one, "1"), (&two, "2")] {
        batch(
            &[
                "batch",
                s(&plant),
                "-o",
                s(dir),
                "--sp",
                "sp",
                "--threads",
                threads,
            ],
            3,
        );
    }
    let a = without_seconds(summary(&one));
    assert_eq!(a.len(), 4);
    assert_eq!(a, without_seconds(summary(&two)));
}

#[test]
fn resume_keeps_the_loops_already_diagnosed() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path());
    let out = dir.path().join("out");
    let args = [
        "batch",
        s(&plant),
        "-o",
        s(&out),
        "--sp",
        "sp",
        "--no-quantify",
    ];
    batch(&args, 3);
    let first = summary(&out);
    let before = mtimes(&out.join("loops"));
    assert_eq!(before.len(), 2, "{before:?}");
    // a new loop arrives; the others are not diagnosed again
    simulate(&plant.join("new.csv"), "0", "9");
    let text = batch(&[&args[..], &["--resume"]].concat(), 3);
    assert!(
        text.contains("resume: 2 kept, 0 redone because their input or settings changed, 1 new"),
        "{text}"
    );
    let after = mtimes(&out.join("loops"));
    for (name, t) in &before {
        assert_eq!(after[name], *t, "{name} was written again");
    }
    assert!(after.contains_key("new.json"));
    let second = summary(&out);
    assert_eq!(second.len(), 4);
    // the rows of the kept loops, timing included, are rebuilt from their JSON unchanged
    for row in &first {
        assert!(second.contains(row), "{row:?} changed");
    }
    // loops diagnosed with other settings are not mixed in
    fails(
        &[&args[..6], &["--resume"]].concat(),
        &["other settings", "without --resume"],
    );
}

#[test]
fn a_long_format_file_is_streamed_loop_by_loop() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path());
    // tag;t;op;pv (semicolon separated) with three loops, rows of each together
    let mut long = String::from("tag;t;sp;op;pv\n");
    let mut first_line = BTreeMap::new();
    let mut line = 2;
    for name in ["sticky", "healthy", "bad"] {
        first_line.insert(name, line);
        let text = std::fs::read_to_string(plant.join(format!("{name}.csv"))).unwrap();
        for l in text.lines().skip(1) {
            let c: Vec<&str> = l.split(',').collect();
            long.push_str(&format!("FIC-{name};{};{};{};{}\n", c[0], c[1], c[2], c[4]));
            line += 1;
        }
    }
    let file = dir.path().join("historian.csv");
    std::fs::write(&file, long).unwrap();
    let out = dir.path().join("out");
    batch(
        &[
            "batch",
            s(&file),
            "-o",
            s(&out),
            "--sp",
            "sp",
            "--loop-id",
            "tag",
            "--no-quantify",
            "--reports",
        ],
        3,
    );
    let rows = summary(&out);
    let ids: Vec<&str> = rows.iter().map(|r| r["loop_id"].as_str()).collect();
    assert_eq!(ids, ["FIC-sticky", "FIC-healthy", "FIC-bad"]);
    assert_eq!(rows[0]["verdict"], "stiction");
    assert_eq!(rows[0]["samples"], "1500");
    assert_eq!(
        rows[0]["source"],
        format!("{} lines 2-1501", file.display())
    );
    assert!(
        ["no_stiction", "undetermined"].contains(&rows[1]["verdict"].as_str()),
        "{:?}",
        rows[1]
    );
    // the error names the long file and its own line
    let bad_line = first_line["bad"] + 40;
    let err = &rows[2]["error"];
    assert!(
        err.contains("historian.csv") && err.contains(&format!("line {bad_line},")),
        "{err}"
    );
    // the same verdicts as the loops read from their own files
    let own = dir.path().join("own");
    batch(
        &[
            "batch",
            s(&plant),
            "-o",
            s(&own),
            "--sp",
            "sp",
            "--no-quantify",
        ],
        3,
    );
    let a: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("loops/FIC-sticky.json")).unwrap()).unwrap();
    let b: serde_json::Value =
        serde_json::from_slice(&std::fs::read(own.join("loops/sticky.json")).unwrap()).unwrap();
    assert_eq!(a["indices"], b["indices"]);
    // reports: a page per diagnosed loop and an index linking them in ranking order
    let index = std::fs::read_to_string(out.join("index.html")).unwrap();
    let p1 = index.find("reports/FIC-sticky.html").unwrap();
    let p2 = index.find("reports/FIC-healthy.html").unwrap();
    assert!(p1 < p2);
    assert!(!index.contains("reports/FIC-bad.html"));
    // one inline script (sorting, the verdict filter), nothing loaded from elsewhere
    assert_eq!(index.matches("<script").count(), 1);
    assert!(!index.contains("<script src"));
    let page = std::fs::read_to_string(out.join("reports/FIC-sticky.html")).unwrap();
    assert!(page.contains("../index.html") && page.contains("cross_correlation"));
    // the long file must name the columns the flags ask for: checked once, before any loop
    fails(
        &[
            "batch",
            s(&file),
            "-o",
            s(&out),
            "--loop-id",
            "tag",
            "--op",
            "OUT",
        ],
        &["historian.csv", "no column 'OUT'", "--op COLUMN"],
    );
}

#[test]
fn patterns_and_duplicate_ids() {
    let dir = tempfile::tempdir().unwrap();
    let plant = plant(dir.path());
    let other = dir.path().join("other");
    std::fs::create_dir_all(&other).unwrap();
    simulate(&other.join("healthy.csv"), "0", "3");
    let out = dir.path().join("out");
    let pattern = format!("{}/h*.csv", plant.display());
    let o = stiction(&[
        "batch",
        &pattern,
        s(&other),
        s(&plant.join("healthy.csv")), // named twice: read once
        "-o",
        s(&out),
        "--sp",
        "sp",
        "--no-quantify",
    ]);
    assert!(o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("'healthy~2'"), "{err}");
    let rows = summary(&out);
    let mut ids: Vec<&str> = rows.iter().map(|r| r["loop_id"].as_str()).collect();
    ids.sort();
    assert_eq!(ids, ["healthy", "healthy~2"]);
    let second = rows.iter().find(|r| r["loop_id"] == "healthy~2").unwrap();
    assert!(second["source"].contains("other"), "{second:?}");
}

#[test]
fn unusable_arguments_stop_with_one_sentence() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let empty = dir.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    fails(
        &["batch", s(&empty), "-o", s(&out)],
        &["no .csv files directly inside this folder"],
    );
    fails(
        &[
            "batch",
            &format!("{}/*.csv", empty.display()),
            "-o",
            s(&out),
        ],
        &["matches no file"],
    );
    fails(
        &["batch", s(&dir.path().join("missing.csv")), "-o", s(&out)],
        &["missing.csv", "no such file or folder"],
    );
    let file = dir.path().join("loop.csv");
    simulate(&file, "0", "1");
    fails(
        &["batch", s(&file), "-o", s(&file.join("out"))],
        &["cannot create the output folder", "-o OUTDIR"],
    );
    fails(
        &["batch", s(&file), "-o", s(&out), "--threads", "0"],
        &["--threads 0"],
    );
}

/// Loops that oscillate at one period count each other in summary.csv, summary.json, the console
/// and the fleet page; a loop that does not oscillate counts none.
#[test]
fn loops_that_share_a_period_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    let plant = dir.path().join("unit");
    std::fs::create_dir_all(&plant).unwrap();
    // the same sticky loop twice (one cycle seen in two loops) and a healthy one
    simulate(&plant.join("first.csv"), "2", "1");
    std::fs::copy(plant.join("first.csv"), plant.join("second.csv")).unwrap();
    simulate(&plant.join("healthy.csv"), "0", "2");
    let out = dir.path().join("out");
    let text = batch(
        &["batch", s(&plant), "-o", s(&out), "--sp", "sp", "--reports"],
        0,
    );
    assert!(
        text.contains("2 oscillating loops share their period"),
        "{text}"
    );
    let rows: BTreeMap<String, String> = summary(&out)
        .into_iter()
        .map(|r| (r["loop_id"].clone(), r["same_period_loops"].clone()))
        .collect();
    assert_eq!(rows["first"], "1");
    assert_eq!(rows["second"], "1");
    assert_eq!(rows["healthy"], "0");
    let j: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert!(j["rows"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["same_period_loops"].is_u64()));
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(page.contains(" +1</td>"), "the fleet page");
}
