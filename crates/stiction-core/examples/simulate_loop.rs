//! Simulate a control loop with a sticky valve and write it as CSV (`t,sp,op,mv,pv`), the form
//! `stiction diagnose FILE --sp sp` reads: a PI controller, a Stenman valve with a band of 2 % of
//! span, a first-order process with dead time, a setpoint step, measurement noise: the
//! repository's `examples/data/sticky_loop.csv`, byte for byte.
//!
//!     cargo run --release -p stiction-core --example simulate_loop -- [FILE]
//!
//! Without FILE it prints the first rows and a summary.

use std::error::Error;
use std::fmt::Write as _;
use stiction_core::models::{Model, Stenman};
use stiction_core::sim::{ClosedLoop, Process, Signal};

fn main() -> Result<(), Box<dyn Error>> {
    let mut sim = ClosedLoop::new(Model::Stenman(Stenman::new(2.0)?));
    sim.process = Process::Foptd {
        k: 3.0,
        tau: 10.0,
        delay: 10.0,
    };
    sim.setpoint = Signal::Step {
        from: 50.0,
        to: 51.0,
        at: 10.0,
    };
    sim.samples = 1500;
    sim.noise = 0.05;
    sim.seed = 3;
    let data = sim.run()?;

    let mut csv = String::from("t,sp,op,mv,pv\n");
    for i in 0..data.t.len() {
        let (t, sp, op, mv, pv) = (data.t[i], data.sp[i], data.op[i], data.mv[i], data.pv[i]);
        writeln!(csv, "{t},{sp},{op},{mv},{pv}")?;
    }
    match std::env::args().nth(1) {
        Some(path) => {
            std::fs::write(&path, csv)?;
            println!("wrote {} samples to {path}", data.t.len());
        }
        None => {
            csv.lines().take(6).for_each(|l| println!("{l}"));
            let (lo, hi) = data
                .op
                .iter()
                .fold((f64::MAX, f64::MIN), |(a, b), &v| (a.min(v), b.max(v)));
            println!(
                "... {} samples; OP cycles between {lo:.2} and {hi:.2} %",
                data.t.len()
            );
        }
    }
    Ok(())
}
