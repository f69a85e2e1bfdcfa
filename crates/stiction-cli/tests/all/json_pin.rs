//! The `--json` outputs of `diagnose`, `quantify` and `estimate` on fixed inputs, pinned against
//! committed files under `tests/pins/`: a refactor that changes a key, a word or a number shows up
//! here. Timings (`seconds`) are left out; numbers compare to 1e-9 relative, words and keys exactly.
//!
//! After a deliberate change of an answer, rewrite the pins with
//! `STICTION_BLESS=1 cargo test -p stiction-cli --test all json_pin` and say why in the commit.

use std::path::{Path, PathBuf};

use crate::common;
use common::{json, ok};
use serde_json::Value;

fn pin_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/pins")
        .join(format!("{name}.json"))
}

/// Drops the keys whose values are timings of this run.
fn without_timings(v: &mut Value) {
    match v {
        Value::Object(map) => {
            map.remove("seconds");
            map.values_mut().for_each(without_timings);
        }
        Value::Array(items) => items.iter_mut().for_each(without_timings),
        _ => {}
    }
}

/// The first difference between `got` and `want`, with its JSON path.
fn difference(path: &str, got: &Value, want: &Value) -> Option<String> {
    match (got, want) {
        (Value::Number(g), Value::Number(w)) => {
            let (g, w) = (g.as_f64().unwrap(), w.as_f64().unwrap());
            let close = (g - w).abs() <= 1e-9 * g.abs().max(w.abs()).max(1e-300);
            (!close).then(|| format!("{path}: {g} here, {w} pinned"))
        }
        (Value::Object(g), Value::Object(w)) => {
            let (gk, wk): (Vec<_>, Vec<_>) = (g.keys().collect(), w.keys().collect());
            if gk != wk {
                return Some(format!("{path}: keys {gk:?} here, {wk:?} pinned"));
            }
            g.iter()
                .find_map(|(k, gv)| difference(&format!("{path}.{k}"), gv, &w[k]))
        }
        (Value::Array(g), Value::Array(w)) => {
            if g.len() != w.len() {
                return Some(format!(
                    "{path}: {} items here, {} pinned",
                    g.len(),
                    w.len()
                ));
            }
            g.iter()
                .zip(w)
                .enumerate()
                .find_map(|(i, (gv, wv))| difference(&format!("{path}[{i}]"), gv, wv))
        }
        _ => (got != want).then(|| format!("{path}: {got} here, {want} pinned")),
    }
}

/// Compares the command's JSON with its pin, or writes the pin under `STICTION_BLESS=1`.
fn check(name: &str, args: &[&str]) {
    let mut got = json(&ok(args));
    without_timings(&mut got);
    let path = pin_path(name);
    if std::env::var_os("STICTION_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        let text = serde_json::to_string_pretty(&got).unwrap() + "\n";
        std::fs::write(&path, text).unwrap();
        return;
    }
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e}; write it with STICTION_BLESS=1", path.display()));
    let want: Value = serde_json::from_str(&text).unwrap();
    if let Some(d) = difference(name, &got, &want) {
        panic!("the --json output of `{}` changed: {d}", args.join(" "));
    }
}

fn simulate(dir: &Path, name: &str, args: &[&str]) -> String {
    let path = dir.join(name).to_str().unwrap().to_string();
    let mut all = vec!["simulate"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--seed", "7", "-o", &path]);
    ok(&all);
    path
}

#[test]
fn estimate_json_is_pinned() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulate(dir.path(), "open.csv", &["--param", "d=0.5"]);
    check(
        "estimate_exact",
        &["estimate", &file, "--op", "op", "--mv", "mv", "--json"],
    );
    check(
        "estimate_kano",
        &[
            "estimate", &file, "--op", "op", "--mv", "mv", "--model", "kano", "--method", "aco-r",
            "--seed", "3", "--json",
        ],
    );
}

#[test]
fn quantify_and_diagnose_json_are_pinned() {
    let dir = tempfile::tempdir().unwrap();
    let file = simulate(
        dir.path(),
        "closed.csv",
        &[
            "--loop",
            "closed",
            "--param",
            "d=2",
            "--samples",
            "1200",
            "--noise",
            "0.05",
        ],
    );
    check("quantify", &["quantify", &file, "--json"]);
    check("diagnose", &["diagnose", &file, "--sp", "sp", "--json"]);
}
