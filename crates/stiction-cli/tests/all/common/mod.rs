//! What every CLI test does: spawn the binary as a user would and read what it says.
#![allow(dead_code)] // each test file uses some of these

use std::path::Path;
use std::process::{Command, Output};

pub fn stiction(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stiction"))
        .args(args)
        .output()
        .expect("the binary runs")
}

/// Runs a command that must succeed; its standard output.
pub fn ok(args: &[&str]) -> String {
    let out = stiction(args);
    assert!(
        out.status.success(),
        "{args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Runs a command that must fail with one clear line on stderr containing every `needles`.
pub fn fails(args: &[&str], needles: &[&str]) {
    let out = stiction(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} should fail");
    assert!(!err.contains("panicked"), "{args:?} panicked: {err}");
    assert_eq!(
        err.trim().lines().count(),
        1,
        "{args:?}: not one line: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{args:?}: '{n}' missing from: {err}");
    }
}

pub fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).expect("valid JSON")
}

/// `stiction simulate` of a closed loop of 1500 samples with a Stenman valve of band `d` (0: a
/// healthy valve) into `path`; `extra` adds or overrides options (noise, seed, process).
pub fn closed_stenman(path: &Path, d: &str, extra: &[&str]) {
    let param = format!("d={d}");
    let mut args = vec![
        "simulate",
        "--loop",
        "closed",
        "--model",
        "stenman",
        "--param",
        &param,
        "-o",
        path.to_str().unwrap(),
    ];
    if !extra.contains(&"--samples") {
        args.extend_from_slice(&["--samples", "1500"]);
    }
    args.extend_from_slice(extra);
    ok(&args);
}
