//! A record whose PV the historian stored only when it moved (deadband compression, the last
//! stored value held between): the verdict never reads compression as stiction, and its next
//! step says that compression hides a sticky valve's sticks.

use crate::common::{closed_stenman, json, ok};

#[test]
fn a_mostly_unrecorded_pv_says_compression_hides_sticks() {
    let dir = tempfile::tempdir().unwrap();
    let whole = dir.path().join("whole.csv");
    closed_stenman(&whole, "0", &["--noise", "0.05", "--seed", "3"]);
    let text = std::fs::read_to_string(&whole).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let pv_col = header.split(',').position(|h| h == "pv").unwrap();
    // deadband storage: a new value only when PV leaves 0.08 of the last stored one
    let mut stored: Option<f64> = None;
    let mut out = vec![header.to_string()];
    for line in lines {
        let mut cells: Vec<String> = line.split(',').map(str::to_string).collect();
        let pv: f64 = cells[pv_col].parse().unwrap();
        let held = match stored {
            Some(s) if (pv - s).abs() <= 0.08 => s,
            _ => pv,
        };
        stored = Some(held);
        cells[pv_col] = held.to_string();
        out.push(cells.join(","));
    }
    let squeezed = dir.path().join("compressed.csv");
    std::fs::write(&squeezed, out.join("\n") + "\n").unwrap();
    let f = squeezed.to_str().unwrap();
    let v = json(&ok(&["diagnose", f, "--sp", "sp", "--json"]));
    assert_ne!(v["verdict"], "stiction", "{v:#}");
    let step = v["next_step"]["text"].as_str().unwrap();
    assert!(step.contains("PV is not recorded in"), "{step}");
    assert!(step.contains("without compression"), "{step}");
    assert!(
        v["next_step"]["pv_not_recorded"].as_f64().is_some(),
        "{v:#}"
    );
    // the record stored whole says nothing of compression
    let v = json(&ok(&[
        "diagnose",
        whole.to_str().unwrap(),
        "--sp",
        "sp",
        "--json",
    ]));
    let step = v["next_step"]["text"].as_str().unwrap();
    assert!(!step.contains("compression"), "{step}");
}
