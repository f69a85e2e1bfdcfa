//! `--thorough`: the model family's levels test and the hidden-valve family, as a user asks for
//! them.

use crate::common;
use common::{closed_stenman, json, ok};

fn family<'a>(v: &'a serde_json::Value, name: &str) -> Option<&'a serde_json::Value> {
    v["families"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["family"] == name)
}

fn model(v: &serde_json::Value) -> &serde_json::Value {
    family(v, "model").unwrap()
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
fn the_levels_test_finds_the_band_of_a_sticky_valve_and_nothing_in_a_healthy_one() {
    let dir = tempfile::tempdir().unwrap();
    let sticky = dir.path().join("sticky.csv");
    closed_stenman(&sticky, "2", &STEPS);
    let s = sticky.to_str().unwrap();
    let v = json(&ok(&["diagnose", s, "--sp", "sp", "--thorough", "--json"]));
    let m = model(&v);
    let levels = &m["model"]["levels"];
    let ratio = levels["ratio"].as_f64().unwrap();
    let band = levels["band_percent_of_span"].as_f64().unwrap();
    assert!(ratio >= levels["threshold"].as_f64().unwrap(), "{m:#}");
    assert!((band - 2.0).abs() < 0.5, "{m:#}");
    // a smaller band than the valve family counts would not vote (0.2 % of span)
    assert_eq!(
        levels["min_band_percent_of_span"].as_f64(),
        Some(0.2),
        "{m:#}"
    );
    assert!(levels["trajectories"].as_u64().unwrap() > 10, "{m:#}");
    assert_eq!(m["vote"], "stiction", "{m:#}");
    assert!(m["note"].as_str().unwrap().contains("levels test"), "{m:#}");
    assert_eq!(v["verdict"], "stiction");
    // decided already: the hidden valve, which costs seconds, is not run
    let hidden = family(&v, "hidden_valve").unwrap();
    assert!(
        hidden["note"].as_str().unwrap().starts_with("not run"),
        "{hidden:#}"
    );
    // the human output names the test
    let text = ok(&["diagnose", s, "--sp", "sp", "--thorough", "--no-quantify"]);
    assert!(text.contains("levels test"), "{text}");
    // without the flag the test is not run
    let plain = json(&ok(&["diagnose", s, "--sp", "sp", "--json"]));
    assert!(model(&plain)["model"].get("levels").is_none());
    assert!(family(&plain, "hidden_valve").is_none());

    let healthy = dir.path().join("healthy.csv");
    closed_stenman(&healthy, "0", &STEPS);
    let h = healthy.to_str().unwrap();
    let v = json(&ok(&["diagnose", h, "--sp", "sp", "--thorough", "--json"]));
    let m = model(&v);
    let levels = &m["model"]["levels"];
    assert!(
        levels["ratio"].as_f64().unwrap() < levels["threshold"].as_f64().unwrap(),
        "{m:#}"
    );
    assert_eq!(v["verdict"], "no_stiction", "{v:#}");
    // no limit cycle: the hidden valve is calibrated on limit cycles and says why it is silent
    let hidden = family(&v, "hidden_valve").unwrap();
    assert_eq!(hidden["vote"], "undetermined", "{hidden:#}");
    assert!(
        hidden["note"]
            .as_str()
            .unwrap()
            .contains("does not oscillate"),
        "{hidden:#}"
    );
    assert!(
        hidden["threshold"].as_str().unwrap().contains("75"),
        "{hidden:#}"
    );
}
