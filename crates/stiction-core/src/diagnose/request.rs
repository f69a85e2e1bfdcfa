//! What `diagnose` is asked, and the request's errors.

use crate::checked::Checked;
use crate::quality::{Limits, Record};
use serde::{Deserialize, Serialize};

/// What `diagnose` needs besides the signals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DiagnoseRequest {
    /// Sampling time, seconds.
    pub ts: f64,
    /// The loop's kind: `Some(true)` an integrating process (a level: the indices and the fits
    /// use their integrating variants), `Some(false)` a self-regulating one, `None` the record's
    /// behaviour decides ([`super::loop_kind`]).
    #[serde(default)]
    pub integrating: Option<bool>,
    /// The ISA-5.1 tag that set `integrating`, when a column's name did (said in a warning).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub integrating_tag: Option<String>,
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
    /// The model family also runs the levels test ([`crate::identify::levels`]): every distinct
    /// Stenman valve scored on PV's levels. Finds more sticky valves on records sampled at every
    /// controller execution, at 1 to 3 s a loop of 2,000 samples. Where the other families have
    /// not decided `stiction`, the hidden-valve family runs too
    /// ([`super::evidence::hidden_valve`]; about 1 s more on two cores where it judges, about 3 s
    /// where it votes stiction: a vote is the median of three draws of its particle filter).
    #[serde(default)]
    pub thorough: bool,
    /// How the families measure ([`super::Settings`]).
    #[serde(default)]
    pub settings: super::Settings,
}

fn default_op_range() -> [f64; 2] {
    [0.0, 100.0]
}

impl Default for DiagnoseRequest {
    fn default() -> Self {
        Self {
            ts: 1.0,
            integrating: None,
            integrating_tag: None,
            limits: Limits::default(),
            min_periods: 4.0,
            min_samples: 200,
            window: None,
            quantify: true,
            max_delay: 30,
            estimate_start: false,
            verdict_margin: 0.3,
            op_range: default_op_range(),
            thorough: false,
            settings: super::Settings::default(),
        }
    }
}

impl DiagnoseRequest {
    /// Check the request once, before any data are read: the sampling time, the window, the OP
    /// range and the judgement's settings (the first one wrong is the error).
    /// [`super::diagnose_checked`] runs the checked request without checking it again.
    pub fn check(&self) -> Result<Checked<DiagnoseRequest>, DiagnoseError> {
        if !(self.ts > 0.0 && self.ts.is_finite()) {
            return Err(DiagnoseError::Ts(self.ts));
        }
        if let Some(w) = self.window {
            if w < self.min_samples {
                return Err(DiagnoseError::Window {
                    window: w,
                    least: self.min_samples,
                });
            }
        }
        let [lo, hi] = self.op_range;
        if !(hi > lo && lo.is_finite() && hi.is_finite()) {
            return Err(DiagnoseError::OpRange { lo, hi });
        }
        self.check_settings()?;
        Ok(Checked::new(self.clone()))
    }

    /// The judgement's settings and the gates' limits, each in its range.
    fn check_settings(&self) -> Result<(), DiagnoseError> {
        let check = |ok: bool, name: &'static str, rule: &'static str, value: f64| {
            if ok {
                Ok(())
            } else {
                Err(DiagnoseError::Setting { name, rule, value })
            }
        };
        let share = |x: f64| (0.0..=1.0).contains(&x);
        let l = &self.limits;
        check(
            self.min_periods > 0.0 && self.min_periods.is_finite(),
            "min_periods",
            "a finite number > 0",
            self.min_periods,
        )?;
        check(
            self.min_samples >= 2,
            "min_samples",
            "at least 2",
            self.min_samples as f64,
        )?;
        check(
            share(self.verdict_margin),
            "verdict_margin",
            "between 0 and 1",
            self.verdict_margin,
        )?;
        let shares = [
            ("limits.saturated_share", l.saturated_share),
            ("limits.repeated_share", l.repeated_share),
            ("limits.manual_share", l.manual_share),
        ];
        for (name, value) in shares {
            check(share(value), name, "a share between 0 and 1", value)?;
        }
        check(
            l.levels_per_100 >= 0.0 && l.levels_per_100.is_finite(),
            "limits.levels_per_100",
            "a finite number >= 0",
            l.levels_per_100,
        )?;
        check(
            l.gap_steps > 0.0 && l.gap_steps.is_finite(),
            "limits.gap_steps",
            "a finite number > 0",
            l.gap_steps,
        )?;
        self.settings.check()
    }

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
    /// A setting of the judgement or a gate's limit out of range, named as its field.
    #[error("{name} must be {rule}, got {value}")]
    Setting {
        /// The field (`min_periods`, `limits.gap_steps`, ...).
        name: &'static str,
        /// What it must be.
        rule: &'static str,
        /// The value given.
        value: f64,
    },
}

/// The record's signals all as long as OP (the data's check; the request is checked when built).
pub(super) fn check_record(r: &Record) -> Result<(), DiagnoseError> {
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
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_finds_each_kind_of_mistake() {
        let good = DiagnoseRequest::default();
        assert_eq!(*good.check().unwrap(), good);
        let with = |change: fn(&mut DiagnoseRequest)| {
            let mut r = DiagnoseRequest::default();
            change(&mut r);
            r.check().unwrap_err()
        };
        assert_eq!(
            with(|r| r.ts = f64::NAN).to_string(),
            "the sampling time must be a positive number of seconds, got NaN"
        );
        assert_eq!(
            with(|r| r.window = Some(50)),
            DiagnoseError::Window {
                window: 50,
                least: 200
            }
        );
        assert_eq!(
            with(|r| r.op_range = [100.0, 0.0]),
            DiagnoseError::OpRange { lo: 100.0, hi: 0.0 }
        );
        assert!(matches!(
            with(|r| r.min_periods = 0.0),
            DiagnoseError::Setting {
                name: "min_periods",
                ..
            }
        ));
        assert!(matches!(
            with(|r| r.verdict_margin = 1.5),
            DiagnoseError::Setting {
                name: "verdict_margin",
                ..
            }
        ));
        assert_eq!(
            with(|r| r.limits.manual_share = 2.0).to_string(),
            "limits.manual_share must be a share between 0 and 1, got 2"
        );
    }

    #[test]
    fn check_record_needs_every_signal_as_long_as_op() {
        let (op, pv, sp) = ([0.0; 4], [0.0; 4], [0.0; 3]);
        let r = Record {
            op: &op,
            pv: &pv,
            sp: Some(&sp),
            mv: None,
            time: None,
            auto: None,
        };
        assert_eq!(
            check_record(&r),
            Err(DiagnoseError::OtherLength {
                signal: "sp",
                len: 3,
                op: 4
            })
        );
        let r = Record {
            sp: None,
            pv: &pv[..2],
            ..r
        };
        assert_eq!(
            check_record(&r),
            Err(DiagnoseError::Lengths { op: 4, pv: 2 })
        );
    }
}
