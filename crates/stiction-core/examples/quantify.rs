//! Quantify stiction from OP and PV alone: the closed-loop fit of a Stenman valve and a linear
//! process, as `stiction quantify` does, on a simulated PI loop with a band of 2 % of span.
//!
//!     cargo run --release -p stiction-core --example quantify

use std::error::Error;
use stiction_core::models::{Model, ModelKind, Stenman};
use stiction_core::quantify::{quantify, QuantifyRequest};
use stiction_core::sim::ClosedLoop;
use stiction_core::Method;

fn main() -> Result<(), Box<dyn Error>> {
    // the default loop: a first-order process with dead time under PI, sampled every second
    let mut sim = ClosedLoop::new(Model::Stenman(Stenman::new(2.0)?));
    sim.samples = 1500;
    sim.noise = 0.05;
    sim.seed = 3;
    let data = sim.run()?;

    // Stenman's model by the exact solver, the process identified beside it
    let req = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
    let q = quantify(&data.op, &data.pv, &req)?;
    println!("status: {:?}", q.status);
    for (name, value) in &q.params {
        println!("  {name} = {value:.3} % of span (simulated: 2)");
    }
    if let Some(fit) = &q.fit {
        println!(
            "  fit of PV: R² {:.4} in simulation, {:.4} one step ahead",
            fit.r2_simulation, fit.r2_one_step
        );
        if let Some(linear) = fit.r2_simulation_without_stiction {
            println!("  without stiction: R² {linear:.4}");
        }
    }
    if let Some(p) = &q.linear_model {
        let (k, tau) = (
            p.gain.unwrap_or(f64::NAN),
            p.time_constant.unwrap_or(f64::NAN),
        );
        println!(
            "  process: gain {k:.2}, time constant {tau:.1} s, dead time {:.0} s (simulated: 3, 10, 10)",
            p.dead_time
        );
    }
    Ok(())
}
