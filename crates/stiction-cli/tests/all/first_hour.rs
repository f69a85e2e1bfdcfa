//! A new user's first hour: exit codes a script can gate on, conflicting flags refused, the
//! warnings that stop a wrong conclusion (an unstable simulated loop, a fit worse than the mean),
//! R² with and without stiction, completions and a manual page, and wording without plurals
//! such as "1 gaps" or times such as 0.20000000000004547.

use crate::common;
use common::{closed_stenman, fails, json, ok, stiction};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn fail_on_stiction_exits_4_after_printing_the_verdict() {
    let dir = tempfile::tempdir().unwrap();
    let sticky = dir.path().join("sticky.csv");
    closed_stenman(&sticky, "3", &[]);
    let healthy = dir.path().join("healthy.csv");
    closed_stenman(&healthy, "0", &["--noise", "0.05"]);
    let out = stiction(&[
        "diagnose",
        s(&sticky),
        "--sp",
        "sp",
        "--fail-on",
        "stiction",
    ]);
    assert_eq!(out.status.code(), Some(4));
    assert!(String::from_utf8_lossy(&out.stdout).contains("STICTION"));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--fail-on stiction"));
    // without the flag, the same verdict is a success
    let out = stiction(&["diagnose", s(&sticky), "--sp", "sp", "--no-quantify"]);
    assert_eq!(out.status.code(), Some(0));
    let out = stiction(&[
        "diagnose",
        s(&healthy),
        "--sp",
        "sp",
        "--fail-on",
        "stiction",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    // the report is written before the exit code says stiction
    let html = dir.path().join("r.html");
    let out = stiction(&[
        "report",
        s(&sticky),
        "--sp",
        "sp",
        "--no-quantify",
        "-o",
        s(&html),
        "--fail-on",
        "stiction",
    ]);
    assert_eq!(out.status.code(), Some(4));
    assert!(html.exists());
}

#[test]
fn exit_codes_bad_input_is_2_and_documented() {
    let out = stiction(&["diagnose", "/no/such/file.csv"]);
    assert_eq!(out.status.code(), Some(2));
    let out = stiction(&["diagnose", "--no-such-flag"]);
    assert_eq!(out.status.code(), Some(2));
    let help = ok(&["--help"]);
    for code in [
        "0  ok",
        "1  internal error",
        "2  bad input",
        "3  batch",
        "4  --fail-on stiction",
    ] {
        assert!(help.contains(code), "{code}: {help}");
    }
    assert!(ok(&["diagnose", "--help"]).contains("--fail-on <VERDICT>"));
}

/// A flag pair clap refuses: exit 2, both flags named.
fn conflict(args: &[&str], a: &str, b: &str) {
    let out = stiction(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains("cannot be used with") && err.contains(a) && err.contains(b),
        "{err}"
    );
}

#[test]
fn conflicting_flags_are_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("loop.csv");
    closed_stenman(&f, "2", &[]);
    conflict(
        &["quantify", s(&f), "--quick", "--full"],
        "--quick",
        "--full",
    );
    conflict(
        &["quantify", s(&f), "--integrating", "--self-regulating"],
        "--integrating",
        "--self-regulating",
    );
    conflict(
        &["diagnose", s(&f), "--no-quantify", "--estimate-start"],
        "--no-quantify",
        "--estimate-start",
    );
    let html = dir.path().join("r.html");
    conflict(
        &[
            "report",
            s(&f),
            "-o",
            s(&html),
            "--no-quantify",
            "--estimate-start",
        ],
        "--no-quantify",
        "--estimate-start",
    );
    // open- and closed-loop settings given for the other kind of loop
    let out = dir.path().join("x.csv");
    fails(
        &["simulate", "--param", "d=1", "--pi", "Kc=1", "-o", s(&out)],
        &["--pi applies to a closed loop", "--loop closed"],
    );
    fails(
        &[
            "simulate",
            "--loop",
            "closed",
            "--param",
            "d=1",
            "--signal",
            "const",
            "-o",
            s(&out),
        ],
        &["--signal drives an open loop"],
    );
    assert!(!out.exists());
}

#[test]
fn simulate_warns_about_an_unstable_or_saturated_loop() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("wild.csv");
    let out = stiction(&[
        "simulate",
        "--loop",
        "closed",
        "--param",
        "d=0.5",
        "--pi",
        "Kc=5,Ti=1",
        "-o",
        s(&f),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{err}");
    assert!(f.exists());
    assert!(
        err.contains("warning: ") && err.contains("unstable") && err.contains("--pi"),
        "{err}"
    );
    let f = dir.path().join("pinned.csv");
    let out = stiction(&[
        "simulate",
        "--loop",
        "closed",
        "--param",
        "d=0.5",
        "--sp",
        "step:from=50,to=80,at=10",
        "--process",
        "foptd:K=0.5,tau=10,delay=2",
        "-o",
        s(&f),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("OP sits at 100 %") && err.contains("cannot reach its setpoint"),
        "{err}"
    );
    // the default loop is healthy: no warning
    let f = dir.path().join("fine.csv");
    let out = stiction(&[
        "simulate",
        "--loop",
        "closed",
        "--param",
        "d=0.5",
        "-o",
        s(&f),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("warning"), "{err}");
}

#[test]
fn estimate_warns_when_mv_does_not_look_like_the_valve() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("open.csv");
    ok(&["simulate", "--param", "d=0.5", "-o", s(&f)]);
    // MV in another scale: 5 % off
    let text = std::fs::read_to_string(&f).unwrap();
    let mut out = String::from("t,op,mv\n");
    for l in text.lines().skip(1) {
        let c: Vec<f64> = l
            .split(',')
            .filter(|x| !x.is_empty())
            .map(|x| x.parse().unwrap())
            .collect();
        out.push_str(&format!("{},{},{}\n", c[0], c[1], c[2] + 5.0));
    }
    let g = dir.path().join("shifted.csv");
    std::fs::write(&g, out).unwrap();
    let text = ok(&["estimate", s(&g)]);
    assert!(
        text.contains("warning: the fit is worse than MV's mean")
            && text.contains("is MV really the valve position"),
        "{text}"
    );
    assert!(!ok(&["estimate", s(&f)]).contains("worse than MV's mean"));
    let out = stiction(&["estimate", s(&g), "--json"]);
    json(&String::from_utf8_lossy(&out.stdout));
    assert!(String::from_utf8_lossy(&out.stderr).contains("is MV really the valve position"));
}

#[test]
fn quantify_prints_r2_with_and_without_stiction() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("loop.csv");
    closed_stenman(&f, "3", &[]);
    let text = ok(&["quantify", s(&f)]);
    let v = json(&ok(&["quantify", s(&f), "--json"]));
    let with = v["fit"]["r2_simulation"].as_f64().unwrap();
    let without = v["fit"]["r2_simulation_without_stiction"].as_f64().unwrap();
    let line = format!("R² in simulation with stiction {with:.4}, without stiction {without:.4}");
    assert!(text.contains(&line), "{line}\n{text}");
    assert!(with > without + 0.3, "{with} {without}");
}

#[test]
fn wording_counts_and_rounded_sampling_times() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("loop.csv");
    closed_stenman(&f, "3", &[]);
    // the same loop on a 0.2 s time axis written as floats (0.6000000000000001 and the like)
    let text = std::fs::read_to_string(&f).unwrap();
    let mut out = String::from("t,op,pv\n");
    for (k, l) in text.lines().skip(1).enumerate() {
        let c: Vec<&str> = l.split(',').collect();
        out.push_str(&format!("{},{},{}\n", k as f64 * 0.2, c[2], c[4]));
    }
    let g = dir.path().join("fast.csv");
    std::fs::write(&g, out).unwrap();
    let text = ok(&["diagnose", s(&g), "--no-quantify"]);
    assert!(text.contains("1500 samples at 0.2 s"), "{text}");
    let text = ok(&["quantify", s(&g)]);
    assert!(text.contains("1500 samples at 0.2 s"), "{text}");
    let v = json(&ok(&["quantify", s(&g), "--json"]));
    assert_eq!(v["ts"], 0.2);
    for t in [
        ok(&["diagnose", s(&g)]),
        ok(&["quantify", s(&g)]),
        ok(&["estimate", s(&f)]),
    ] {
        for bad in [
            " 1 samples",
            " 1 gaps",
            " 1 evaluations",
            " 1 cells",
            " 1 half periods",
            "..=",
            "Some(",
        ] {
            assert!(!t.contains(bad), "'{bad}' in {t}");
        }
    }
}

#[test]
fn completions_and_manual_pages() {
    for shell in ["bash", "zsh", "fish"] {
        let text = ok(&["completions", shell]);
        assert!(
            text.contains("stiction") && text.contains("fail-on"),
            "{shell}"
        );
    }
    let page = ok(&["man"]);
    assert!(
        page.contains(".TH stiction") && page.contains("diagnose"),
        "{page}"
    );
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("man");
    let r = stiction(&["man", "--out", s(&out)]);
    assert!(r.status.success());
    let diagnose = std::fs::read_to_string(out.join("stiction-diagnose.1")).unwrap();
    assert!(
        diagnose.contains(r"\-\-time\-format") && diagnose.contains(r"\-\-tz"),
        "{diagnose}"
    );
    assert!(diagnose.contains(env!("CARGO_PKG_VERSION")), "{diagnose}");
}

/// The README's quick start: the shipped example loops are what their commands write, and
/// diagnose tells them apart.
#[test]
fn the_quick_start_examples_are_reproducible_and_tell_apart() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/data");
    let dir = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str], &str); 2] = [
        ("sticky_loop.csv", &["--param", "d=2"], "STICTION"),
        (
            "healthy_loop.csv",
            &[
                "--param",
                "d=0",
                "--disturbance",
                "sine:amplitude=0.5,period=80",
            ],
            "no stiction",
        ),
    ];
    for (name, extra, verdict) in cases {
        let again = dir.path().join(name);
        let mut args = vec![
            "simulate",
            "--loop",
            "closed",
            "--model",
            "stenman",
            "--noise",
            "0.05",
            "--seed",
            "3",
            "--samples",
            "1500",
            "-o",
            s(&again),
        ];
        args.extend_from_slice(extra);
        ok(&args);
        let shipped = data.join(name);
        assert_eq!(
            std::fs::read(&again).unwrap(),
            std::fs::read(&shipped).unwrap(),
            "{name} is not what its command in examples/data/README.md writes"
        );
        let text = ok(&["diagnose", s(&shipped), "--sp", "sp"]);
        assert!(
            text.starts_with(&format!("{}: {verdict}", shipped.display())),
            "{text}"
        );
    }
}
