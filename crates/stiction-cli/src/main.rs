//! `stiction`: find and measure stiction in control valves. Thin glue over `stiction-core`:
//! flags are parsed here, turned into validated core requests, and results printed by a human or a
//! JSON printer.

mod cmd_batch;
mod cmd_diagnose;
mod cmd_estimate;
mod cmd_quantify;
mod cmd_report;
mod cmd_reproduce;
mod cmd_simulate;
mod data;
mod plot;
mod spec;
mod timestamp;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "stiction",
    version,
    about = "Find and measure stiction (static friction) in control valves",
    long_about = "Find and measure stiction (static friction) in control valves: simulate sticky \
valves open or closed loop, estimate the stiction band from command and valve position with the \
paper's ant colony optimisation, ACO_R, a grid or an exact solver, and reproduce the paper."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Simulate a sticky valve open loop (a command signal) or in a PI control loop; writes t,sp,op,mv,pv.
    Simulate(cmd_simulate::Args),
    /// Estimate stiction-model parameters from the command (op) and the valve position (mv).
    Estimate(cmd_estimate::Args),
    /// Quantify stiction from OP and PV alone (closed-loop Hammerstein identification).
    Quantify(cmd_quantify::Args),
    /// Diagnose a loop from routine data: quality gates, oscillation, stiction indices and a verdict.
    Diagnose(cmd_diagnose::Args),
    /// Diagnose a loop and write one self-contained HTML report (inline SVG charts, no network).
    Report(cmd_report::Args),
    /// Diagnose and quantify many loops in parallel: a ranked summary, per-loop JSON and reports.
    Batch(cmd_batch::Args),
    /// Reproduce published results (`stiction reproduce paper`).
    Reproduce(cmd_reproduce::Args),
}

fn main() -> ExitCode {
    // SAFETY: setting a signal disposition before any thread starts; SIG_DFL is always valid
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Simulate(a) => cmd_simulate::run(a),
        Command::Estimate(a) => cmd_estimate::run(a),
        Command::Quantify(a) => cmd_quantify::run(a),
        Command::Diagnose(a) => cmd_diagnose::run(a),
        Command::Report(a) => cmd_report::run(a),
        Command::Batch(a) => cmd_batch::run(a),
        Command::Reproduce(a) => cmd_reproduce::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // one sentence: the context chain joined, outermost first
            let msg: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", msg.join(": "));
            ExitCode::from(2)
        }
    }
}
