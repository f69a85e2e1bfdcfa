//! Diagnose a loop from a CSV file in Rust, as `stiction diagnose FILE --sp sp` does.
//!
//!     cargo run --release -p stiction-core --example diagnose_csv -- [FILE]
//!
//! FILE has a header line and the columns `op`, `pv` and `sp` (default: the repository's
//! `examples/data/sticky_loop.csv`, sampled every second).

use std::error::Error;
use stiction_core::diagnose::{diagnose, DiagnoseRequest, LoopRecord};

/// The columns `names` of a comma-separated file with a header line.
fn read_columns(path: &str, names: &[&str]) -> Result<Vec<Vec<f64>>, Box<dyn Error>> {
    let text = std::fs::read_to_string(path)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().ok_or("empty file")?.split(',').collect();
    let index = names
        .iter()
        .map(|n| {
            header
                .iter()
                .position(|h| h.trim() == *n)
                .ok_or(format!("no column {n}"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut columns = vec![Vec::new(); names.len()];
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let cells: Vec<&str> = line.split(',').collect();
        for (column, &i) in columns.iter_mut().zip(&index) {
            column.push(cells.get(i).ok_or("short row")?.trim().parse()?);
        }
    }
    Ok(columns)
}

fn main() -> Result<(), Box<dyn Error>> {
    let default = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/data/sticky_loop.csv"
    );
    let path = std::env::args()
        .nth(1)
        .unwrap_or_else(|| default.to_string());
    let [op, pv, sp] = <[Vec<f64>; 3]>::try_from(read_columns(&path, &["op", "pv", "sp"])?)
        .expect("three columns");
    let record = LoopRecord {
        op: &op,
        pv: &pv,
        sp: Some(&sp),
        mv: None,
        time: None,
        auto: None,
    };
    // the defaults: sampled every second, OP in % of the valve's span, the band estimated too
    let d = diagnose(&record, &DiagnoseRequest::default())?;
    println!("{path}: {}", d.verdict);
    if let Some(p) = d.probability {
        println!("  probability of a sticky valve {p:.2}");
    }
    if let Some(band) = &d.band {
        println!("  stiction band {:.2} % of span", band.band_percent_of_span);
    }
    // the reasons and the next step are typed; stiction-report words them for people
    for r in &d.reasons {
        println!("  why: {:?}", r.finding);
    }
    println!("  next step: {:?}", d.next_step.action);
    Ok(())
}
