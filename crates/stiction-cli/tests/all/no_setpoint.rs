//! A record exported without its setpoint: where the setpoint stepped, the steps are read off OP
//! and PV (OP stepped while PV was still, then PV settled at a new level) and the warning says so;
//! where it held, the error stays PV's deviation from its mean.

use crate::common::{closed_stenman, json, ok};

#[test]
fn setpoint_steps_are_read_off_a_record_without_sp() {
    let dir = tempfile::tempdir().unwrap();
    let steps_csv = dir.path().join("steps.csv");
    closed_stenman(
        &steps_csv,
        "0",
        &[
            "--noise",
            "0.05",
            "--seed",
            "3",
            "--sp",
            "steps:amplitude=2,hold=300,offset=50,seed=1",
        ],
    );
    // judged without --sp, as an export without the setpoint column is
    let v = json(&ok(&["diagnose", steps_csv.to_str().unwrap(), "--json"]));
    // the verdict is the model's, not what this test is about (a healthy valve here: the lead's
    // model work checks its verdict); the diagnosis is judged and says why
    assert_ne!(v["verdict"], "insufficient_data", "{v:#}");
    assert!(
        !v["reasons"][0]["text"].as_str().unwrap().is_empty(),
        "{v:#}"
    );
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("setpoint steps read off the record"),
        "{warnings}"
    );
    // the steps, where the setpoint stepped (every 300 s at 1 s a sample), and the levels between
    let steps = v["setpoint_read_off"]["steps"].as_array().unwrap();
    assert!(!steps.is_empty(), "{v:#}");
    for s in steps {
        let k = s.as_u64().unwrap();
        assert!(k % 300 <= 2, "a step read at sample {k}");
    }
    assert_eq!(
        v["setpoint_read_off"]["levels"].as_array().unwrap().len(),
        steps.len() + 1
    );
    // the human output lists them
    let text = ok(&["diagnose", steps_csv.to_str().unwrap()]);
    assert!(
        text.contains("setpoint read off OP and PV (no setpoint column): "),
        "{text}"
    );
    assert!(text.contains(", then "), "{text}");
    // and the report draws them where SP would be
    let page = dir.path().join("steps.html");
    ok(&[
        "report",
        steps_csv.to_str().unwrap(),
        "-o",
        page.to_str().unwrap(),
    ]);
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("SP read off OP and PV"));
    // the same loop at a steady setpoint: nothing to read off
    let steady = dir.path().join("steady.csv");
    closed_stenman(
        &steady,
        "0",
        &["--noise", "0.05", "--seed", "3", "--sp", "const:value=50"],
    );
    let v = json(&ok(&["diagnose", steady.to_str().unwrap(), "--json"]));
    let warnings = v["warnings"].to_string();
    assert!(warnings.contains("deviation from its mean"), "{warnings}");
    assert!(!warnings.contains("read off"), "{warnings}");
    assert!(v.get("setpoint_read_off").is_none(), "{v:#}");
}
