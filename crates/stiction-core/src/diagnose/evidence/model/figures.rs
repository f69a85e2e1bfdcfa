//! The fits' figures as the result reports them, and the words of the family's note on them.

use super::Levels;
use crate::diagnose::evidence::Context;
use crate::identify::Structure;
use crate::quantify::{FitComparison, OverLag};
use serde::{Deserialize, Serialize};

/// The fits behind the model family's vote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelEvidence {
    /// The linear structure the fits share, as a model of the PV (integrating for a level).
    pub structure: Structure,
    /// What the fits see of the valve over the lag: its change, or for an integrating process
    /// its position summed over the lag (the level's inflow).
    #[serde(default)]
    pub over_lag: OverLag,
    /// R² in simulation of the output (PV, or its change for an integrating structure).
    pub r2_without_stiction: f64,
    /// R² in simulation of the output with Stenman's valve.
    pub r2_stenman: f64,
    /// R² in simulation of the output with Kano's valve (a band S and a slip jump J of its own).
    pub r2_slip_jump: f64,
    /// Stenman's band, OP units and % of span.
    pub stenman_d: f64,
    /// Stenman's band, % of valve span.
    pub stenman_d_percent_of_span: f64,
    /// Kano's band S and slip jump J, OP units.
    pub kano_s: f64,
    /// Kano's slip jump J, OP units.
    pub kano_j: f64,
    /// The improvement of the better stiction fit over the linear loop, share of the output's
    /// variance above its noise.
    pub improvement: f64,
    /// The calibrated test's ratio: the improvement over the stiction fit's residual per
    /// independent change (samples over `correlation_span`).
    pub significance: f64,
    /// The samples one independent change spans in the test: the long-run overlap of the
    /// stiction fit's residual with the change the band makes to the fit (about the lag for
    /// noise; more where both share a cycle OP does not drive).
    pub correlation_span: f64,
    /// Share of the PV's variance above its noise explained with stiction.
    pub explained: f64,
    /// Share of the output's variance that is noise.
    pub noise_share: f64,
    /// Gain of the linear part fitted with the best stiction model (PV units per OP unit; per
    /// second for an integrating process).
    pub gain: Option<f64>,
    /// Its time constant, seconds.
    pub time_constant: Option<f64>,
    /// Its dead time, seconds.
    pub dead_time: f64,
    /// The comparison behind the shares: samples compared, the lag of the changes compared
    /// (samples), their sum of squares, the linear loop's and the best stiction model's simulation
    /// error, and the measurement noise's expected share of them.
    pub samples: usize,
    /// The lag of the changes compared, samples.
    pub lag: usize,
    /// Where the fitted valve stood at the first sample (OP units).
    pub valve_start: f64,
    /// Sum of squares of the centred compared output.
    pub sst: f64,
    /// Simulation error (sum of squares) of the linear loop (a valve that follows OP).
    pub sse_linear: f64,
    /// Simulation error (sum of squares) of the better stiction model.
    pub sse_stiction: f64,
    /// The measurement noise's expected sum of squares over the samples compared.
    pub sse_noise: f64,
    /// The lag's bound (samples), when the lag reached it and the comparison over a third of it,
    /// which `lag` then gives, had the higher test ratio.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lag_bound: Option<usize>,
    /// The test could judge the record: enough independent changes, and PV varying above its
    /// noise (otherwise the verdict's model does not read the fit).
    pub judged: bool,
}

impl ModelEvidence {
    /// Whether the stiction fits found explain PV better than the linear loop. A valve with no
    /// band is a sticky valve too, so the best stiction model is never worse than the linear
    /// loop; where the band search settles below it (about one record in seven of the plant
    /// benchmark's catalogue), no band fits better, and the test counts no gain.
    pub fn band_fits_better(&self) -> bool {
        self.r2_stenman.max(self.r2_slip_jump) > self.r2_without_stiction
    }
}

/// The fits' R² in words, with Stenman's band and Kano's S and J in % of span; where no band
/// found fits better than the linear loop, it says so ([`ModelEvidence::band_fits_better`]).
pub(super) fn fits_words(ctx: &Context, f: &FitComparison, evidence: &ModelEvidence) -> String {
    let pct = |v: f64| ctx.req.percent_of_span(v);
    format!(
        "{}{:.3} with Stenman's band (d = {:.2} % of span), {:.3} with a slip jump (Kano S = {:.2}, J = {:.2} % of span){}",
        if evidence.band_fits_better() {
            format!("R² {:.3} without stiction, ", f.linear.r2)
        } else {
            format!(
                "R² {:.3} without stiction, and no band found fits better (the search's best: ",
                f.linear.r2
            )
        },
        f.stenman.r2,
        pct(f.stenman.params[0]),
        f.slip_jump.r2,
        pct(evidence.kano_s),
        pct(evidence.kano_j),
        if evidence.band_fits_better() { "" } else { ")" }
    ) + &ctx.lag_bound.map_or(String::new(), |b| {
        format!(
            "; PV's changes compared over {} samples, a third of the bound of {b} the lag reached (the stronger of the two comparisons)",
            f.lag
        )
    }) + &inflow_words(f)
}

/// For a level, a clause saying how the fits see it: its changes over the lag against the
/// valve's position summed over them, and the integration rate found.
fn inflow_words(f: &FitComparison) -> String {
    match (f.over_lag, f.gain) {
        (OverLag::Sum, Some(k)) => format!(
            "; a level: its changes over {} samples fitted to the valve's position summed over them (its inflow), \
             integration rate {k:.3e} per s per OP unit",
            f.lag
        ),
        (OverLag::Sum, None) => format!(
            "; a level: its changes over {} samples fitted to the valve's position summed over them (its inflow)",
            f.lag
        ),
        (OverLag::Change, _) => String::new(),
    }
}

/// The fits' figures, as the result reports them.
pub(super) fn model_evidence(ctx: &Context, f: &FitComparison, levels: &Levels) -> ModelEvidence {
    let Levels {
        noise_share,
        improvement,
        significance,
        explained,
    } = *levels;
    let d = f.stenman.params[0];
    ModelEvidence {
        structure: f.structure,
        over_lag: f.over_lag,
        r2_without_stiction: f.linear.r2,
        r2_stenman: f.stenman.r2,
        r2_slip_jump: f.slip_jump.r2,
        stenman_d: d,
        stenman_d_percent_of_span: ctx.req.percent_of_span(d),
        kano_s: f.slip_jump.params[0],
        kano_j: f.slip_jump.params[1],
        improvement,
        significance,
        correlation_span: f.correlation_span,
        explained,
        noise_share,
        gain: f.gain,
        time_constant: f.time_constant,
        dead_time: f.dead_time,
        samples: f.samples_used,
        lag: f.lag,
        valve_start: f.valve_start,
        sst: f.sst,
        sse_linear: f.linear.sse,
        sse_stiction: f.stenman.sse.min(f.slip_jump.sse),
        sse_noise: f.samples_used as f64 * f.noise_var,
        lag_bound: ctx.lag_bound,
        judged: true,
    }
}
