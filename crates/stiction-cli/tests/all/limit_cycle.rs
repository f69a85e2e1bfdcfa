//! The loop family through the binary (issue 14): a fast loop written by `stiction simulate`,
//! judged by `stiction diagnose` as a user would.

use crate::common;
use common::{json, ok};

/// A fast loop sampled every 2 s (K = 1, τ = 12 s, dead time 30 s; PI 1.3 / 1500 s) with a
/// Stenman band of `d` %, or a healthy valve and an external sinusoid of period 120 s.
fn fast_loop(dir: &std::path::Path, d: &str, disturbance: Option<&str>) -> String {
    let p = dir.join(format!("fast_{d}.csv"));
    let param = format!("d={d}");
    let mut args = vec![
        "simulate",
        "--loop",
        "closed",
        "--model",
        "stenman",
        "--param",
        &param,
        "--process",
        "foptd:K=1,tau=12,delay=30",
        "--pi",
        "Kc=1.3,Ti=1500",
        "--ts",
        "2",
        "--samples",
        "2000",
        "--noise",
        "0.05",
        "--seed",
        "3",
        "--op0",
        "41.5",
        "-o",
        p.to_str().unwrap(),
    ];
    if let Some(w) = disturbance {
        args.extend(["--disturbance", w]);
    }
    ok(&args);
    p.to_str().unwrap().to_string()
}

fn loop_family(v: &serde_json::Value) -> &serde_json::Value {
    v["families"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["family"] == "loop")
        .expect("the loop family is reported")
}

#[test]
fn a_fast_sticky_loops_cycle_is_measured_and_the_loop_family_sizes_its_band() {
    let dir = tempfile::tempdir().unwrap();
    let f = fast_loop(dir.path(), "2", None);
    let v = json(&ok(&[
        "diagnose",
        &f,
        "--sp",
        "sp",
        "--no-quantify",
        "--json",
    ]));
    // (a near-sinusoidal limit cycle gives no sticks and fits alike with and without a band: the
    // verdict's model may leave it undetermined; the lab's verdict tables show the trade)
    assert_ne!(v["verdict"], "insufficient_data", "{v:#}");
    // the family measures the cycle the linear loop cannot sustain (the verdict's model does not
    // read its lag: on the real records it calls a healthy level loop sticky)
    let lf = loop_family(&v);
    assert!(lf["vote"].as_str().is_some(), "{lf:#}");
    let e = &lf["limit_cycle"];
    assert!(e["margins"]["gain_margin"].as_f64().unwrap() > 1.0, "{e:#}");
    let band = e["describing"]["band_percent_of_span"].as_f64().unwrap();
    assert!(
        (1.5..2.6).contains(&band),
        "describing-function band {band}"
    );
    assert!(e["controller"]["action"] == "reverse" && e["setpoint_recorded"] == true);
    // the human printer names the family and the band beside the verdict's
    let text = ok(&["diagnose", &f, "--sp", "sp", "--no-quantify"]);
    assert!(text.contains("linear loop"), "{text}");
    assert!(text.contains("describing function"), "{text}");
}

#[test]
fn without_a_setpoint_the_loop_family_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let f = fast_loop(dir.path(), "2", None);
    let v = json(&ok(&["diagnose", &f, "--no-quantify", "--json"]));
    let e = &loop_family(&v)["limit_cycle"];
    assert_eq!(e["setpoint_recorded"], false, "{e:#}");
    assert!(e["caveat"].as_str().unwrap().contains("cascade"), "{e:#}");
}

#[test]
fn an_external_sinusoid_through_a_healthy_valve_is_not_stiction() {
    let dir = tempfile::tempdir().unwrap();
    let f = fast_loop(dir.path(), "0", Some("sine:amplitude=1,period=120"));
    let v = json(&ok(&[
        "diagnose",
        &f,
        "--sp",
        "sp",
        "--no-quantify",
        "--json",
    ]));
    assert_ne!(v["verdict"], "stiction", "{v:#}");
    assert_ne!(loop_family(&v)["vote"], "stiction");
}
