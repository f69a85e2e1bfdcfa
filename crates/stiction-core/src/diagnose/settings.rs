//! The judgement's settings in one typed table: how the families measure what the verdict's
//! model reads. Every field has a default ([`Settings::default`]) and is checked with the request
//! ([`super::DiagnoseRequest::check`]); the guide's page on the verdict prints the table
//! (`stiction diagnose --settings`).

use super::averaging::AveragingSettings;
use super::evidence::stick_slip::{StepSettings, StuckSettings};
use super::request::DiagnoseError;
use serde::{Deserialize, Serialize};

/// How `diagnose` measures (the verdict's model and its thresholds are in the model file,
/// [`super::VerdictModel`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct Settings {
    /// How PV's levels, steps and sticks are told (the stick-slip family).
    #[serde(default)]
    pub steps: StepSettings,
    /// How a hold of PV off the setpoint is told (the stick-slip family).
    #[serde(default)]
    pub stuck: StuckSettings,
    /// How a long record is averaged before it is judged.
    #[serde(default)]
    pub averaging: AveragingSettings,
}

impl Settings {
    /// An error naming the first field out of range.
    pub fn check(&self) -> Result<(), DiagnoseError> {
        let positive = |name: &'static str, v: f64| {
            if v > 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(DiagnoseError::Setting {
                    name,
                    rule: "a finite number > 0",
                    value: v,
                })
            }
        };
        let share = |name: &'static str, v: f64| {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(DiagnoseError::Setting {
                    name,
                    rule: "a share between 0 and 1",
                    value: v,
                })
            }
        };
        let at_least = |name: &'static str, v: usize, least: usize| {
            if v >= least {
                Ok(())
            } else {
                Err(DiagnoseError::Setting {
                    name,
                    rule: if least == 1 {
                        "at least 1"
                    } else {
                        "at least 2"
                    },
                    value: v as f64,
                })
            }
        };
        let s = &self.steps;
        positive("settings.steps.penalty", s.penalty)?;
        at_least("settings.steps.min_level", s.min_level, 2)?;
        share("settings.steps.transition_share", s.transition_share)?;
        positive("settings.steps.min_step", s.min_step)?;
        positive("settings.steps.op_travel", s.op_travel)?;
        at_least("settings.steps.lead", s.lead, 1)?;
        share("settings.steps.late_share", s.late_share)?;
        share("settings.steps.flatness", s.flatness)?;
        positive("settings.steps.offset", s.offset)?;
        at_least("settings.steps.max_level", s.max_level, 2)?;
        let h = &self.stuck;
        at_least("settings.stuck.smoothing", h.smoothing, 1)?;
        at_least("settings.stuck.min_samples", h.min_samples, 2)?;
        positive("settings.stuck.offset", h.offset)?;
        share("settings.stuck.spread", h.spread)?;
        let a = &self.averaging;
        at_least("settings.averaging.min_samples", a.min_samples, 2)?;
        positive("settings.averaging.per_time_scale", a.per_time_scale)?;
        at_least("settings.averaging.max_time_scales", a.max_time_scales, 1)?;
        Ok(())
    }
}
