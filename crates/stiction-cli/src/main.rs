//! `stiction`: find and measure stiction in control valves. Thin glue over `stiction-core`:
//! flags are parsed here, turned into validated core requests, and results printed by a human or a
//! JSON printer.

mod atomic;
mod cmd_batch;
mod cmd_diagnose;
mod cmd_estimate;
mod cmd_quantify;
mod cmd_report;
mod cmd_reproduce;
mod cmd_simulate;
mod data;
mod diagnosed;
mod exit;
mod human;
mod loop_file;
mod loop_messages;
mod plot;
mod spec;

// the wording of verdicts, votes, numbers and durations, shared with the HTML pages
use stiction_report::words;

use clap::{CommandFactory, Parser, Subcommand};
use exit::{Ending, Exit};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "stiction",
    version,
    about = "Find and measure stiction (static friction) in control valves",
    long_about = "Find and measure stiction (static friction) in control valves: simulate sticky \
valves open or closed loop, estimate the stiction band from command and valve position with the \
paper's ant colony optimisation, ACO_R, a grid or an exact solver, and reproduce the paper.",
    after_help = exit::EXIT_CODES_HELP
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
    /// Diagnose a loop from routine data: the probability of a sticky valve, a verdict, its reasons and the next step.
    Diagnose(cmd_diagnose::Args),
    /// Diagnose a loop and write one self-contained HTML report (inline SVG charts, no network).
    Report(cmd_report::Args),
    /// Diagnose and quantify many loops in parallel: a ranked summary, per-loop JSON and reports.
    Batch(cmd_batch::Args),
    /// Reproduce published results (`stiction reproduce paper`).
    Reproduce(cmd_reproduce::Args),
    /// Print a shell completion script (e.g. `stiction completions bash > /etc/bash_completion.d/stiction`).
    Completions {
        /// bash, zsh, fish, elvish or powershell
        shell: clap_complete::Shell,
    },
    /// Print the manual page (roff), or write one per command into a folder with --out.
    Man {
        /// Write stiction.1 and stiction-COMMAND.1 into this folder instead of printing stiction.1
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
    },
}

fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Simulate(a) => cmd_simulate::run(a),
        Command::Estimate(a) => cmd_estimate::run(a),
        Command::Quantify(a) => cmd_quantify::run(a),
        Command::Diagnose(a) => cmd_diagnose::run(a),
        Command::Report(a) => cmd_report::run(a),
        // batch has its own exit statuses (3: some loops failed; 130 / 143: stopped by a signal)
        Command::Batch(a) => match cmd_batch::run(a)? {
            0 => Ok(()),
            3 => Err(Ending::error(Exit::FailedLoops, "")),
            130 => Err(Ending::error(Exit::Interrupted, "")),
            _ => Err(Ending::error(Exit::Terminated, "")),
        },
        Command::Reproduce(a) => cmd_reproduce::run(a),
        Command::Completions { shell } => {
            clap_complete::generate(
                shell,
                &mut Cli::command(),
                "stiction",
                &mut std::io::stdout(),
            );
            Ok(())
        }
        Command::Man { out } => man(out),
    }
}

/// The manual page: one for `stiction` on standard output, or one per command in a folder.
fn man(out: Option<PathBuf>) -> anyhow::Result<()> {
    let cmd = Cli::command();
    let Some(dir) = out else {
        let mut page = Vec::new();
        clap_mangen::Man::new(cmd).render(&mut page)?;
        std::io::stdout().write_all(&page)?;
        return Ok(());
    };
    std::fs::create_dir_all(&dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    let mut pages = vec![("stiction.1".to_string(), cmd.clone())];
    for sub in cmd.get_subcommands() {
        let name = format!("stiction-{}", sub.get_name());
        let page = sub
            .clone()
            .name(name.clone())
            .version(env!("CARGO_PKG_VERSION"));
        pages.push((format!("{name}.1"), page));
    }
    for (file, c) in pages {
        let mut page = Vec::new();
        clap_mangen::Man::new(c).render(&mut page)?;
        let path = dir.join(&file);
        std::fs::write(&path, page)
            .map_err(|e| anyhow::anyhow!("{}: cannot write the file: {e}", path.display()))?;
    }
    eprintln!("manual pages written to {}", dir.display());
    Ok(())
}

fn main() -> ExitCode {
    // SAFETY: setting a signal disposition before any thread starts; SIG_DFL is always valid
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // a panic is a bug: say so in one line and exit 1, not with Rust's panic text
    std::panic::set_hook(Box::new(|info| {
        if data::in_guarded_reader() {
            return; // a damaged workbook or Parquet file: said as a sentence by the reader
        }
        let p = info.payload();
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        let at = info
            .location()
            .map(|l| format!(" ({}:{})", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!(
            "error: internal error, a bug: please report it with the command that caused it: {}{at}",
            what.replace('\n', " ")
        );
    }));
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // --help and --version print to standard output and end with 0
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            eprintln!("{}", clap_error_line(&e));
            return Exit::BadInput.code();
        }
    };
    match std::panic::catch_unwind(|| run(cli.command)) {
        Ok(Ok(())) => Exit::Ok.code(),
        Ok(Err(e)) => {
            let (exit, line) = exit::report(&e);
            if let Some(line) = line {
                eprintln!("{line}");
            }
            exit.code()
        }
        Err(_) => Exit::Internal.code(),
    }
}

/// A flag or value clap rejects, in one line: its message and the possible values, without the
/// usage block.
fn clap_error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let parts: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| {
            !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
        })
        .collect();
    format!("{} (see --help)", parts.join(" "))
}
