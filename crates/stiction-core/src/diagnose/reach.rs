//! What a record like this one can show of a sticky valve. Proportional action passes the PV's
//! noise on to OP; a band of a few of OP's noise standard deviations is crossed by the noise alone,
//! and the valve then moves in small jumps that look like a healthy valve's noise. Bands under
//! [`SMALL`] OP noise standard deviations are seldom found, and most of those over `LARGE` are
//! (the lab's plant benchmark tables the sticky valves found by band over OP's noise), so a
//! `no_stiction` verdict speaks for large bands and is nearly silent on small ones.

use super::{DiagnoseRequest, Diagnosis, Family, FamilyEvidence};
use serde::{Deserialize, Serialize};

/// A small band: under this many OP noise standard deviations.
pub const SMALL: f64 = 4.0;
/// A large band: over this many OP noise standard deviations.
const LARGE: f64 = 12.0;

/// The bands a record like this one shows and hides, from OP's noise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Reach {
    /// OP's noise standard deviation, OP units (as the stick-slip family measured it; on OP held
    /// between updates, from its changes).
    pub op_noise: f64,
    /// OP's noise standard deviation, % of valve span.
    pub op_noise_percent_of_span: f64,
    /// Bands under this (% of span; [`SMALL`] OP noise standard deviations) often pass for OP's
    /// noise.
    pub small_band_percent_of_span: f64,
    /// Bands over this (% of span; `LARGE` OP noise standard deviations) mostly show.
    pub large_band_percent_of_span: f64,
}

impl Reach {
    /// The reach of a record whose OP noise standard deviation is `op_noise` (OP units).
    pub fn new(op_noise: f64, req: &DiagnoseRequest) -> Option<Self> {
        (op_noise.is_finite() && op_noise > 0.0).then(|| Self {
            op_noise,
            op_noise_percent_of_span: req.percent_of_span(op_noise),
            small_band_percent_of_span: req.percent_of_span(SMALL * op_noise),
            large_band_percent_of_span: req.percent_of_span(LARGE * op_noise),
        })
    }
}

/// The reach of the stretch judged in `d` (OP `op`): OP's noise as the stick-slip family measured
/// it, or measured here when that family did not judge.
pub(super) fn of(d: &Diagnosis, op: &[f64], req: &DiagnoseRequest) -> Option<Reach> {
    Reach::new(op_noise(&d.families, || crate::detect::held_noise(op)), req)
}

/// OP's noise standard deviation as the reach reads it: the stick-slip family's, or `measured`
/// when that family did not judge.
pub(super) fn op_noise(families: &[FamilyEvidence], measured: impl FnOnce() -> f64) -> f64 {
    families
        .iter()
        .find(|f| f.family == Family::StickSlip)
        .and_then(|f| f.stick_slip.as_ref())
        .map_or_else(measured, |s| s.op_noise)
}

#[cfg(test)]
mod tests {
    use super::{Reach, LARGE, SMALL};
    use crate::diagnose::DiagnoseRequest;

    #[test]
    fn the_reach_is_the_ops_noise_times_the_calibrated_factors_in_percent_of_span() {
        let mut req = DiagnoseRequest::default();
        let r = Reach::new(0.1, &req).expect("a positive noise has a reach");
        assert!((r.small_band_percent_of_span - SMALL * 0.1).abs() < 1e-12);
        assert!((r.large_band_percent_of_span - LARGE * 0.1).abs() < 1e-12);
        // OP on a 0-1 scale: the same noise is ten per cent of span
        req.op_range = [0.0, 1.0];
        let r = Reach::new(0.1, &req).expect("a positive noise has a reach");
        assert!((r.op_noise_percent_of_span - 10.0).abs() < 1e-9);
        assert!(Reach::new(0.0, &req).is_none());
        assert!(Reach::new(f64::NAN, &req).is_none());
    }
}
