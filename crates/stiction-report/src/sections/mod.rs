//! The report's tables as context: evidence (families and indices), oscillation, estimates,
//! convergence, data quality, the verdict per window and the notes.

use super::context::{rich, Rich};
use crate::words::{self, capital, duration, num, opt, verdict};
use serde::Serialize;
use stiction_core::diagnose::{BandSource, Diagnosis, Verdict, Vote};
use stiction_core::estimate::IntervalKind;
use stiction_core::quality::Gate;
use stiction_core::quantify::{
    FitOutput, LinearFamily, Quantification, QuantifyStatus, ValveStartKind,
};

mod convergence;
mod estimates;
mod evidence;
mod notes;
mod oscillation;
mod quality;
mod windows;

pub use convergence::{convergence, Convergence};
pub use estimates::{estimates, Estimates};
pub use evidence::{evidence, Evidence};
pub use notes::{notes, Notes};
pub use oscillation::oscillation;
pub use quality::{quality, Quality};
pub use windows::{windows, Windows};

/// A row of a two-column table: a label and its value.
#[derive(Serialize)]
pub struct KvRow {
    pub label: &'static str,
    pub value: Rich,
}

fn kv(label: &'static str, value: impl Into<Rich>) -> KvRow {
    KvRow {
        label,
        value: value.into(),
    }
}

impl From<String> for Rich {
    fn from(s: String) -> Rich {
        rich(s)
    }
}

/// A vote as the template's chip shows it.
#[derive(Serialize)]
pub struct Chip {
    pub code: &'static str,
    pub words: &'static str,
}

fn vote_chip(v: Vote) -> Chip {
    Chip {
        code: words::vote_code(v),
        words: words::vote(v),
    }
}

fn verdict_chip(v: Verdict) -> Chip {
    Chip {
        code: v.as_str(),
        words: verdict(v),
    }
}
