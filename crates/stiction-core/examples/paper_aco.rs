//! The paper's ant colony optimisation on a simulated valve: a Kano valve (S = 2, J = 1 % of
//! span) driven open loop by a sine, its parameters estimated from the command (op) and the
//! valve position (mv) with the paper's ACO, checked against the truth.
//!
//!     cargo run --release -p stiction-core --example paper_aco

use std::error::Error;
use stiction_core::models::{Kano, Model, ModelKind};
use stiction_core::sim::{simulate_open_loop, Signal};
use stiction_core::{estimate, Method, Request};

fn main() -> Result<(), Box<dyn Error>> {
    let valve = Model::Kano(Kano::new(2.0, 1.0)?);
    let command = Signal::Sine {
        amplitude: 5.0,
        period: 10.0,
        offset: 50.0,
    };
    // 1001 samples every 0.1 s, the valve position measured with noise of 0.01 % of span
    let data = simulate_open_loop(&valve, &command, 0.1, 1001, 0.01, 1)?;

    // the paper's ACO with its settings (20 ants, 100 iterations), S and J searched in 0-10 %
    let req = Request {
        bounds: Some(vec![(0.0, 10.0), (0.0, 10.0)]),
        seed: 1,
        ..Request::new(ModelKind::Kano, Method::Aco)
    };
    let est = estimate(&data.op, &data.mv, &req)?;
    println!("Kano valve, S = 2, J = 1 (% of span), by the paper's ACO:");
    for (name, value) in &est.params {
        println!("  {name} = {value:.3}");
    }
    println!(
        "  fit: RMSE {:.4}, R² {:.4}; {} evaluations in {} iterations",
        est.rmse, est.r2, est.evaluations, est.iterations
    );
    Ok(())
}
