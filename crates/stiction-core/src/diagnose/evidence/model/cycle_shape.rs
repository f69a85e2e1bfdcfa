//! The model family's check of a regular cycle's shape: does the fitted valve give PV the cycle
//! it has?
//!
//! A band can explain a cycle that OP does not drive. With a sine added to PV (an upstream
//! loop's cycle, a pump), OP answers it through the controller, and the fit with a band can
//! turn OP's cycle into PV's: its valve slips twice a period, in step with the cycle, a relay
//! whose lag the fitted process carries to PV's phase (the controller's law read backwards). So
//! the fit gains far more than healthy loops give, on a loop whose valve is healthy. But such a
//! valve moves in steps, and its PV carries the steps' harmonics; the PV recorded, a sine in
//! noise, carries none. A sticky valve that makes the cycle gives PV the harmonics its fit
//! gives (on the catalogue's calibration draws, of the 218 sticky valves whose fit voted
//! stiction on a regular cycle with harmonics of at least [`FIT_HARMONICS`], the fit's PV
//! carried at most 4.5 times the harmonics of the recorded PV, 2.5 times but for one).
//!
//! So on a regular cycle (Thornhill's regularity [`super::LIMIT_CYCLE_REGULARITY`] or more,
//! whether or not it stands out of the noise as an oscillation), where the fitted valve gives PV
//! harmonics of at least [`FIT_HARMONICS`] of its cycle's power and [`FOREIGN_SHAPE`] times or
//! more those of the recorded PV, the fit's stiction vote is withdrawn: its band reproduces the
//! cycle's timing with a shape PV does not have. It clears healthy loops with a sine added to PV
//! (the batch benchmark's mix); on the catalogue's sets and the ISDB no fit that decides a verdict
//! has so foreign a shape.

use super::{Context, LIMIT_CYCLE_REGULARITY};
use crate::diagnose::evidence::limit_cycle::{measurable_harmonics, MIN_HARMONICS};
use crate::diagnose::evidence::shape::SINUSOIDAL_HARMONICS;
use crate::quantify::FitComparison;
use crate::spectral::harmonic_distortion;
use serde::{Deserialize, Serialize};

/// The fitted valve's PV must carry at least this share of its cycle's power in harmonics 2 to
/// 5 (the shape family's bound of a sinusoid): a fit whose PV is itself sinusoidal has no shape
/// to miss.
pub(super) const FIT_HARMONICS: f64 = SINUSOIDAL_HARMONICS;
/// ... and this many times those of the recorded PV: above every sticky valve of the
/// catalogue's calibration draws (the largest 4.5).
pub(crate) const FOREIGN_SHAPE: f64 = 5.0;

/// The harmonics of the cycle in the fitted valve's PV and in the recorded PV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleShape {
    /// The cycle's period, s.
    pub period: f64,
    /// Harmonics 2 to `harmonic_count` over the fundamental's power in the PV the fitted valve
    /// gives, over the cycle's stretch.
    pub fit_harmonics: f64,
    /// The same in the recorded PV (its white noise's floor taken off).
    pub pv_harmonics: f64,
    /// The highest harmonic measured (up to 5, below the Nyquist frequency).
    pub harmonic_count: usize,
}

impl CycleShape {
    /// The harmonics of a regular cycle of the control error in `ctx`, in the fit's PV and the
    /// recorded one; `None` without such a cycle, or where a cycle of few samples puts the 3rd
    /// harmonic above the Nyquist frequency.
    pub(super) fn of(ctx: &Context, f: &FitComparison) -> Option<Self> {
        let o = &ctx.oscillation;
        let period = o.period?;
        if !o.regularity.oscillating || o.regularity.regularity < LIMIT_CYCLE_REGULARITY {
            return None;
        }
        let [s, e] = o.stretch;
        if e > ctx.pv.len() || f.pv_stiction.len() != ctx.pv.len() {
            return None;
        }
        let samples = period / ctx.req.ts;
        let count = measurable_harmonics(samples);
        if count < MIN_HARMONICS {
            return None;
        }
        Some(Self {
            period,
            fit_harmonics: harmonic_distortion(&f.pv_stiction[s..e], 1.0 / samples, count)?,
            pv_harmonics: harmonic_distortion(&ctx.pv[s..e], 1.0 / samples, count)?,
            harmonic_count: count,
        })
    }

    /// Whether the fitted valve gives the cycle a shape the recorded PV does not have.
    pub fn foreign(&self) -> bool {
        self.fit_harmonics >= FIT_HARMONICS
            && self.fit_harmonics >= FOREIGN_SHAPE * self.pv_harmonics.max(0.0)
    }

    /// A clause for the family's note, where the shape is foreign.
    pub fn words(&self) -> String {
        format!(
            "but on the regular cycle of {:.0} s the fitted valve would give PV harmonics of {:.3} of the cycle's power and the recorded PV carries {:.4}: \
             the band reproduces the cycle's timing with a shape PV does not have (a cycle OP does not drive, as a sine added to PV, gives that), so this is no vote",
            self.period,
            self.fit_harmonics,
            self.pv_harmonics.max(0.0)
        )
    }
}

/// The cycle's shape of a stiction vote's fit, kept in `evidence`; the words for the family's
/// note where the shape is foreign (the vote is then withdrawn).
pub(super) fn checked(
    ctx: &Context,
    f: &FitComparison,
    evidence: &mut super::ModelEvidence,
) -> Option<String> {
    evidence.cycle_shape = CycleShape::of(ctx, f);
    evidence
        .cycle_shape
        .as_ref()
        .filter(|c| c.foreign())
        .map(CycleShape::words)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(fit: f64, pv: f64) -> CycleShape {
        CycleShape {
            period: 100.0,
            fit_harmonics: fit,
            pv_harmonics: pv,
            harmonic_count: 5,
        }
    }

    #[test]
    fn a_fit_whose_steps_the_recorded_cycle_lacks_is_foreign() {
        // the batch mix's sine on PV: the fit's relay gives 0.047, PV 0.003
        assert!(shape(0.047, 0.0034).foreign());
        // a sticky valve's cycle carries the fit's harmonics
        assert!(!shape(0.15, 0.08).foreign());
        // a fit that is itself sinusoidal has no shape to miss
        assert!(!shape(0.008, 0.0).foreign());
        // a noise floor taken off below zero counts as none
        assert!(shape(0.02, -0.001).foreign());
        assert!(!shape(FIT_HARMONICS, FIT_HARMONICS / FOREIGN_SHAPE + 1e-6).foreign());
    }
}
