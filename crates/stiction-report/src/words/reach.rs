//! What a record like this one can show of a sticky valve, in words (the core's calibration
//! stays in its fields; the words quote the record's figures only).

use super::figures::{fig, fig2};
use stiction_core::diagnose::Reach;

/// One sentence: the bands OP's noise hides and the bands a record like this one shows.
pub fn reach(r: &Reach) -> String {
    let times = |band: f64| {
        (r.op_noise_percent_of_span > 0.0).then(|| fig(band / r.op_noise_percent_of_span))
    };
    let small = times(r.small_band_percent_of_span).unwrap_or_default();
    let large = times(r.large_band_percent_of_span).unwrap_or_default();
    format!(
        "a sticky valve with a band under {} % of span ({small} times OP's noise, a standard deviation of {} %) often passes for OP's noise in a record like this one; one over {} % ({large} times) mostly shows",
        fig2(r.small_band_percent_of_span),
        fig2(r.op_noise_percent_of_span),
        fig2(r.large_band_percent_of_span),
    )
}
