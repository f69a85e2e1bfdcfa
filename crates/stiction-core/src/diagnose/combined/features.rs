//! The statistics the combination reads: what the families measured, as numbers, in one order.
//! Each is taken as the families report it (a missing one reads 0, a shape index not computed
//! `NOT_COMPUTED`); counts, ratios and spans that run over decades are read on a signed log
//! scale.

use crate::diagnose::evidence::{Family, FamilyEvidence};
use crate::diagnose::result::{Index, Oscillation};

/// What the combination reads of one judged stretch besides the families.
pub struct Stretch<'a> {
    /// The families' evidence.
    pub families: &'a [FamilyEvidence],
    /// The oscillation found.
    pub oscillation: &'a Oscillation,
    /// The shape family's indices (none where the stretch does not oscillate).
    pub indices: &'a [Index],
    /// OP's noise standard deviation (OP units), as the reach reads it
    /// (`diagnose::reach::op_noise`).
    pub op_noise: f64,
    /// Sampling time, seconds.
    pub ts: f64,
    /// Samples judged.
    pub samples: usize,
}

/// How a statistic is read: as it is, on a signed log scale, as a natural log, or a vote.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// As it is.
    Plain,
    /// `sign(x) ln(1 + |x|)`: counts, ratios and spans over decades.
    SignedLog,
    /// `ln(x)`: the sampling time and the samples.
    Ln,
    /// A family's vote: +1 stiction, -1 none, 0 undetermined.
    Vote,
    /// A shape index's value as it is, `NOT_COMPUTED` where it could not be computed.
    Index,
}

/// What a shape index reads where it was not computed (below every index's range).
pub(super) const NOT_COMPUTED: f64 = -9.0;

impl Scale {
    /// A value read on this scale, back on its own.
    pub fn undo(self, v: f64) -> f64 {
        match self {
            Scale::SignedLog => v.signum() * v.abs().exp_m1(),
            Scale::Ln => v.exp(),
            Scale::Plain | Scale::Vote | Scale::Index => v,
        }
    }
}

/// The statistics' names (the trees' inputs, in order), each in words, and how it is read.
pub(super) const NAMES: [(&str, &str, Scale); COUNT] = [
    (
        "model_test_ratio",
        "the closed-loop fit's test ratio",
        Scale::SignedLog,
    ),
    (
        "model_improvement",
        "the fit's improvement with stiction",
        Scale::Plain,
    ),
    (
        "model_explained",
        "the share of PV the stiction fit explains",
        Scale::Plain,
    ),
    ("model_r2_linear", "the linear loop's R²", Scale::Plain),
    ("model_r2_stenman", "Stenman's fit's R²", Scale::Plain),
    ("model_r2_slip_jump", "the slip-jump fit's R²", Scale::Plain),
    ("model_loop_gain", "the fitted loop gain", Scale::Plain),
    (
        "model_noise_share",
        "the noise's share of PV's changes",
        Scale::Plain,
    ),
    (
        "model_correlation_span",
        "the fits' correlation span",
        Scale::SignedLog,
    ),
    (
        "model_band_over_op_noise",
        "the fitted band over OP's noise",
        Scale::SignedLog,
    ),
    (
        "model_slip_band_over_op_noise",
        "the slip-jump band over OP's noise",
        Scale::SignedLog,
    ),
    (
        "model_slip_over_band",
        "the fitted slip jump over its band",
        Scale::Plain,
    ),
    (
        "stick_slip_episodes",
        "the stick-slip episodes",
        Scale::SignedLog,
    ),
    (
        "stick_slip_stuck_share",
        "the share of OP's travel spent stuck",
        Scale::Plain,
    ),
    (
        "stick_slip_travel_over_op_noise",
        "OP's travel per stick over its noise",
        Scale::SignedLog,
    ),
    (
        "stick_slip_quiet_stretches",
        "the stretches of quiet PV",
        Scale::SignedLog,
    ),
    ("shape_score", "the shape indices' score", Scale::Plain),
    ("shape_vote", "the shape family's vote", Scale::Vote),
    (
        "loop_needed_lag",
        "the valve lag the loop needs",
        Scale::Plain,
    ),
    ("loop_vote", "the loop family's vote", Scale::Vote),
    ("model_vote", "the closed-loop fit's vote", Scale::Vote),
    ("stick_slip_vote", "the stick-slip vote", Scale::Vote),
    ("oscillating", "an oscillation", Scale::Plain),
    (
        "regularity",
        "the oscillation's regularity",
        Scale::SignedLog,
    ),
    (
        "periods_in_record",
        "the periods in the record",
        Scale::SignedLog,
    ),
    (
        "amplitude_over_noise",
        "the oscillation's amplitude over the noise",
        Scale::SignedLog,
    ),
    ("log_ts", "the sampling time", Scale::Ln),
    ("log_samples", "the samples judged", Scale::Ln),
    (
        "loop_gain_margin",
        "the linear loop's gain margin",
        Scale::Plain,
    ),
    (
        "loop_residual_share",
        "PV's cycle OP does not explain",
        Scale::Plain,
    ),
    ("loop_harmonics", "the cycle's harmonics", Scale::SignedLog),
    (
        "loop_amplitude_scatter",
        "the cycle's amplitude scatter",
        Scale::Plain,
    ),
    (
        "loop_amplitude_change",
        "the cycle's amplitude change",
        Scale::SignedLog,
    ),
    (
        "loop_phase_wander",
        "the cycle's phase wander",
        Scale::SignedLog,
    ),
    (
        "loop_needed_gain",
        "the valve gain the loop needs",
        Scale::Plain,
    ),
    (
        "loop_describing_distance",
        "the describing function's distance",
        Scale::SignedLog,
    ),
    (
        "model_cycle_cancelled_ratio",
        "the fits' test ratio over whole periods",
        Scale::SignedLog,
    ),
    (
        "loop_controller_residual",
        "OP the identified PI does not explain",
        Scale::Plain,
    ),
    (
        "loop_op_at_limit",
        "OP at a limit in the cycle",
        Scale::Plain,
    ),
    (
        "cross_correlation",
        "the cross-correlation index",
        Scale::Index,
    ),
    ("curve_fitting", "the curve-fitting index", Scale::Index),
    ("harmonics", "the harmonics index", Scale::Index),
    ("shape", "Hägglund's shape index", Scale::Index),
    ("bicoherence", "the bicoherence index", Scale::Index),
    (
        "ddpv_histogram",
        "the histogram index of PV's second difference",
        Scale::Index,
    ),
];

/// How many statistics the combination reads.
pub const COUNT: usize = 45;

/// The shape indices the combination reads, by their names in [`NAMES`] (the last six).
const INDICES: usize = 6;

/// A shape index's value by name, [`NOT_COMPUTED`] where missing.
fn index(indices: &[Index], name: &str) -> f64 {
    indices
        .iter()
        .find(|i| i.name == name)
        .and_then(|i| i.value)
        .filter(|v| v.is_finite())
        .unwrap_or(NOT_COMPUTED)
}

/// A count or ratio over decades, on a signed log scale.
fn slog(x: f64) -> f64 {
    x.signum() * x.abs().ln_1p()
}

fn family(families: &[FamilyEvidence], f: Family) -> Option<&FamilyEvidence> {
    families.iter().find(|e| e.family == f)
}

fn vote(families: &[FamilyEvidence], f: Family) -> f64 {
    family(families, f).map_or(0.0, |e| e.vote.sign())
}

/// The statistics of one judged stretch, in `NAMES`' order (every one finite).
pub fn of(s: &Stretch) -> [f64; COUNT] {
    let fams = s.families;
    let model = family(fams, Family::Model).and_then(|f| f.model.as_ref());
    let stick = family(fams, Family::StickSlip).and_then(|f| f.stick_slip.as_ref());
    let cycle = family(fams, Family::Loop).and_then(|f| f.limit_cycle.as_ref());
    let value = |f: Family| family(fams, f).and_then(|e| e.value).unwrap_or(0.0);
    let op_noise = s.op_noise.max(1e-6);
    let m = |g: &dyn Fn(&crate::diagnose::evidence::ModelEvidence) -> f64| model.map_or(0.0, g);
    let st =
        |g: &dyn Fn(&crate::diagnose::evidence::StickSlipEvidence) -> f64| stick.map_or(0.0, g);
    let lc = |g: &dyn Fn(&crate::diagnose::evidence::LoopEvidence) -> f64| cycle.map_or(0.0, g);
    let amp = |g: &dyn Fn(&crate::loop_analysis::AmplitudeTrend) -> f64| {
        cycle.and_then(|c| c.amplitude.as_ref()).map_or(0.0, g)
    };
    let o = s.oscillation;
    let x: [f64; COUNT - INDICES] = [
        m(&|e| slog(e.significance)),
        m(&|e| e.improvement),
        m(&|e| e.explained),
        m(&|e| e.r2_without_stiction),
        m(&|e| e.r2_stenman),
        m(&|e| e.r2_slip_jump),
        m(&|e| e.loop_gain.unwrap_or(0.0)),
        m(&|e| e.noise_share),
        m(&|e| slog(e.correlation_span)),
        m(&|e| slog(e.stenman_d / op_noise)),
        m(&|e| slog(e.kano_s / op_noise)),
        m(&|e| e.kano_j / e.kano_s.max(1e-9)),
        st(&|e| slog(e.episodes as f64)),
        st(&|e| e.stuck_share),
        st(&|e| e.median_travel.map_or(0.0, |t| slog(t / op_noise))),
        st(&|e| slog(e.quiet_stretches as f64)),
        value(Family::Shape),
        vote(fams, Family::Shape),
        value(Family::Loop),
        vote(fams, Family::Loop),
        vote(fams, Family::Model),
        vote(fams, Family::StickSlip),
        if o.oscillating { 1.0 } else { 0.0 },
        slog(o.regularity.regularity),
        o.periods_in_record.map_or(0.0, slog),
        slog(o.amplitude / o.noise_std.max(1e-9)),
        s.ts.max(1e-3).ln(),
        (s.samples.max(1) as f64).ln(),
        lc(&|e| e.margins.gain_margin.unwrap_or(0.0)),
        lc(&|e| e.residual_share),
        lc(&|e| e.harmonics.map_or(0.0, slog)),
        amp(&|a| a.scatter),
        amp(&|a| slog(a.change)),
        lc(&|e| e.phase_wander.map_or(0.0, slog)),
        lc(&|e| e.needed_gain),
        slog(
            cycle
                .and_then(|c| c.describing.as_ref())
                .map_or(9.0, |d| d.distance),
        ),
        m(&|e| {
            e.cycle_cancelled
                .as_ref()
                .map_or(0.0, |c| slog(c.significance))
        }),
        lc(&|e| e.controller_residual_share),
        lc(&|e| e.op_at_limit),
    ];
    let mut all = [0.0; COUNT];
    all[..COUNT - INDICES].copy_from_slice(&x);
    for (v, (name, ..)) in all[COUNT - INDICES..]
        .iter_mut()
        .zip(&NAMES[COUNT - INDICES..])
    {
        *v = index(s.indices, name);
    }
    all.map(|v| if v.is_finite() { v } else { 0.0 })
}
