//! `--thorough`: the hidden-valve family, as a user asks for it: it reports beside the verdict,
//! which does not read it.

use crate::common;
use common::{closed_stenman, json, ok};

fn family<'a>(v: &'a serde_json::Value, name: &str) -> Option<&'a serde_json::Value> {
    v["families"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["family"] == name)
}

/// Setpoint steps in a loop tuned calmly: the valve sticks between steps (no limit cycle).
const STEPS: [&str; 8] = [
    "--noise",
    "0.05",
    "--seed",
    "3",
    "--sp",
    "steps:amplitude=4,hold=200,offset=50,seed=2",
    "--pi",
    "Kc=0.3,Ti=20",
];

#[test]
fn the_hidden_valve_reports_beside_the_verdict_only_when_asked() {
    let dir = tempfile::tempdir().unwrap();
    let sticky = dir.path().join("sticky.csv");
    closed_stenman(&sticky, "2", &STEPS);
    let s = sticky.to_str().unwrap();
    let v = json(&ok(&["diagnose", s, "--sp", "sp", "--thorough", "--json"]));
    let hidden = family(&v, "hidden_valve").unwrap();
    // the model does not read it: no share of the log-odds, and the verdict is the same
    assert!(hidden.get("contribution").is_none(), "{hidden:#}");
    assert!(!hidden["note"].as_str().unwrap().is_empty(), "{hidden:#}");
    assert!(
        hidden["threshold"].as_str().unwrap().contains("75"),
        "{hidden:#}"
    );
    let plain = json(&ok(&["diagnose", s, "--sp", "sp", "--json"]));
    assert!(family(&plain, "hidden_valve").is_none());
    assert_eq!(plain["verdict"], v["verdict"]);
    assert_eq!(plain["probability"], v["probability"]);
    // the human output names the family under its details
    let text = ok(&["diagnose", s, "--sp", "sp", "--thorough", "--no-quantify"]);
    assert!(
        text.lines()
            .any(|l| l.trim_start().starts_with("hidden valve")),
        "{text}"
    );

    // no limit cycle: the hidden valve is calibrated on limit cycles and says why it is silent
    let healthy = dir.path().join("healthy.csv");
    closed_stenman(&healthy, "0", &STEPS);
    let h = healthy.to_str().unwrap();
    let v = json(&ok(&["diagnose", h, "--sp", "sp", "--thorough", "--json"]));
    let hidden = family(&v, "hidden_valve").unwrap();
    assert_eq!(hidden["vote"], "undetermined", "{hidden:#}");
    assert!(
        hidden["note"]
            .as_str()
            .unwrap()
            .contains("does not oscillate"),
        "{hidden:#}"
    );
}
