//! What `diagnose` is asked, and the request's errors.

use crate::quality::{Limits, Record};
use serde::{Deserialize, Serialize};

/// What `diagnose` needs besides the signals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiagnoseRequest {
    /// Sampling time, seconds.
    pub ts: f64,
    /// A level-type (integrating) process: the indices and the fits use their integrating variants.
    pub integrating: bool,
    /// The data-quality gates' limits.
    pub limits: Limits,
    /// Fewest oscillation periods for the shape indices to judge an oscillation.
    pub min_periods: f64,
    /// Fewest samples in the analysed stretch.
    pub min_samples: usize,
    /// Add a verdict per window of this many samples.
    pub window: Option<usize>,
    /// Size the band with the closed-loop estimate (`quantify`) when the verdict is `stiction`.
    pub quantify: bool,
    /// Largest process delay the fits try, samples.
    pub max_delay: usize,
    /// The closed-loop estimate also estimates where the valve stood at the first sample
    /// ([`crate::quantify::QuantifyRequest::estimate_start`]).
    pub estimate_start: bool,
    /// Margin of the shape indices' weighted vote (in -1..=1) for the shape family to vote.
    pub verdict_margin: f64,
    /// The OP values of a closed and a fully open valve: the band is reported in % of this span.
    /// Default `[0, 100]` (OP in % of span).
    #[serde(default = "default_op_range")]
    pub op_range: [f64; 2],
}

fn default_op_range() -> [f64; 2] {
    [0.0, 100.0]
}

impl Default for DiagnoseRequest {
    fn default() -> Self {
        Self {
            ts: 1.0,
            integrating: false,
            limits: Limits::default(),
            min_periods: 4.0,
            min_samples: 200,
            window: None,
            quantify: true,
            max_delay: 30,
            estimate_start: false,
            verdict_margin: 0.3,
            op_range: default_op_range(),
        }
    }
}

impl DiagnoseRequest {
    /// A band in OP units as a percentage of the valve's span.
    pub fn percent_of_span(&self, op_units: f64) -> f64 {
        100.0 * op_units / (self.op_range[1] - self.op_range[0])
    }
}

/// Errors in the request (the data themselves never give an error: a record that cannot be judged
/// is `insufficient_data`, and missing values are gaps).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum DiagnoseError {
    /// OP and PV differ in length.
    #[error("op has {op} samples but pv has {pv}: the signals must have the same length")]
    Lengths {
        /// Samples of OP.
        op: usize,
        /// Samples of PV.
        pv: usize,
    },
    /// SP, MV, time or the mode differs in length from OP.
    #[error("{signal} has {len} samples but op has {op}: the signals must have the same length")]
    OtherLength {
        /// Which signal (`sp`, `mv`, `time` or `mode`).
        signal: &'static str,
        /// Its samples.
        len: usize,
        /// Samples of OP.
        op: usize,
    },
    /// The sampling time (seconds) is not a positive number.
    #[error("the sampling time must be a positive number of seconds, got {0}")]
    Ts(f64),
    /// The verdict window is too short.
    #[error("a window of {window} samples is too short: a window needs at least {least}")]
    Window {
        /// The window asked for, samples.
        window: usize,
        /// The shortest window allowed, samples.
        least: usize,
    },
    /// The OP range of a closed and a fully open valve is empty or reversed.
    #[error("the OP range [{lo}, {hi}] is empty: the value of a fully open valve must exceed that of a closed one")]
    OpRange {
        /// OP of a closed valve.
        lo: f64,
        /// OP of a fully open valve.
        hi: f64,
    },
}

pub(super) fn check(r: &Record, req: &DiagnoseRequest) -> Result<(), DiagnoseError> {
    if r.op.len() != r.pv.len() {
        return Err(DiagnoseError::Lengths {
            op: r.op.len(),
            pv: r.pv.len(),
        });
    }
    let n = r.op.len();
    for (signal, len) in [
        ("sp", r.sp.map(|s| s.len())),
        ("mv", r.mv.map(|s| s.len())),
        ("time", r.time.map(|s| s.len())),
        ("mode", r.auto.map(|s| s.len())),
    ] {
        if let Some(len) = len {
            if len != n {
                return Err(DiagnoseError::OtherLength { signal, len, op: n });
            }
        }
    }
    if !(req.ts > 0.0 && req.ts.is_finite()) {
        return Err(DiagnoseError::Ts(req.ts));
    }
    if let Some(w) = req.window {
        if w < req.min_samples {
            return Err(DiagnoseError::Window {
                window: w,
                least: req.min_samples,
            });
        }
    }
    let [lo, hi] = req.op_range;
    if !(hi > lo && lo.is_finite() && hi.is_finite()) {
        return Err(DiagnoseError::OpRange { lo, hi });
    }
    Ok(())
}
