//! `stiction batch` on a plant's own layouts: wide exports holding many loops' tags, split by a
//! tag pattern (`--tags`), and a loop list naming each loop's columns and options (`--columns`).

use std::collections::BTreeMap;
use std::path::Path;

use crate::common;
use common::{closed_stenman, fails, stiction};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Runs a batch that must exit with `code`; its stdout and stderr.
fn batch(args: &[&str], code: i32) -> (String, String) {
    let o = stiction(args);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    (String::from_utf8(o.stdout).unwrap(), err)
}

/// A wide export: `time` and, per loop, its columns named `<loop>.<ROLE>` from a simulated loop
/// (FIC101 sticky with OP, PV and SP; LIC7 healthy, in lower case; TIC3 with a PV only).
fn wide(dir: &Path) -> std::path::PathBuf {
    let sticky = dir.join("sticky.csv");
    let healthy = dir.join("healthy.csv");
    closed_stenman(&sticky, "2", &["--noise", "0.05", "--seed", "1"]);
    closed_stenman(&healthy, "0", &["--noise", "0.05", "--seed", "2"]);
    let read = |p: &Path| -> Vec<Vec<String>> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(str::to_string).collect())
            .collect()
    };
    // t,sp,op,mv,pv
    let (a, b) = (read(&sticky), read(&healthy));
    let mut text = String::from("time,FIC101.OP,FIC101.PV,FIC101.SP,LIC7.op,lic7.pv,TIC3.PV\n");
    for (x, y) in a.iter().zip(&b) {
        text.push_str(&format!(
            "{},{},{},{},{},{},{}\n",
            x[0], x[2], x[4], x[1], y[2], y[4], y[4]
        ));
    }
    let file = dir.join("wide.csv");
    std::fs::write(&file, text).unwrap();
    file
}

fn summary(out: &Path) -> BTreeMap<String, BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(out.join("summary.csv")).unwrap();
    let headers = r.headers().unwrap().clone();
    r.records()
        .map(|rec| {
            let row: BTreeMap<String, String> = headers
                .iter()
                .zip(rec.unwrap().iter())
                .map(|(h, c)| (h.to_string(), c.to_string()))
                .collect();
            (row["loop_id"].clone(), row)
        })
        .collect()
}

fn loop_json(out: &Path, id: &str) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(out.join(format!("loops/{id}.json"))).unwrap()).unwrap()
}

#[test]
fn a_tag_pattern_splits_a_wide_export_into_loops() {
    let dir = tempfile::tempdir().unwrap();
    let file = wide(dir.path());
    let out = dir.path().join("out");
    let args = [
        "batch",
        s(&file),
        "-o",
        s(&out),
        "--tags",
        "{loop}.{role}",
        "--no-quantify",
    ];
    batch(&args, 3);
    let rows = summary(&out);
    assert_eq!(rows.len(), 3, "{rows:?}");
    assert_eq!(rows["FIC101"]["verdict"], "stiction");
    assert!(rows["FIC101"]["source"].contains("FIC101.OP"));
    // the verdict is the model's (a healthy loop read as a level, without its setpoint): not
    // what this test is about; it is judged, and not called sticky
    assert!(
        ["no_stiction", "undetermined"].contains(&rows["LIC7"]["verdict"].as_str()),
        "{:?}",
        rows["LIC7"]
    );
    // a loop without an op column: a failed row naming file, loop and the column looked for
    let tic = &rows["TIC3"];
    assert_eq!(tic["verdict"], "failed");
    for needle in ["wide.csv", "loop 'TIC3'", "no op column", "'TIC3.OP'"] {
        assert!(tic["error"].contains(needle), "{needle}: {}", tic["error"]);
    }
    // each loop read with its own columns (the setpoint too), as its own file would be
    let j = loop_json(&out, "FIC101");
    assert_eq!(j["input"]["settings"]["sp"], "FIC101.SP");
    assert_eq!(j["input"]["settings"]["op"], "FIC101.OP");
    let own = dir.path().join("own");
    batch(
        &[
            "batch",
            s(&dir.path().join("sticky.csv")),
            "-o",
            s(&own),
            "--sp",
            "sp",
            "--no-quantify",
        ],
        0,
    );
    assert_eq!(j["indices"], loop_json(&own, "sticky")["indices"]);
    // the pattern must name the loop and the role
    fails(
        &[&args[..4], &["--tags", "{loop}"]].concat(),
        &["--tags '{loop}'", "{loop} and {role}"],
    );
}

#[test]
fn a_toml_loop_list_names_each_loops_columns_and_options() {
    let dir = tempfile::tempdir().unwrap();
    let file = wide(dir.path());
    let list = dir.path().join("loops.toml");
    let write_list = |lic_integrating: bool| {
        std::fs::write(
            &list,
            format!(
                r#"# the plant's loop list
[[loop]]
id = "FIC101"
op = "FIC101.OP"
pv = "FIC101.PV"
sp = "FIC101.SP"

[[loop]]
id = "LIC7"
file = "wide.csv"
op = "LIC7.OP"
pv = "LIC7.PV"
integrating = {lic_integrating}
ts = 1

[[loop]]
id = "BAD"
op = "FIC101.OP"
pv = "FIC101.MISSING"

[[loop]]
id = "GHOST"
op = "GHOST.OP"
pv = "GHOST.PV"
"#
            ),
        )
        .unwrap();
    };
    write_list(true);
    let out = dir.path().join("out");
    let args = [
        "batch",
        s(&file),
        "-o",
        s(&out),
        "--columns",
        s(&list),
        "--no-quantify",
    ];
    let (text, _) = batch(&args, 3);
    assert!(text.contains("4 loops"), "{text}");
    let rows = summary(&out);
    assert_eq!(rows["FIC101"]["verdict"], "stiction");
    // the verdict is the model's (a healthy loop read as a level, without its setpoint): not
    // what this test is about; it is judged, and not called sticky
    assert!(
        ["no_stiction", "undetermined"].contains(&rows["LIC7"]["verdict"].as_str()),
        "{:?}",
        rows["LIC7"]
    );
    // a column the file lacks: a failed row naming file, column and loop
    let bad = &rows["BAD"]["error"];
    for needle in [
        "wide.csv",
        "'FIC101.MISSING'",
        "loop 'BAD'",
        "loops.toml, loop 3",
    ] {
        assert!(bad.contains(needle), "{needle}: {bad}");
    }
    let ghost = &rows["GHOST"]["error"];
    assert!(
        ghost.contains("loop 'GHOST'")
            && ghost.contains("no input file has its op column 'GHOST.OP'"),
        "{ghost}"
    );
    let settings = &loop_json(&out, "LIC7")["input"]["settings"];
    assert_eq!(settings["integrating"], true);
    assert_eq!(settings["ts"], 1.0);
    assert_eq!(
        loop_json(&out, "FIC101")["input"]["settings"]["integrating"],
        false
    );
    // the list changes one loop's options: --resume diagnoses that loop again, keeps the other
    write_list(false);
    let (text, _) = batch(&[&args[..], &["--resume"]].concat(), 3);
    assert!(
        text.contains("resume: 1 kept, 1 redone because their input or settings changed, 0 new"),
        "{text}"
    );
    assert_eq!(
        loop_json(&out, "LIC7")["input"]["settings"]["integrating"],
        false
    );
}

#[test]
fn a_loop_list_names_the_tags_of_a_narrow_export() {
    // a row per tag and time (tag, time, value): the list's columns are tags
    let dir = tempfile::tempdir().unwrap();
    let sticky = dir.path().join("sticky.csv");
    closed_stenman(&sticky, "2", &["--noise", "0.05", "--seed", "1"]);
    let mut text = String::from("tag,time,value\n");
    for line in std::fs::read_to_string(&sticky).unwrap().lines().skip(1) {
        let c: Vec<&str> = line.split(',').collect(); // t,sp,op,mv,pv
        for (tag, k) in [
            ("FIC101.OP", 2),
            ("FIC101.PV", 4),
            ("LIC7.OP", 2),
            ("LIC7.PV", 4),
        ] {
            text.push_str(&format!("{tag},{},{}\n", c[0], c[k]));
        }
    }
    let file = dir.path().join("plant.csv");
    std::fs::write(&file, text).unwrap();
    let list = dir.path().join("loops.toml");
    let entry = |id: &str, tag: &str| {
        format!(
            "[[loop]]\nid = \"{id}\"\nfile = \"plant.csv\"\nop = \"{tag}.OP\"\npv = \"{tag}.PV\"\n"
        )
    };
    let toml = [
        entry("FIC101", "FIC101"),
        entry("LIC7", "LIC7"),
        entry("BAD", "NOPE"),
    ]
    .concat();
    std::fs::write(&list, toml).unwrap();
    let out = dir.path().join("out");
    let (text, _) = batch(
        &[
            "batch",
            s(&file),
            "-o",
            s(&out),
            "--columns",
            s(&list),
            "--no-quantify",
        ],
        3,
    );
    assert!(text.contains("3 loops"), "{text}");
    let rows = summary(&out);
    assert_eq!(rows["FIC101"]["verdict"], "stiction");
    assert_eq!(rows["LIC7"]["verdict"], "stiction");
    let bad = &rows["BAD"]["error"];
    assert!(
        bad.contains("no column 'NOPE.OP'") && bad.contains("the file looks narrow"),
        "{bad}"
    );
}

#[test]
fn a_csv_loop_list_gives_options_to_the_loops_of_a_long_format_file() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.csv");
    let b = dir.path().join("b.csv");
    closed_stenman(&a, "2", &["--noise", "0.05", "--seed", "1"]);
    closed_stenman(&b, "0", &["--noise", "0.05", "--seed", "2"]);
    let mut long = String::from("tag,t,SETPOINT,OUT,MEAS\n");
    for (name, f) in [("FIC1", &a), ("FIC2", &b)] {
        for l in std::fs::read_to_string(f).unwrap().lines().skip(1) {
            let c: Vec<&str> = l.split(',').collect();
            long.push_str(&format!("{name},{},{},{},{}\n", c[0], c[1], c[2], c[4]));
        }
    }
    let file = dir.path().join("historian.csv");
    std::fs::write(&file, long).unwrap();
    // semicolons, any case in the header, options left empty take the flags'
    let list = dir.path().join("loops.csv");
    std::fs::write(
        &list,
        "ID;OP;PV;SP;integrating;ts\nFIC1;OUT;MEAS;SETPOINT;;2\nFIC2;OUT;MEAS;NOPE;no;\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    batch(
        &[
            "batch",
            s(&file),
            "-o",
            s(&out),
            "--loop-id",
            "tag",
            "--columns",
            s(&list),
            "--no-quantify",
        ],
        3,
    );
    let rows = summary(&out);
    assert_eq!(rows["FIC1"]["verdict"], "stiction");
    assert_eq!(loop_json(&out, "FIC1")["input"]["settings"]["ts"], 2.0);
    assert_eq!(loop_json(&out, "FIC1")["ts"], 2.0);
    let err = &rows["FIC2"]["error"];
    for needle in ["historian.csv", "'NOPE'", "loop 'FIC2'", "loops.csv line 3"] {
        assert!(err.contains(needle), "{needle}: {err}");
    }
    // the loop of a long file: its hash is of its own rows, so it is kept when others change
    let h = loop_json(&out, "FIC1")["input"]["hash"].clone();
    assert_eq!(h.as_str().unwrap().len(), 16);
}

#[test]
fn an_unusable_loop_list_stops_with_one_sentence() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("x.csv");
    closed_stenman(&file, "0", &[]);
    let out = dir.path().join("out");
    let list = dir.path().join("loops.toml");
    let run = |text: &str, needles: &[&str]| {
        std::fs::write(&list, text).unwrap();
        fails(
            &["batch", s(&file), "-o", s(&out), "--columns", s(&list)],
            needles,
        );
    };
    run(
        "[[loop]\nid = 1",
        &["loops.toml", "not a loop list", "[[loop]]"],
    );
    run(
        "[[loop]]\nid = \"A\"\nop = \"A.OP\"\npv = \"A.PV\"\ncolour = \"red\"",
        &["loops.toml", "colour"],
    );
    run(
        "[[loop]]\nid = \"A\"\nop = \"A.OP\"",
        &["loops.toml, loop 1", "loop 'A' names no pv column"],
    );
    run(
        "[[loop]]\nid = \"A\"\nop = \"A.OP\"\npv = \"A.PV\"\nts = -1",
        &["loop 'A'", "ts -1", "positive"],
    );
    fails(
        &[
            "batch",
            s(&file),
            "-o",
            s(&out),
            "--columns",
            s(&dir.path().join("none.toml")),
        ],
        &["none.toml", "cannot be read", "--columns"],
    );
    let o = stiction(&[
        "batch",
        s(&file),
        "-o",
        s(&out),
        "--columns",
        s(&list),
        "--tags",
        "{loop}.{role}",
    ]);
    assert_eq!(o.status.code(), Some(2));
}
