//! The command line as a user types it: the binary is spawned, its output read.

use std::path::{Path, PathBuf};

use crate::common;
use common::{closed_stenman, fails, json, ok, stiction};

fn tmp() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn simulate_open(dir: &Path, d: &str) -> String {
    let p: PathBuf = dir.join("open.csv");
    let path = p.to_str().unwrap();
    ok(&[
        "simulate",
        "--model",
        "stenman",
        "--param",
        &format!("d={d}"),
        "-o",
        path,
    ]);
    path.to_string()
}

#[test]
fn simulate_then_estimate_exact() {
    let dir = tmp();
    let file = simulate_open(dir.path(), "0.5");
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.starts_with("t,sp,op,mv,pv\n"));
    assert_eq!(text.lines().count(), 1002);
    let v = json(&ok(&[
        "estimate", &file, "--op", "op", "--mv", "mv", "--model", "stenman", "--method", "exact",
        "--json",
    ]));
    for key in [
        "model",
        "method",
        "params",
        "interval",
        "sse",
        "evaluations",
        "seconds",
    ] {
        assert!(v.get(key).is_some(), "no {key} in {v}");
    }
    let [lo, hi] = [
        v["interval"]["d"][0].as_f64().unwrap(),
        v["interval"]["d"][1].as_f64().unwrap(),
    ];
    assert!(lo <= 0.5 && 0.5 <= hi, "[{lo}, {hi}]");
    assert_eq!(v["sse"].as_f64().unwrap(), 0.0);
    assert_eq!(v["method"], "exact");
}

#[test]
fn estimate_with_the_papers_aco_and_a_trace() {
    let dir = tmp();
    let file = simulate_open(dir.path(), "0.2");
    let trace = dir.path().join("trace.csv");
    let out = ok(&[
        "estimate",
        &file,
        "--model",
        "stenman",
        "--method",
        "aco",
        "--seed",
        "4",
        "--trace",
        trace.to_str().unwrap(),
        "--json",
    ]);
    let v = json(&out);
    assert!((v["params"]["d"].as_f64().unwrap() - 0.2).abs() < 0.011);
    assert_eq!(v["seed"], 4);
    assert_eq!(v["certificate"]["estimate_is_optimal"], true);
    let t = std::fs::read_to_string(trace).unwrap();
    assert!(t.starts_with(
        "iteration,best_d,best_sse,iteration_best_d,iteration_best_sse,evaluations\n"
    ));
    assert_eq!(t.lines().count(), 101);
    // the same seed gives the same answer
    assert_eq!(
        json(&ok(&[
            "estimate", &file, "--method", "aco", "--seed", "4", "--json"
        ]))["params"],
        v["params"]
    );
    // human output says the same in words
    let human = ok(&["estimate", &file, "--method", "aco", "--seed", "4"]);
    assert!(
        human.contains("d = 0.2") && human.contains("is optimal"),
        "{human}"
    );
}

#[test]
fn two_parameter_models_default_to_aco_r() {
    let dir = tmp();
    let file = dir.path().join("kano.csv");
    let f = file.to_str().unwrap();
    ok(&[
        "simulate",
        "--model",
        "kano",
        "--param",
        "S=4,J=1",
        "--signal",
        "sine:amplitude=10,period=50,offset=50",
        "--ts",
        "0.5",
        "--samples",
        "600",
        "-o",
        f,
    ]);
    let v = json(&ok(&["estimate", f, "--model", "kano", "--json"]));
    assert_eq!(v["method"], "aco-r");
    assert!(
        (v["params"]["S"].as_f64().unwrap() - 4.0).abs() < 0.3,
        "{v}"
    );
    assert!(
        (v["params"]["J"].as_f64().unwrap() - 1.0).abs() < 0.3,
        "{v}"
    );
    let g = json(&ok(&[
        "estimate", f, "--model", "he", "--method", "grid", "--points", "60", "--json",
    ]));
    assert_eq!(g["evaluations"], 3600);
}

#[test]
fn closed_loop_simulation_as_in_the_issue() {
    let dir = tmp();
    let file = dir.path().join("loop.csv");
    let f = file.to_str().unwrap();
    ok(&[
        "simulate",
        "--loop",
        "closed",
        "--model",
        "stenman",
        "--param",
        "d=0.5",
        "--process",
        "foptd:K=3,tau=10,delay=10",
        "--pi",
        "Kc=0.2,Ti=10",
        "--ts",
        "1",
        "--samples",
        "2000",
        "--noise",
        "0.05",
        "--seed",
        "7",
        "-o",
        f,
    ]);
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.starts_with("t,sp,op,mv,pv\n"));
    assert_eq!(text.lines().count(), 2001);
    let row: Vec<&str> = text.lines().nth(1500).unwrap().split(',').collect();
    assert_eq!(row.len(), 5);
    assert!(row.iter().all(|c| c.parse::<f64>().is_ok()), "{row:?}");
    // an ideal valve is a valid valve
    ok(&[
        "simulate", "--loop", "closed", "--model", "stenman", "--param", "d=0", "-o", f,
    ]);
    ok(&[
        "simulate",
        "--loop",
        "closed",
        "--model",
        "kano",
        "--param",
        "S=3",
        "--param",
        "J=1",
        "--process",
        "integrating:K=0.02,delay=2",
        "--pi",
        "Kc=2,Ti=50",
        "-o",
        f,
    ]);
}

#[test]
fn columns_match_case_insensitively_and_separators_are_sniffed() {
    let dir = tmp();
    let mut text = String::from("Time;OP;Valve\n");
    for k in 0..200 {
        let u = (k as f64 * 0.3).sin() * 2.0;
        let x = if k % 7 == 0 {
            u
        } else {
            (u * 2.0).round() / 2.0
        };
        text.push_str(&format!("{k};{u};{x}\n"));
    }
    let f = write(dir.path(), "semi.csv", &text);
    let v = json(&ok(&[
        "estimate", &f, "--op", "op", "--mv", "VALVE", "--json",
    ]));
    assert_eq!(v["samples"], 200);
    let tabbed = write(dir.path(), "tab.tsv", &text.replace(';', "\t"));
    ok(&["estimate", &tabbed, "--mv", "valve", "--time", "TIME"]);
}

#[test]
fn reproduce_paper_json_and_figures() {
    let dir = tmp();
    let out = dir.path().join("paper");
    let v = json(&ok(&[
        "reproduce",
        "paper",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    let cases = v["cases"].as_array().unwrap();
    assert_eq!(cases.len(), 2);
    for (c, (d, paper)) in cases.iter().zip([(0.2, 0.2), (0.5, 0.48)]) {
        assert_eq!(c["true_d"], d);
        assert_eq!(c["paper_estimate"], paper);
        assert_eq!(c["estimates"].as_array().unwrap().len(), 20);
        assert_eq!(c["inside"], 20);
        let lo = c["interval"][0].as_f64().unwrap();
        let hi = c["interval"][1].as_f64().unwrap();
        assert!(lo <= d && d < hi);
    }
    for stem in [
        "fig5_response_weak",
        "fig6_response_strong",
        "fig5-6_phase_plot",
        "fig7_trajectories_weak",
        "fig8_trajectories_strong",
    ] {
        for ext in ["png", "svg"] {
            let p = out.join(format!("{stem}.{ext}"));
            assert!(
                std::fs::metadata(&p)
                    .map(|m| m.len() > 5000)
                    .unwrap_or(false),
                "{}",
                p.display()
            );
        }
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        assert!(
            svg.contains("<text"),
            "{stem}.svg has no text (title, labels)"
        );
    }
    let human = ok(&["reproduce", "paper", "--out", out.to_str().unwrap()]);
    assert!(human.contains("20/20") && human.contains("0.48"), "{human}");
}

// ----------------------------------------------------------------------------- bad input

fn good_rows(n: usize) -> String {
    let mut s = String::from("t,op,mv\n");
    for k in 0..n {
        s.push_str(&format!("{k},{},{}\n", k % 5, (k % 5) / 2));
    }
    s
}

#[test]
fn missing_file_and_column() {
    let dir = tmp();
    fails(
        &["estimate", "/no/such/file.csv"],
        &["/no/such/file.csv", "no such file"],
    );
    let f = write(dir.path(), "a.csv", &good_rows(20));
    fails(
        &["estimate", &f, "--mv", "position"],
        &["a.csv", "'position'", "t, op, mv", "--mv"],
    );
    fails(
        &["estimate", &f, "--time", "clock"],
        &["a.csv", "'clock'", "--time"],
    );
}

#[test]
fn non_numeric_nan_and_infinite_cells() {
    let dir = tmp();
    let mut text = good_rows(20);
    text = text.replacen("7,2,1", "7,abc,1", 1);
    let f = write(dir.path(), "b.csv", &text);
    fails(
        &["estimate", &f],
        &["b.csv", "line 9", "column 'op'", "'abc'", "not a number"],
    );
    // NaN is a gap: the longest stretch without one is used, and a note says so
    let f = write(
        dir.path(),
        "c.csv",
        &good_rows(20).replacen("7,2,1", "7,2,NaN", 1),
    );
    let err = ok(&["estimate", &f]);
    assert!(
        err.contains("  note: 1 cell treated as missing (mv 1")
            && err.contains("using line 10 to 21")
            && err.contains("12 samples of 20"),
        "{err}"
    );
    let f = write(
        dir.path(),
        "d.csv",
        &good_rows(20).replacen("7,2,1", "7,inf,1", 1),
    );
    fails(
        &["estimate", &f],
        &["d.csv", "line 9", "column 'op'", "finite"],
    );
}

#[test]
fn too_few_samples_different_lengths_and_constant_command() {
    let dir = tmp();
    let f = write(dir.path(), "short.csv", &good_rows(6));
    fails(&["estimate", &f], &["short.csv", "6 rows", "at least 10"]);
    // mv stops early: the last rows have no mv, a gap at the end; the rows before are used
    let mut text = good_rows(20);
    for k in 20..25 {
        text.push_str(&format!("{k},1,\n"));
    }
    let f = write(dir.path(), "ragged.csv", &text);
    let out = stiction(&["estimate", &f, "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert_eq!(json(&String::from_utf8_lossy(&out.stdout))["samples"], 20);
    assert!(err.contains("5 cells treated as missing (mv 5"), "{err}");
    // gaps that leave no stretch long enough: refused in one sentence saying how long it must be
    let text = good_rows(20)
        .replacen("7,2,1", "7,,1", 1)
        .replacen("14,4,2", "14,Bad Input,2", 1);
    let f = write(dir.path(), "holes.csv", &text);
    fails(
        &["estimate", &f],
        &[
            "holes.csv",
            "no stretch of at least 10 samples",
            "2 cells treated as missing: op 2",
            "the longest stretch without gaps is 7 samples, line 2 to 8",
        ],
    );
    let mut text = String::from("t,op,mv\n");
    for k in 0..30 {
        text.push_str(&format!("{k},42,41\n"));
    }
    let f = write(dir.path(), "flat.csv", &text);
    fails(&["estimate", &f], &["flat.csv", "column 'op'", "constant"]);
}

#[test]
fn bad_bounds_and_names() {
    let dir = tmp();
    let f = write(dir.path(), "e.csv", &good_rows(30));
    fails(
        &["estimate", &f, "--lo=-1", "--hi", "5"],
        &["bounds for d", "negative"],
    );
    fails(
        &["estimate", &f, "--lo", "5", "--hi", "1"],
        &["bounds for d", "reversed"],
    );
    fails(
        &["estimate", &f, "--bounds", "x=0:1"],
        &["--bounds", "no parameter 'x'", "d"],
    );
    fails(
        &["estimate", &f, "--model", "dahl"],
        &["unknown model 'dahl'", "stenman, he, kano, choudhury"],
    );
    fails(
        &["estimate", &f, "--method", "pso"],
        &["unknown method 'pso'", "aco, aco-r, exact, grid"],
    );
    fails(
        &["estimate", &f, "--model", "kano", "--method", "exact"],
        &["exact", "Stenman model only"],
    );
    fails(
        &[
            "simulate", "--model", "kano", "--param", "S=2,d=1", "-o", "x.csv",
        ],
        &["unknown name 'd'", "S, J"],
    );
    fails(
        &[
            "simulate", "--model", "kano", "--param", "S=2", "-o", "x.csv",
        ],
        &["needs --param J"],
    );
    fails(
        &[
            "simulate",
            "--model",
            "he",
            "--param",
            "fs=1,fd=2",
            "-o",
            "x.csv",
        ],
        &["fd", "must not exceed"],
    );
    fails(
        &["simulate", "--param", "d=-1", "-o", "x.csv"],
        &["d = -1", ">= 0"],
    );
    fails(
        &[
            "simulate", "--param", "d=1", "--signal", "square", "-o", "x.csv",
        ],
        &["unknown signal 'square'"],
    );
    fails(
        &[
            "simulate",
            "--loop",
            "closed",
            "--param",
            "d=1",
            "--process",
            "foptd:tau=-3",
            "-o",
            "x.csv",
        ],
        &["tau", "> 0"],
    );
    fails(&["reproduce", "everything"], &["everything", "paper"]);
    // a method's settings: the core names the setting, the message the flag that sets it
    fails(
        &["estimate", &f, "--method", "aco", "--ants", "0"],
        &["--ants must be at least 1, got 0"],
    );
    fails(
        &["estimate", &f, "--method", "aco", "--rho", "1"],
        &["--rho must be between 0 and 1, exclusive, got 1"],
    );
    fails(
        &["estimate", &f, "--method", "aco-r", "--locality", "0"],
        &["--locality must be a finite number > 0, got 0"],
    );
    fails(
        &["estimate", &f, "--method", "grid", "--points", "1"],
        &["--points must be at least 2, got 1"],
    );
}

// ----------------------------------------------------------------------------- quantify

fn closed_loop(dir: &Path, d: &str) -> String {
    let p = dir.join("loop.csv");
    closed_stenman(&p, d, &["--noise", "0.02", "--seed", "4"]);
    p.to_str().unwrap().to_string()
}

#[test]
fn quantify_from_op_and_pv_json_and_plots() {
    let dir = tmp();
    let f = closed_loop(dir.path(), "1");
    let plots = dir.path().join("plots");
    let v = json(&ok(&[
        "quantify",
        &f,
        "--op",
        "op",
        "--pv",
        "pv",
        "--json",
        "--plot",
        plots.to_str().unwrap(),
    ]));
    assert_eq!(v["status"], "ok");
    // a search setting out of range is the flag's sentence, as in estimate (it was a panic)
    fails(
        &["quantify", &f, "--method", "aco", "--ants", "0"],
        &["--ants must be at least 1, got 0"],
    );
    for key in [
        "model",
        "method",
        "params",
        "interval",
        "linear_model",
        "fit",
        "apparent_stiction",
        "evaluations",
        "seconds",
    ] {
        assert!(v.get(key).is_some(), "no {key}");
    }
    for key in [
        "na",
        "nb",
        "nk",
        "a",
        "b",
        "gain",
        "time_constant",
        "dead_time",
    ] {
        assert!(
            v["linear_model"].get(key).is_some(),
            "no linear_model.{key}"
        );
    }
    assert!(v["fit"]["r2_simulation"].as_f64().unwrap() > 0.9);
    assert!(v["fit"]["r2_one_step"].is_number());
    let d = v["params"]["d"].as_f64().unwrap();
    assert!((d - 1.0).abs() < 0.1, "d = {d}");
    assert_eq!(v["linear_model"]["nk"], 11);
    assert!(v["caveat"]
        .as_str()
        .unwrap()
        .contains("without the valve position"));
    for stem in ["phase_plot", "trends"] {
        for ext in ["png", "svg"] {
            assert!(plots.join(format!("{stem}.{ext}")).exists(), "{stem}.{ext}");
        }
    }
    let human = ok(&["quantify", &f]);
    assert!(
        human.contains("apparent stiction") && human.contains("without the valve position"),
        "{human}"
    );
    assert!(human.contains("delay 11 samples"), "{human}");
    assert!(
        human.contains("valve at the first sample") && human.contains("--estimate-start"),
        "{human}"
    );
    let v = json(&ok(&["quantify", &f, "--estimate-start", "--json"]));
    assert_eq!(v["valve_start_kind"], "estimated", "{v:#}");
    assert!(v["valve_start"].as_f64().is_some());
}

#[test]
fn quantify_two_parameter_model() {
    let dir = tmp();
    let f = closed_loop(dir.path(), "2");
    let v = json(&ok(&[
        "quantify",
        &f,
        "--model",
        "kano",
        "--method",
        "aco-r",
        "--iterations",
        "20",
        "--seed",
        "3",
        "--json",
    ]));
    assert_eq!(v["method"], "aco-r");
    assert!(v["params"]["S"].is_number() && v["params"]["J"].is_number());
    assert_eq!(v["seed"], 3);
}

#[test]
fn quantify_bad_input_and_insufficient_data() {
    let dir = tmp();
    let f = closed_loop(dir.path(), "1");
    fails(
        &["quantify", &f, "--pv", "level"],
        &["loop.csv", "'level'", "--pv"],
    );
    fails(
        &["quantify", &f, "--model", "kano", "--method", "exact"],
        &["exact", "Stenman model only"],
    );
    fails(&["quantify", &f, "--ts", "0"], &["--ts", "positive"]);
    // too short: a clear error in words, a status in JSON
    let short: String = std::fs::read_to_string(&f)
        .unwrap()
        .lines()
        .take(40)
        .collect::<Vec<_>>()
        .join("\n");
    let s = write(dir.path(), "short.csv", &short);
    fails(
        &["quantify", &s],
        &["short.csv", "insufficient data", "samples"],
    );
    let v = json(&ok(&["quantify", &s, "--json"]));
    assert_eq!(v["status"], "insufficient_data");
    assert!(v["reason"].as_str().unwrap().contains("samples"));
    // a constant PV
    let mut text = String::from("t,op,pv\n");
    for k in 0..500 {
        text.push_str(&format!("{k},{},20\n", 50.0 + (k as f64 * 0.1).sin()));
    }
    let c = write(dir.path(), "flat.csv", &text);
    fails(&["quantify", &c], &["flat.csv", "PV is constant"]);
    // OP saturated the whole time
    let mut text = String::from("t,op,pv\n");
    for k in 0..500 {
        text.push_str(&format!("{k},100,{}\n", 20.0 + (k as f64 * 0.1).sin()));
    }
    let c = write(dir.path(), "sat.csv", &text);
    let v = json(&ok(&["quantify", &c, "--json"]));
    assert_eq!(v["status"], "insufficient_data");
    // OP in raw units, never inside 0-100 %: said, with the way out
    let mut text = String::from("t,op,pv\n");
    for k in 0..500 {
        let u = (k as f64 * 0.1).sin();
        text.push_str(&format!("{k},{},{}\n", 3000.0 + 500.0 * u, 20.0 + u));
    }
    let c = write(dir.path(), "raw.csv", &text);
    fails(
        &["quantify", &c],
        &["raw.csv", "other units than %", "rescale"],
    );
}

#[test]
fn estimate_on_a_valve_that_never_moved_says_so() {
    let dir = tmp();
    let mut text = String::from("t,op,mv\n");
    for k in 0..400 {
        text.push_str(&format!("{k},{},50\n", 50.0 + (k as f64 / 10.0).sin()));
    }
    let f = write(dir.path(), "stuck.csv", &text);
    let o = ok(&["estimate", &f]);
    assert!(o.contains("MV does not vary"), "{o}");
    assert!(!o.contains("NaN"), "{o}");
    assert!(o.contains("wide relative to d"), "{o}");
}

#[test]
fn quantify_keeps_the_first_row_of_a_repeated_time() {
    // an export that writes every time twice (two historian tags joined on time): the signals
    // have half the table's rows, and the fit's stretch must be counted in samples, not rows
    let dir = tmp();
    let f = closed_loop(dir.path(), "1");
    let text = std::fs::read_to_string(&f).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for line in lines.take(700) {
        out.push_str(&format!("{line}\n{line}\n"));
    }
    let d = write(dir.path(), "twice.csv", &out);
    let o = ok(&["quantify", &d]);
    assert!(o.contains("repeat an earlier row's time"), "{o}");
    let v = json(&ok(&["quantify", &d, "--json"]));
    assert_eq!(v["status"], "ok", "{v:#}");
    assert_eq!(v["samples"], 700, "{v:#}");
}

#[test]
fn quantify_reads_historian_timestamps() {
    let dir = tmp();
    let f = closed_loop(dir.path(), "1");
    // the same loop exported with text timestamps every 2 s, semicolon separated
    let text = std::fs::read_to_string(&f).unwrap();
    let mut out = String::from("Timestamp;OP;PV\n");
    for (k, line) in text.lines().skip(1).enumerate() {
        let c: Vec<&str> = line.split(',').collect();
        let secs = 2 * k;
        out.push_str(&format!(
            "2024-03-01 {:02}:{:02}:{:02};{};{}\n",
            10 + secs / 3600,
            (secs / 60) % 60,
            secs % 60,
            c[2],
            c[4]
        ));
    }
    let h = write(dir.path(), "historian.csv", &out);
    let v = json(&ok(&["quantify", &h, "--json"]));
    assert_eq!(v["ts"], 2.0);
    assert_eq!(v["status"], "ok");
    let bad = write(
        dir.path(),
        "badtime.csv",
        &out.replacen("2024-03-01 10:00:04", "soon", 1),
    );
    fails(
        &["quantify", &bad],
        &[
            "badtime.csv",
            "line 4",
            "'Timestamp'",
            "'soon'",
            "date and time",
        ],
    );
}
