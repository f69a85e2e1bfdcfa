//! `stiction diagnose` as a user types it: the binary is spawned, its output read.

use std::path::Path;

use crate::common;
use common::{closed_stenman, fails, json, ok};

/// A closed loop (default process K = 3, tau = 10 s, delay = 10 s, PI 0.2 / 10 s).
fn simulate(dir: &Path, name: &str, d: &str, extra: &[&str]) -> String {
    let p = dir.join(name);
    closed_stenman(
        &p,
        d,
        &[&["--noise", "0.05", "--seed", "3"], extra].concat(),
    );
    p.to_str().unwrap().to_string()
}

fn rows(path: &str) -> Vec<Vec<String>> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect()
}

#[test]
fn a_sticky_loop_is_stiction_with_the_band_sized() {
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "sticky.csv", "2", &[]);
    let v = json(&ok(&["diagnose", &f, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    let p = v["probability"].as_f64().unwrap();
    assert!(p > 0.0 && p <= 1.0, "{p}");
    // the one or two reasons that decided it, typed and in words
    let reasons = v["reasons"].as_array().unwrap();
    assert!(!reasons.is_empty() && reasons.len() <= 2, "{v:#}");
    for r in reasons {
        assert!(r["kind"].as_str().is_some(), "{r:#}");
        assert!(!r["text"].as_str().unwrap().is_empty(), "{r:#}");
    }
    // the model's reading: every statistic, its value and its share of the log-odds
    let read = v["statistics"]["contributions"].as_array().unwrap();
    assert!(!read.is_empty());
    for c in read {
        assert!(c["statistic"].as_str().is_some() && c["contribution"].as_f64().is_some());
    }
    let names: Vec<&str> = v["indices"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| i["name"].as_str().unwrap())
        .collect();
    assert!(names.contains(&"cross_correlation") && names.contains(&"curve_fitting"));
    assert!(names.contains(&"harmonics") && names.contains(&"shape"));
    // every family reports its value, threshold and vote
    let families = v["families"].as_array().unwrap();
    for name in ["valve", "model", "stick_slip", "shape", "loop"] {
        let f = families.iter().find(|f| f["family"] == name).unwrap();
        assert!(f["threshold"].as_str().is_some() && f["vote"].as_str().is_some());
    }
    let model = families.iter().find(|f| f["family"] == "model").unwrap();
    assert!(
        model["model"]["r2_stenman"].as_f64().unwrap() > 0.9,
        "{model:#}"
    );
    for i in v["indices"].as_array().unwrap() {
        assert!(i["threshold"].as_str().is_some() && i["vote"].as_str().is_some());
    }
    let d = v["band"]["band_percent_of_span"].as_f64().unwrap();
    assert!(d > 0.5 && d < 4.0, "band {d}");
    // the headline's estimator is the band calibration's choice; the closed-loop estimate is
    // the headline or beside it
    let band = &v["band"];
    assert!(
        band["source"] == "closed_loop"
            || band["others"]
                .as_array()
                .unwrap()
                .iter()
                .any(|o| o[0] == "closed_loop"),
        "{band:#}"
    );
    assert_eq!(v["next_step"]["action"], "travel_test", "{v:#}");
    assert!(
        v["next_step"]["text"].as_str().unwrap().contains("valve"),
        "{v:#}"
    );
    assert!(v["oscillation"]["period"].as_f64().unwrap() > 10.0);
    // the human printer says the same: the verdict and P first, the reasons, the band, the
    // next step, then every family's detail
    let text = ok(&["diagnose", &f, "--sp", "sp", "--no-quantify"]);
    let first = text.lines().next().unwrap();
    assert!(first.ends_with(&format!(": STICTION (P {p:.2})")), "{text}");
    assert!(text.contains("cross_correlation"), "{text}");
    assert!(text.contains("closed-loop fit's scan"), "{text}");
    let text = ok(&["diagnose", &f, "--sp", "sp"]);
    let lines: Vec<&str> = text.lines().collect();
    let at = |start: &str| {
        lines
            .iter()
            .position(|l| l.trim_start().starts_with(start))
            .unwrap_or_else(|| panic!("no line {start:?} in:\n{text}"))
    };
    let (why, band, next, details) = (
        at("why:"),
        at("stiction band:"),
        at("next step:"),
        at("details"),
    );
    assert!(why < band && band < next && next < details, "{text}");
    for r in reasons {
        assert!(text.contains(r["text"].as_str().unwrap()), "{text}");
    }
    assert!(text.contains("closed-loop fit: R²"), "{text}");
    assert!(text.contains("% of valve span"), "{text}");
    // one line per family under details, with its vote and share of the log-odds
    for f in families {
        let words = match f["family"].as_str().unwrap() {
            "valve" => "valve position",
            "model" => "closed-loop fit",
            "stick_slip" => "stick-slip episodes",
            "shape" => "shape of the oscillation",
            "loop" => "linear loop",
            other => panic!("{other}"),
        };
        assert!(
            lines[details..]
                .iter()
                .any(|l| l.trim_start().starts_with(words)),
            "{words}: {text}"
        );
    }
    assert_eq!(v["quantification"]["valve_start_kind"], "first_op");
    let v = json(&ok(&[
        "diagnose",
        &f,
        "--sp",
        "sp",
        "--estimate-start",
        "--json",
    ]));
    assert_eq!(
        v["quantification"]["valve_start_kind"], "estimated",
        "{v:#}"
    );
}

#[test]
fn a_healthy_loop_with_noise_only_is_no_stiction() {
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "healthy.csv", "0", &[]);
    let v = json(&ok(&["diagnose", &f, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "no_stiction", "{v:#}");
    assert!(v.get("quantification").is_none());
    // what the verdict speaks for: the bands the record hides, from OP's noise
    let reach = &v["reach"];
    let sd = reach["op_noise_percent_of_span"].as_f64().unwrap();
    assert!(sd > 0.0, "{reach:#}");
    let small = reach["small_band_percent_of_span"].as_f64().unwrap();
    let large = reach["large_band_percent_of_span"].as_f64().unwrap();
    assert!((small - 4.0 * sd).abs() < 1e-9 && (large - 12.0 * sd).abs() < 1e-9);
    // why, in words, and a next step that leaves the valve alone
    let reasons = v["reasons"].as_array().unwrap();
    assert!(!reasons.is_empty(), "{v:#}");
    assert!(reasons
        .iter()
        .all(|r| !r["text"].as_str().unwrap().is_empty()));
    let action = v["next_step"]["action"].as_str().unwrap();
    assert!(
        ["no_action", "no_action_weak", "check_tuning"].contains(&action),
        "{action}"
    );
    let human = ok(&["diagnose", &f, "--sp", "sp"]);
    let p = v["probability"].as_f64().unwrap();
    assert!(
        human
            .lines()
            .next()
            .unwrap()
            .ends_with(&format!(": no stiction (P {p:.2})")),
        "{human}"
    );
    assert!(human.contains("why:"), "{human}");
    let line = human
        .lines()
        .find(|l| l.trim_start().starts_with("what this record can show:"))
        .unwrap_or_else(|| panic!("no reach line in:\n{human}"));
    assert!(
        line.contains("times OP's noise") && !line.contains("simulated"),
        "{line}"
    );
}

#[test]
fn windows_locate_the_verdict_in_time() {
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "sticky.csv", "2", &[]);
    let v = json(&ok(&[
        "diagnose",
        &f,
        "--window",
        "500",
        "--no-quantify",
        "--json",
    ]));
    let w = v["windows"].as_array().unwrap();
    assert_eq!(w.len(), 3);
    assert_eq!(w[0]["start"], 0);
    assert_eq!(w[2]["end"], 1500);
    for x in w {
        assert!(x["verdict"].as_str().is_some());
        for r in x["reasons"].as_array().unwrap() {
            assert!(!r["text"].as_str().unwrap().is_empty(), "{x:#}");
        }
    }
    let text = ok(&["diagnose", &f, "--window", "500", "--no-quantify"]);
    assert!(text.contains("windows:"), "{text}");
}

/// The sticky loop exported the way a historian does: semicolons, decimal commas, text
/// timestamps every 2 s, a mode column.
fn historian(dir: &Path, manual_until: usize, gap_at: Option<usize>) -> String {
    let f = simulate(dir, "src.csv", "2", &[]);
    let r = rows(&f);
    let mut out = String::from("Timestamp;FIC101.OP;FIC101.PV;FIC101.SP;Mode\n");
    for (k, c) in r.iter().skip(1).enumerate() {
        let mut secs = 2 * k;
        if gap_at.is_some_and(|g| k >= g) {
            secs += 600;
        }
        let mode = if k < manual_until { "MAN" } else { "AUTO" };
        out.push_str(&format!(
            "2024-03-01 {:02}:{:02}:{:02};{};{};{};{mode}\n",
            10 + secs / 3600,
            (secs / 60) % 60,
            secs % 60,
            c[2].replace('.', ","),
            c[4].replace('.', ","),
            c[1].replace('.', ","),
        ));
    }
    let p = dir.join("historian.csv");
    std::fs::write(&p, out).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn historian_exports_with_timestamps_decimal_commas_and_a_mode_column() {
    let dir = tempfile::tempdir().unwrap();
    let h = historian(dir.path(), 300, None);
    let cols = [
        "--op",
        "FIC101.OP",
        "--pv",
        "FIC101.PV",
        "--sp",
        "FIC101.SP",
        "--mode",
        "Mode",
    ];
    let mut args = vec!["diagnose", &h];
    args.extend_from_slice(&cols);
    args.extend_from_slice(&["--json", "--no-quantify"]);
    let v = json(&ok(&args));
    assert_eq!(v["ts"], 2.0);
    // the manual stretch is left out
    assert_eq!(v["analysed"][0], 300);
    assert_eq!(v["verdict"], "stiction", "{v:#}");

    // always in manual: no verdict, and never a false "no stiction"
    let m = historian(dir.path(), 2000, None);
    let mut args = vec!["diagnose", &m];
    args.extend_from_slice(&cols);
    args.push("--json");
    let v = json(&ok(&args));
    assert_eq!(v["verdict"], "insufficient_data");
    assert!(
        v["reasons"][0]["text"].as_str().unwrap().contains("manual"),
        "{v:#}"
    );

    // a gap in the time axis splits the record; the longer stretch is judged
    let g = historian(dir.path(), 0, Some(700));
    let mut args = vec!["diagnose", &g];
    args.extend_from_slice(&cols);
    args.push("--json");
    let v = json(&ok(&args));
    assert_eq!(v["stretches"].as_array().unwrap().len(), 2, "{v:#}");
    assert!(
        v["quality"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f["gate"] == "time_gaps"),
        "{v:#}"
    );
    assert_eq!(v["verdict"], "stiction", "{v:#}");
}

/// A record of 1,000 samples with OP held at `op` while PV cycles.
fn held_op(dir: &Path, name: &str, op: f64) -> std::path::PathBuf {
    let mut text = String::from("t,op,pv\n");
    for k in 0..1000 {
        let pv = 50.0 + (k as f64 * 0.1).sin();
        text.push_str(&format!("{k},{op},{pv}\n"));
    }
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// A copy of the CSV at `path`, named `name`, with column `column` rewritten by `edit` (the
/// row, from 1 after the header, and the cell).
fn edited(
    path: &str,
    name: &str,
    column: &str,
    mut edit: impl FnMut(usize, &str) -> String,
) -> String {
    let raw = std::fs::read_to_string(path).unwrap();
    let mut lines = raw.lines();
    let header = lines.next().unwrap();
    let col = header.split(',').position(|c| c == column).unwrap();
    let mut out = format!("{header}\n");
    for (row, line) in lines.enumerate() {
        let mut cells: Vec<String> = line.split(',').map(String::from).collect();
        cells[col] = edit(row + 1, &cells[col]);
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    let p = Path::new(path).with_file_name(name);
    std::fs::write(&p, out).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn saturated_and_constant_loops_are_insufficient_data() {
    let dir = tempfile::tempdir().unwrap();
    let p = held_op(dir.path(), "sat.csv", 100.0);
    let v = json(&ok(&["diagnose", p.to_str().unwrap(), "--json"]));
    assert_eq!(v["verdict"], "insufficient_data");
    let text = ok(&["diagnose", p.to_str().unwrap()]);
    assert!(text.contains("insufficient data"), "{text}");
}

#[test]
fn a_still_op_is_insufficient_data_and_op_off_its_span_is_said() {
    let dir = tempfile::tempdir().unwrap();
    // OP held mid-range while PV cycles: the controller did not act, whatever PV does
    let p = held_op(dir.path(), "still.csv", 50.0);
    let v = json(&ok(&["diagnose", p.to_str().unwrap(), "--json"]));
    assert_eq!(v["verdict"], "insufficient_data", "{v:#}");
    assert!(
        v["reasons"][0]["text"]
            .as_str()
            .unwrap()
            .contains("OP stays at 50"),
        "{v:#}"
    );
    // OP in raw units (a flow setpoint of some thousands): bands in % of span need --op-range
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    let p = edited(&f, "raw.csv", "op", |_, v| {
        format!("{}", v.parse::<f64>().unwrap() * 40.0)
    });
    let text = ok(&["diagnose", &p, "--sp", "sp"]);
    assert!(text.contains("outside the valve's span 0 to 100"), "{text}");
    assert!(text.contains("--op-range"), "{text}");
    let text = ok(&["diagnose", &p, "--sp", "sp", "--op-range", "0:4000"]);
    assert!(!text.contains("outside the valve's span"), "{text}");
}

#[test]
fn a_pv_glitch_is_left_out_not_read() {
    // one historian glitch in a sticky loop's PV used to turn the verdict into "OP does not
    // drive this variation"
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    let p = edited(&f, "glitch.csv", "pv", |row, v| {
        if row == 501 {
            "1e6".into()
        } else {
            v.into()
        }
    });
    let v = json(&ok(&["diagnose", &p, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("1 sample in a spike left out"),
        "{warnings}"
    );
}

#[test]
fn historian_states_in_a_few_cells_are_bridged_not_a_split() {
    // four PV cells of "Bad Input", "I/O Timeout" or "No Data" (as PI exports them) used to cut
    // the record into four stretches; the last, 800 samples, was judged, with a band of 0.00 %
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    let p = edited(&f, "states.csv", "pv", |row, v| match row {
        301 | 302 => "Bad Input".into(),
        701 => "I/O Timeout".into(),
        1201 => "No Data".into(),
        _ => v.into(),
    });
    let v = json(&ok(&["diagnose", &p, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    assert_eq!(v["stretches"].as_array().unwrap().len(), 1, "{v:#}");
    let band = v["band"]["band_percent_of_span"].as_f64().unwrap();
    assert!((band - 2.0).abs() < 0.2, "band {band}");
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("3 short gaps (4 samples with a missing value) bridged"),
        "{warnings}"
    );
}

#[test]
fn a_merge_of_recorded_values_is_put_on_a_grid() {
    // a historian stores OP and PV each on change (past 0.05), and the export of both tags puts
    // them on the union of their times: most rows hold one and leave the other blank. Read as
    // gaps, the blanks cut the record into 418 stretches ("insufficient data").
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    let table = rows(&f);
    let mut out = String::from("t,sp,op,pv\n");
    let (mut last_op, mut last_pv) = (f64::NAN, f64::NAN);
    for r in &table[1..] {
        let (op, pv): (f64, f64) = (r[2].parse().unwrap(), r[4].parse().unwrap());
        let store_op = last_op.is_nan() || (op - last_op).abs() > 0.05;
        let store_pv = last_pv.is_nan() || (pv - last_pv).abs() > 0.05;
        if store_op {
            last_op = op;
        }
        if store_pv {
            last_pv = pv;
        }
        if store_op || store_pv {
            let cell = |store: bool, v: f64| {
                if store {
                    format!("{v:.4}")
                } else {
                    String::new()
                }
            };
            out.push_str(&format!(
                "{},{},{},{}\n",
                r[0],
                r[1],
                cell(store_op, op),
                cell(store_pv, pv)
            ));
        }
    }
    let p = dir.path().join("recorded.csv");
    std::fs::write(&p, out).unwrap();
    let p = p.to_str().unwrap();
    let v = json(&ok(&["diagnose", p, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    assert_eq!(v["samples"].as_u64(), Some(table.len() as u64 - 1), "{v:#}");
    let band = v["band"]["band_percent_of_span"].as_f64().unwrap();
    assert!((band - 2.0).abs() < 0.3, "band {band}");
    let human = ok(&["diagnose", p, "--sp", "sp", "--no-quantify"]);
    assert!(
        human.contains(
            "the signals are stored at their own times (a merge of a historian's recorded values"
        ) && human.contains("onto a grid every 1 s"),
        "{human}"
    );
    assert!(!human.contains("treated as missing"), "{human}");
}

#[test]
fn a_setpoint_stored_only_when_it_changes_is_held() {
    // step tags are exported with the value only where it changes; read as gaps, every row but
    // those was unusable ("the longest usable stretch has 1 samples")
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    let mut last = String::new();
    let p = edited(&f, "sp_on_change.csv", "sp", |_, v| {
        if v == last {
            String::new()
        } else {
            last = v.to_string();
            v.into()
        }
    });
    let v = json(&ok(&["diagnose", &p, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    let human = ok(&["diagnose", &p, "--sp", "sp", "--no-quantify"]);
    assert!(
        human.contains("the setpoint is stored only when it changes (")
            && human.contains("each value is held until the next"),
        "{human}"
    );
    assert!(!human.contains("treated as missing"), "{human}");
}

#[test]
fn a_mode_stored_only_when_it_changes_is_held() {
    // MAN in the first row, AUTO from row 300, blank between, as a step tag is exported; the
    // blanks were read as manual and left nothing to judge
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    let table = rows(&f);
    let mut out = format!("{},mode\n", table[0].join(","));
    for (k, r) in table[1..].iter().enumerate() {
        let mode = match k {
            0 => "MAN",
            300 => "AUTO",
            _ => "",
        };
        out.push_str(&format!("{},{mode}\n", r.join(",")));
    }
    let p = dir.path().join("mode.csv");
    std::fs::write(&p, out).unwrap();
    let p = p.to_str().unwrap();
    let v = json(&ok(&[
        "diagnose", p, "--sp", "sp", "--mode", "mode", "--json",
    ]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    assert_eq!(v["analysed"][0], 300, "{v:#}");
    let human = ok(&[
        "diagnose",
        p,
        "--sp",
        "sp",
        "--mode",
        "mode",
        "--no-quantify",
    ]);
    assert!(
        human.contains("the mode in column 'mode' is stored only when it changes"),
        "{human}"
    );
}

#[test]
fn bad_input_is_one_clear_sentence() {
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "loop.csv", "2", &[]);
    fails(
        &["diagnose", &f, "--sp", "setpoint"],
        &["'setpoint'", "--sp"],
    );
    fails(&["diagnose", &f, "--window", "10"], &["--window 10"]);
    fails(&["diagnose", &f, "--ts", "0"], &["--ts 0"]);
    let mut text = String::from("t,op,pv,mode\n");
    for k in 0..300 {
        text.push_str(&format!(
            "{k},{},{},{}\n",
            50.0 + (k % 7) as f64,
            k,
            if k == 5 { "maybe" } else { "1" }
        ));
    }
    let p = dir.path().join("mode.csv");
    std::fs::write(&p, text).unwrap();
    fails(
        &["diagnose", p.to_str().unwrap(), "--mode", "mode"],
        &["mode.csv", "line 7", "'mode'", "'maybe'", "auto or manual"],
    );
    let p = dir.path().join("empty.csv");
    std::fs::write(&p, "t,op,pv\n").unwrap();
    fails(
        &["diagnose", p.to_str().unwrap()],
        &["empty.csv", "no data rows"],
    );
}

/// A Stenman band of 2 (or a healthy valve) in the default loop, 2,000 samples, the setpoint
/// stepping every 150 s: no hold has two of the sticky loop's cycles (about 105 s).
fn short_holds(dir: &Path, d: &str) -> String {
    let sp = "steps:amplitude=1,hold=150,offset=50,seed=1";
    let extra = [
        "--noise",
        "0.05",
        "--seed",
        "3",
        "--sp",
        sp,
        "--samples",
        "2000",
    ];
    closed_loop(dir, &format!("holds_{d}.csv"), d, &extra)
}

/// `stiction simulate --loop closed --param d=D EXTRA -o DIR/NAME`, the file's path.
fn closed_loop(dir: &Path, name: &str, d: &str, extra: &[&str]) -> String {
    let path = dir.join(name).to_str().unwrap().to_string();
    let param = format!("d={d}");
    let args = [
        &["simulate", "--loop", "closed", "--param", &param],
        extra,
        &["-o", &path],
    ];
    ok(&args.concat());
    path
}

/// `stiction diagnose FILE --sp sp --no-quantify --json`, parsed.
fn sp_json(f: &str) -> serde_json::Value {
    json(&ok(&[
        "diagnose",
        f,
        "--sp",
        "sp",
        "--no-quantify",
        "--json",
    ]))
}

#[test]
fn a_cycle_across_short_setpoint_holds_is_judged_across_them_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let f = short_holds(dir.path(), "2");
    let v = sp_json(&f);
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    let o = &v["oscillation"];
    assert_eq!(o["oscillating"], true, "{o:#}");
    assert_eq!(o["across_setpoint_steps"], true, "{o:#}");
    assert_eq!(o["stretch"], serde_json::json!([0, 2000]), "{o:#}");
    assert!(o["cycle_share"].as_f64().unwrap() >= 0.3, "{o:#}");
    let text = ok(&["diagnose", &f, "--sp", "sp", "--no-quantify"]);
    assert!(text.contains("across the setpoint's steps"), "{text}");
    // the same loop with a healthy valve has no cycle to find across its steps
    let v = sp_json(&short_holds(dir.path(), "0"));
    assert_ne!(v["verdict"], "stiction", "{v:#}");
    let o = &v["oscillation"];
    assert!(o.get("across_setpoint_steps").is_none(), "{o:#}");
}

/// Issue 10's integrating loop, typed as the issue types it: `simulate --loop closed --param d=D
/// --process integrating:K=0.05,delay=5 --noise 0.05`.
fn integrating_loop(dir: &Path, d: &str) -> String {
    let extra = ["--process", "integrating:K=0.05,delay=5", "--noise", "0.05"];
    closed_loop(dir, &format!("integrating_{d}.csv"), d, &extra)
}

#[test]
fn a_level_is_checked_and_its_band_measured_without_being_told_it_integrates() {
    // its cycle lasts about as long as the changes the closed-loop fit compares: differenced over
    // a whole period, the cycle (and the valve that drives it) would cancel; the lag is kept off
    // it and the fit measures the band. The loop is judged self-regulating unless told (or a tag
    // says so), and the warning says PV behaves as a level's
    let dir = tempfile::tempdir().unwrap();
    let judge = |f: &str, more: &[&str]| {
        let mut args = vec!["diagnose", f, "--sp", "sp", "--json"];
        args.extend_from_slice(more);
        json(&ok(&args))
    };
    let sticky = integrating_loop(dir.path(), "2");
    let v = judge(&sticky, &[]);
    assert_eq!(v["loop_kind"]["integrating"], false, "{v:#}");
    assert_eq!(v["loop_kind"]["behaves_integrating"], true, "{v:#}");
    let warned = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("say --integrating"));
    assert!(warned, "{:#}", v["warnings"]);
    let v = judge(&sticky, &["--integrating"]);
    assert_eq!(v["loop_kind"]["integrating"], true, "{v:#}");
    assert_eq!(v["loop_kind"]["from"], "request", "{v:#}");
    let model = v["families"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["family"] == "model")
        .unwrap();
    let m = &model["model"];
    let (period, lag) = (
        v["oscillation"]["period"].as_f64().unwrap(),
        m["lag"].as_f64().unwrap(),
    );
    let kept = 2.0 * (std::f64::consts::PI * lag / period).sin().abs();
    assert!(
        kept >= 0.5,
        "lag {lag} s keeps {kept} of the {period} s cycle"
    );
    assert!(
        (m["stenman_d"].as_f64().unwrap() - 2.0).abs() < 0.2,
        "{m:#}"
    );
    // the same loop with a healthy valve
    let v = judge(&integrating_loop(dir.path(), "0"), &[]);
    assert_ne!(v["verdict"], "stiction", "{v:#}");
}

#[test]
fn a_tag_in_a_column_name_hints_the_loops_kind() {
    let dir = tempfile::tempdir().unwrap();
    let f = integrating_loop(dir.path(), "2");
    let text = std::fs::read_to_string(&f).unwrap();
    let tagged = dir.path().join("tagged.csv");
    std::fs::write(&tagged, text.replacen("pv", "LIC101.PV", 1)).unwrap();
    let t = tagged.to_str().unwrap();
    let v = json(&ok(&[
        "diagnose",
        t,
        "--pv",
        "LIC101.PV",
        "--sp",
        "sp",
        "--json",
    ]));
    assert_eq!(v["loop_kind"]["integrating"], true, "{v:#}");
    assert_eq!(v["loop_kind"]["from"], "tag", "{v:#}");
    assert_eq!(v["loop_kind"]["tag"], "LIC101", "{v:#}");
    // the flag overrides the tag
    let v = json(&ok(&[
        "diagnose",
        t,
        "--pv",
        "LIC101.PV",
        "--sp",
        "sp",
        "--self-regulating",
        "--json",
    ]));
    assert_eq!(v["loop_kind"]["integrating"], false, "{v:#}");
    assert_eq!(v["loop_kind"]["from"], "request", "{v:#}");
}

/// The same valve and noise with another seed: the cycle's period wanders, and read plainly the
/// autocorrelation's scatter near zero breaks its periods up; read through its noise band it is an
/// oscillation, and the output says how it was read. The healthy valve's loop has none either way.
#[test]
fn a_wandering_cycle_is_read_through_the_noise_band_and_said_so() {
    let dir = tempfile::tempdir().unwrap();
    let extra = ["--noise", "0.45", "--seed", "1", "--samples", "2000"];
    let f = closed_loop(dir.path(), "wandering.csv", "0.5", &extra);
    let o = &sp_json(&f)["oscillation"];
    assert_eq!(o["oscillating"], true, "{o:#}");
    assert_eq!(o["through_noise_band"], true, "{o:#}");
    let text = ok(&["diagnose", &f, "--sp", "sp", "--no-quantify"]);
    assert!(
        text.contains("zero crossings taken through its noise band"),
        "{text}"
    );
    let o = &sp_json(&closed_loop(dir.path(), "healthy.csv", "0", &extra))["oscillation"];
    assert_eq!(o["oscillating"], false, "{o:#}");
    assert!(o.get("through_noise_band").is_none(), "{o:#}");
}

/// A sticky valve's cycle only 2.5 noise standard deviations high (Stenman 0.5 %, PV noise 0.45)
/// is a weak cycle: an oscillation, and said to be one; the healthy valve's loop in the same
/// noise has none.
#[test]
fn a_weak_cycle_is_an_oscillation_and_said_to_be_weak() {
    let dir = tempfile::tempdir().unwrap();
    let extra = ["--noise", "0.45", "--seed", "4", "--samples", "2000"];
    let f = closed_loop(dir.path(), "weak.csv", "0.5", &extra);
    let v = sp_json(&f);
    let o = &v["oscillation"];
    assert_eq!(o["oscillating"], true, "{o:#}");
    assert_eq!(o["weak_cycle"], true, "{o:#}");
    assert!(o["iae"]["exceedances"].as_u64().unwrap() < 4, "{o:#}");
    let text = ok(&["diagnose", &f, "--sp", "sp", "--no-quantify"]);
    assert!(text.contains("oscillation: yes, a weak cycle"), "{text}");
    let v = sp_json(&closed_loop(dir.path(), "healthy.csv", "0", &extra));
    let o = &v["oscillation"];
    assert_eq!(o["oscillating"], false, "{o:#}");
    assert!(o.get("weak_cycle").is_none(), "{o:#}");
}

/// `diagnose --settings`: how diagnose measures and decides, with no file, as text and JSON.
#[test]
fn settings_print_the_table_and_the_verdicts_model() {
    let text = ok(&["diagnose", "--settings"]);
    for needle in [
        "[steps]",
        "[stuck]",
        "penalty = ",
        "stiction from P ",
        "knots",
    ] {
        assert!(text.contains(needle), "{needle}: {text}");
    }
    let v = json(&ok(&["diagnose", "--settings", "--json"]));
    assert!(
        v["settings"]["steps"]["penalty"].as_f64().is_some(),
        "{v:#}"
    );
    let model = &v["model"];
    let inputs = model["inputs"].as_array().unwrap();
    assert!(!inputs.is_empty(), "{v:#}");
    for i in inputs {
        let name = i["statistic"].as_str().unwrap();
        assert!(text.contains(name), "{name}: {text}");
        assert_eq!(
            i["knots"].as_array().unwrap().len(),
            i["weights"].as_array().unwrap().len()
        );
    }
    let (below, from) = (
        model["no_stiction_below"].as_f64().unwrap(),
        model["stiction_from"].as_f64().unwrap(),
    );
    assert!(0.0 < below && below <= from && from < 1.0);
    // without --settings a file is needed
    fails(&["diagnose"], &["FILE"]);
}

#[test]
fn a_long_record_is_judged_on_its_means_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let f = simulate(dir.path(), "long.csv", "2", &["--samples", "24000"]);
    let v = json(&ok(&["diagnose", &f, "--sp", "sp", "--json"]));
    assert_eq!(v["verdict"], "stiction", "{v:#}");
    let on = &v["judged_on"];
    let over = on["over"].as_u64().unwrap();
    assert!(over > 1, "{on:#}");
    assert!(on["samples"].as_u64().unwrap() >= 2000, "{on:#}");
    let text = ok(&["diagnose", &f, "--sp", "sp"]);
    assert!(
        text.contains(&format!("judged on means of {over} samples")),
        "{text}"
    );
    // a record of the usual length is judged sample by sample, and the JSON says nothing of it
    let short = simulate(dir.path(), "short.csv", "2", &[]);
    let v = json(&ok(&["diagnose", &short, "--sp", "sp", "--json"]));
    assert!(v.get("judged_on").is_none(), "{v:#}");
}
