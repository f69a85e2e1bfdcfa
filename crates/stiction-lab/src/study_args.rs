//! The command line every study program shares: `--benchmark` (the benchmark seeds instead of
//! the calibration seeds), `--out FILE` (the table to a file instead of standard output) and
//! other `--flag VALUE` pairs.

use crate::catalogue::{Set, Suite};

/// The study's arguments.
pub struct StudyArgs {
    program: &'static str,
    args: Vec<String>,
}

impl StudyArgs {
    /// The process's arguments, for the study `program` (named in messages).
    pub fn from_env(program: &'static str) -> Self {
        StudyArgs {
            program,
            args: std::env::args().skip(1).collect(),
        }
    }

    /// The value after `flag`, if given.
    pub fn value(&self, flag: &str) -> Option<&str> {
        self.args
            .iter()
            .position(|a| a == flag)
            .and_then(|i| self.args.get(i + 1))
            .map(String::as_str)
    }

    /// Whether `flag` was given.
    pub fn has(&self, flag: &str) -> bool {
        self.args.iter().any(|a| a == flag)
    }

    /// The catalogue set: the benchmark seeds with `--benchmark`, else the calibration seeds.
    pub fn set(&self) -> Set {
        if self.args.iter().any(|a| a == "--benchmark") {
            Set::Benchmark
        } else {
            Set::Calibration
        }
    }

    /// The suite of `--suite routine|fast` (routine when not given); exit 2 on another name.
    pub fn suite(&self) -> Suite {
        match self.value("--suite") {
            None | Some("routine") => Suite::Routine,
            Some("fast") => Suite::Fast,
            Some(other) => self.fail(&format!("--suite {other}: use routine or fast")),
        }
    }

    /// Write the table to `--out FILE`, or print it; exit 1 with one sentence if the file cannot
    /// be written.
    pub fn emit(&self, md: &str) {
        match self.value("--out") {
            Some(path) => std::fs::write(path, md).unwrap_or_else(|e| {
                eprintln!("{}: {path}: cannot write: {e}", self.program);
                std::process::exit(1)
            }),
            None => print!("{md}"),
        }
    }

    /// The number after `flag`, or `default` without it; exit 2 with one sentence if it does not
    /// parse.
    pub fn number<T: std::str::FromStr>(&self, flag: &str, default: T) -> T {
        self.value(flag).map_or(default, |v| {
            v.parse()
                .unwrap_or_else(|_| self.fail(&format!("{flag} {v}: give a number")))
        })
    }

    /// Stop with exit code 2 and one sentence about a bad argument.
    pub fn fail(&self, message: &str) -> ! {
        eprintln!("{}: {message}", self.program);
        std::process::exit(2)
    }
}
