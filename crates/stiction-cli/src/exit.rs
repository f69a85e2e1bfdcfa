//! Exit codes, one meaning each, documented in `--help` and the README. A command that has
//! written its output and still wants a code other than 0 returns an [`Ending`] as its error;
//! `main` turns it into the code.

use std::fmt;
use std::process::ExitCode;
use stiction_core::diagnose::Verdict;

/// What the program's exit status means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exit {
    /// Everything worked.
    Ok = 0,
    /// An internal error (a bug): please report it.
    Internal = 1,
    /// Bad input: a flag, a file, a column or a value; the message says which and how to fix it.
    BadInput = 2,
    /// `batch` finished, but some loops failed (the summary is still written).
    FailedLoops = 3,
    /// `--fail-on stiction`: the verdict is stiction.
    StictionFound = 4,
    /// `batch` stopped by SIGINT (Ctrl-C) after writing what was done.
    Interrupted = 130,
    /// `batch` stopped by SIGTERM after writing what was done.
    Terminated = 143,
}

impl Exit {
    pub fn code(self) -> ExitCode {
        ExitCode::from(self as u8)
    }
}

/// The help text's table of exit codes.
pub const EXIT_CODES_HELP: &str = "Exit codes:
  0  ok
  1  internal error (a bug: please report it)
  2  bad input (a flag, file, column or value; the message says which and how to fix it)
  3  batch finished, but some loops failed (the summary is still written)
  4  --fail-on stiction: the verdict is stiction (diagnose, report)
  130, 143  batch stopped by SIGINT or SIGTERM (what was done is written; --resume finishes)";

/// An end with a given exit code after the output is written, and a line for standard error
/// (empty: none).
#[derive(Debug)]
pub struct Ending {
    pub exit: Exit,
    pub message: String,
}

impl Ending {
    pub fn error(exit: Exit, message: impl Into<String>) -> anyhow::Error {
        anyhow::Error::new(Ending {
            exit,
            message: message.into(),
        })
    }
}

impl fmt::Display for Ending {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Ending {}

/// The exit code and the line to print for a command's error: an [`Ending`] keeps its code and
/// words; any other error is bad input, its context chain joined in one sentence.
pub fn report(e: &anyhow::Error) -> (Exit, Option<String>) {
    if let Some(end) = e.downcast_ref::<Ending>() {
        let msg = (!end.message.is_empty()).then(|| end.message.clone());
        return (end.exit, msg);
    }
    let msg: Vec<String> = e.chain().map(|c| c.to_string()).collect();
    (Exit::BadInput, Some(format!("error: {}", msg.join(": "))))
}

/// Verdicts a script can gate on with `--fail-on`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FailOn {
    /// The verdict is stiction (exit code 4)
    Stiction,
}

impl FailOn {
    /// The ending for `--fail-on` when the verdict calls for it.
    pub fn check(fail_on: Option<FailOn>, verdict: Verdict) -> anyhow::Result<()> {
        match fail_on {
            Some(FailOn::Stiction) if verdict == Verdict::Stiction => Err(Ending::error(
                Exit::StictionFound,
                "stiction found (--fail-on stiction: exit code 4)",
            )),
            _ => Ok(()),
        }
    }
}
