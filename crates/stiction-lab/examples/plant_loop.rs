//! Write one loop of the benchmark catalogue (`stiction_lab::catalogue`) as a CSV file with
//! the columns `t,sp,op,mv,pv`, so it can be given to `stiction diagnose`.
//!
//!     cargo run --release -p stiction-lab --example plant_loop -- ID FILE
//!
//! ID is a catalogue id: `routine-b-0042` (routine suite, benchmark set, loop 42), `fast-c-0007`
//! (fast suite, calibration set), or `issue14`. The loop's description and the matching
//! `stiction diagnose` command are printed on stderr.

use std::process::exit;
use stiction_lab::catalogue;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [id, path] = args.as_slice() else {
        eprintln!("usage: plant_loop ID FILE (e.g. plant_loop routine-b-0042 loop.csv)");
        exit(2)
    };
    let Some(l) = catalogue::find(id) else {
        eprintln!(
            "plant_loop: no catalogue loop '{id}'; ids are routine-b-NNNN (0..{}), fast-b-NNNN (0..{}), \
             with c instead of b for the calibration set, or issue14",
            catalogue::size(catalogue::Suite::Routine) - 1,
            catalogue::size(catalogue::Suite::Fast) - 1
        );
        exit(2)
    };
    let csv = stiction_lab::catalogue_loop::csv(&l);
    if let Err(e) = std::fs::write(path, csv) {
        eprintln!("plant_loop: {path}: cannot write the file: {e}");
        exit(1)
    }
    eprintln!(
        "{} ({}, truth {}, {} slips): {}\nwrote {} samples to {path}; judge it with\n  stiction diagnose {path} --sp sp{}",
        l.id,
        l.class,
        l.truth.name(),
        l.slips,
        l.description,
        l.data.t.len(),
        if l.integrating { " --integrating" } else { "" }
    );
}
