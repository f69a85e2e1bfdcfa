//! The shape family: the literature's stiction indices read the shape and phase of an oscillation
//! (Horch's cross-correlation or, for integrating loops, his second-difference histogram; He et
//! al.'s curve fitting; harmonics; Hägglund's shape index; Choudhury's bicoherence, reported only).
//! They judge an oscillating stretch with a constant setpoint; without an oscillation this family
//! abstains (no oscillation is not "no stiction": the other families judge such records).
//!
//! A vote against stiction from curve fitting or harmonics says the cycle is near-sinusoidal,
//! which a sticky valve behind a slow process or a fast PI loop also gives: it is held weakly.

use super::{Context, EvidenceFamily, Family, FamilyEvidence};
use crate::detect::{self, CrossCorrelation, ShapeIndex};
use crate::diagnose::oscillation::{mean, noise_std, smooth};
use crate::diagnose::result::{Index, Oscillation, Vote};
use crate::spectral::{self, BicoherenceSettings};

/// The shape family.
pub struct Shape;

impl EvidenceFamily for Shape {
    fn family(&self) -> Family {
        Family::Shape
    }

    fn evaluate(&self, ctx: &Context) -> FamilyEvidence {
        let osc = &ctx.oscillation;
        let threshold = format!(
            "read by the verdict's model: the indices' weighted vote, -1 (sinusoidal) to 1 (a sticky valve's shape), not read where PV is compressed in over \
             {:.0} % of the oscillating stretch and the shape points to a valve",
            100.0 * ctx.req.limits.repeated_share
        );
        let statistic = "weighted vote of the shape indices (-1 none, +1 stiction)";
        let periods = osc.periods_in_record.unwrap_or(0.0);
        if !osc.oscillating || periods < ctx.req.min_periods {
            let _ = ctx.indices.set(Vec::new());
            let why = if !osc.oscillating {
                format!(
                    "no oscillation above the noise on the longest constant-setpoint stretch (regularity {}, amplitude {:.3} vs noise {:.3})",
                    osc.regularity.shown(), osc.amplitude, osc.noise_std
                )
            } else {
                format!(
                    "only {periods:.1} oscillation periods (of {:.0} s) {}; the indices need {}",
                    osc.period.unwrap_or(0.0),
                    if osc.across_setpoint_steps {
                        "across the setpoint's steps"
                    } else {
                        "with a constant setpoint"
                    },
                    ctx.req.min_periods
                )
            };
            return FamilyEvidence::abstains(Family::Shape, statistic, threshold, why);
        }
        let [s, e] = osc.stretch;
        let idx = indices(
            &ctx.op[s..e],
            &ctx.pv[s..e],
            &ctx.error[s..e],
            osc,
            ctx.req.ts,
            ctx.integrating,
        );
        let (_, score, _) = combine(&idx, ctx.req.verdict_margin);
        // a compressed PV (repeats, or exactly straight lines between stored points, in more of
        // the stretch than the quality gate allows) is the historian's drawing: the kinks and
        // ramps the indices read as a valve's are the compression's, and a shape that points to a
        // valve is not read (one that points away still is: compression makes a cycle look less
        // sinusoidal, not more)
        let compressed = ctx.unrecorded_share(s, e);
        let drawn = score > 0.0 && compressed > ctx.req.limits.repeated_share;
        let note = idx
            .iter()
            .filter(|i| i.weight > 0.0 && (i.only_votes.is_none() || i.vote != Vote::Undetermined))
            .map(|i| {
                format!(
                    "{} {}",
                    i.name,
                    match i.vote {
                        Vote::Stiction => "stiction",
                        Vote::NoStiction => "none",
                        Vote::Undetermined => "undetermined",
                    }
                )
            })
            .collect::<Vec<_>>()
            .join(", ");
        let _ = ctx.indices.set(idx);
        FamilyEvidence {
            family: Family::Shape,
            vote: Vote::Undetermined,
            strength: 0.0,
            contribution: None,
            value: (!drawn).then_some(score),
            statistic: statistic.into(),
            threshold,
            note: format!(
                "oscillation of period {:.1} s, regularity {}: {note}{}",
                osc.period.unwrap_or(0.0),
                osc.regularity.shown(),
                if drawn {
                    format!(
                        "; but PV repeats itself or runs in exactly straight lines in {:.0} % of the oscillating stretch (historian compression): \
                         the shape the indices read is the compression's, so it is not read",
                        100.0 * compressed
                    )
                } else {
                    String::new()
                }
            ),
            leans: None,
            model: None,
            stick_slip: None,
            valve: None,
            limit_cycle: None,
            hidden_valve: None,
        }
    }
}

/// Horch (2000), integrating loops: the histogram of the second difference of the (smoothed) PV
/// has one peak for stiction (the PV rises and falls in straight lines with kinks) and two peaks
/// for a sinusoid. Sarle's bimodality coefficient (skew² + 1) / kurtosis tells them apart: 5/9
/// for a uniform distribution, 2/3 for a sinusoid's, 1/3 for a Gaussian's.
pub fn ddpv_bimodality(pv: &[f64], smooth_over: usize) -> Option<f64> {
    let y = smooth(pv, smooth_over);
    let y = smooth(&y, smooth_over);
    let dd: Vec<f64> = y.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
    if dd.len() < 20 {
        return None;
    }
    let m = mean(&dd);
    let (mut m2, mut m3, mut m4) = (0.0, 0.0, 0.0);
    for v in &dd {
        let c = v - m;
        m2 += c * c;
        m3 += c * c * c;
        m4 += c * c * c * c;
    }
    let k = dd.len() as f64;
    let (m2, m3, m4) = (m2 / k, m3 / k, m4 / k);
    if m2 <= 0.0 {
        return None;
    }
    let skew = m3 / m2.powf(1.5);
    let kurt = m4 / (m2 * m2);
    Some((skew * skew + 1.0) / kurt)
}

fn horch_index(c: &CrossCorrelation) -> Index {
    Index {
        name: "cross_correlation".into(),
        reference: "Horch (1999): OP-PV cross-correlation, odd for stiction".into(),
        value: c.oddness,
        threshold: format!(
            "stiction above {:.3}, none below {:.3} (oddness of the first zero crossings)",
            c.stiction_above, c.no_stiction_below
        ),
        vote: c.vote,
        weight: 1.0,
        only_votes: None,
        note: match c.oddness {
            None => "no zero crossing on both sides of lag 0".into(),
            Some(_) => format!(
                "first zero crossings at {} s and {} s",
                c.tau_left.map_or("-".into(), |v| format!("{v:.1}")),
                c.tau_right.map_or("-".into(), |v| format!("{v:.1}"))
            ),
        },
    }
}

struct ShapeRow<'a> {
    name: &'a str,
    reference: &'a str,
    threshold: String,
    weight: f64,
    only_votes: Option<Vote>,
    on: &'a str,
}

fn shape_row(s: &ShapeIndex, row: ShapeRow) -> Index {
    Index {
        name: row.name.into(),
        reference: row.reference.into(),
        value: s.value.is_finite().then_some(s.value),
        threshold: row.threshold,
        vote: s.vote,
        weight: row.weight,
        only_votes: row.only_votes,
        note: if s.half_cycles < 4 {
            format!("only {} usable half cycles of {}", s.half_cycles, row.on)
        } else {
            format!("{} half cycles of {}", s.half_cycles, row.on)
        },
    }
}

/// The indices of one oscillating stretch.
pub fn indices(
    op: &[f64],
    pv: &[f64],
    error: &[f64],
    osc: &Oscillation,
    ts: f64,
    integrating: bool,
) -> Vec<Index> {
    let period_samples = osc
        .period
        .map_or(op.len() / 4, |p| (p / ts).round() as usize);
    let mut out = Vec::new();
    // noise-free shapes: a moving average over a twentieth of a period
    let w = (period_samples / 20).max(1);
    if integrating {
        let value = ddpv_bimodality(pv, w);
        let vote = match value {
            Some(b) if b < 0.4 => Vote::Stiction,
            Some(b) if b > 0.555 => Vote::NoStiction,
            _ => Vote::Undetermined,
        };
        out.push(Index {
            name: "ddpv_histogram".into(),
            reference: "Horch (2000): histogram of the second difference of PV, integrating loops"
                .into(),
            value,
            threshold: "bimodality coefficient: one peak (stiction) below 0.4, two peaks (sinusoid) above 0.555".into(),
            vote,
            weight: 1.0,
            only_votes: None,
            note: format!("PV smoothed over {w} samples"),
        });
    } else {
        let c = detect::horch(op, pv, ts, period_samples.max(10).min(op.len() / 2));
        out.push(horch_index(&c));
    }
    out.push(bicoherence_index(error));
    let op_s = smooth(op, w);
    let pv_s = smooth(pv, w);
    let e_s = smooth(error, w);
    let (cf_signal, cf_name, cf_raw) = if integrating {
        (&pv_s, "PV", pv)
    } else {
        (&op_s, "OP", op)
    };
    let hysteresis = 2.0 * noise_std(cf_raw).max(1e-12);
    let cf = detect::curve_fitting_index(cf_signal, hysteresis);
    out.push(shape_row(
        &cf,
        ShapeRow {
            name: "curve_fitting",
            reference: "He et al. (2007): sine vs triangle fits per half cycle",
            threshold: format!(
                "stiction at {} and above, none at {} and below",
                cf.stiction_above, cf.no_stiction_below
            ),
            weight: 1.0,
            only_votes: None,
            on: cf_name,
        },
    ));
    let mut shape = detect::shape_index(&e_s, 2.0 * osc.noise_std.max(1e-12));
    // a square-like error needs a fast process (Hägglund's flow loops); a sine-like one is what
    // stiction gives behind a slow process too, so it confirms stiction and never rules it out
    if shape.vote == Vote::NoStiction {
        shape.vote = Vote::Undetermined;
    }
    out.push(harmonics_index(op, pv, osc, ts));
    out.push(shape_row(
        &shape,
        ShapeRow {
            name: "shape",
            reference: "Hägglund (2011): sine vs square fits of the control error per half period",
            threshold:
                "square-like (stiction) above 0; sine-like (0 or below) does not rule stiction out"
                    .into(),
            weight: 0.5,
            only_votes: Some(Vote::Stiction),
            on: "the control error",
        },
    ));
    out
}

/// Harmonics below this share of the fundamental's power, in OP and in PV, make an oscillation
/// sinusoidal: less than a triangle wave's 1/81 + 1/625 = 0.014.
pub(super) const SINUSOIDAL_HARMONICS: f64 = 0.01;

/// A sticky valve moves in jumps, which put harmonics of the oscillation into MV and so into PV
/// and, through the controller, OP (the effect the bicoherence test looks for through phase
/// coupling; measured here directly as power). An oscillation that is sinusoidal in both OP and
/// PV is a linear one (tuning, an external disturbance): the index then votes "no stiction". It
/// never votes "stiction": noise, other non-linearities and aggressive tuning add harmonics too.
fn harmonics_index(op: &[f64], pv: &[f64], osc: &Oscillation, ts: f64) -> Index {
    let f0 = osc.period.map(|p| ts / p);
    let h_op = f0.and_then(|f| spectral::harmonic_distortion(op, f, 5));
    let h_pv = f0.and_then(|f| spectral::harmonic_distortion(pv, f, 5));
    let value = match (h_op, h_pv) {
        (Some(a), Some(b)) => Some(a.max(b)),
        _ => None,
    };
    let vote = match value {
        Some(h) if h < SINUSOIDAL_HARMONICS => Vote::NoStiction,
        _ => Vote::Undetermined,
    };
    Index {
        name: "harmonics".into(),
        reference: "harmonic distortion of the oscillation (a valve's jumps put harmonics into OP and PV; cf. Choudhury, Shah and Thornhill 2004)".into(),
        value,
        threshold: format!(
            "sinusoidal (no stiction) when harmonics 2 to 5 carry less than {} of the fundamental's power in both OP and PV (a triangle wave: 0.014); never votes stiction",
            SINUSOIDAL_HARMONICS
        ),
        vote,
        weight: 1.0,
        only_votes: Some(Vote::NoStiction),
        note: match (h_op, h_pv) {
            (Some(a), Some(b)) => format!("OP {a:.4}, PV {b:.4} of the fundamental's power; value shown: the larger"),
            _ => "no period, fewer than 2 periods, or a period too short for 5 harmonics below the Nyquist frequency (under 11 samples)".into(),
        },
    }
}

/// Choudhury, Shah and Thornhill (2004): the squared bicoherence of the control error; a
/// non-Gaussian (NGI) and non-linear (NLI) error points to a non-linearity in the loop, most often
/// the valve; a Gaussian one to a linear cause. Reported with its vote but weight 0: on our
/// benchmark (stiction-lab/results/diagnose-benchmark.md) it did not separate stiction from other
/// causes.
fn bicoherence_index(error: &[f64]) -> Index {
    let settings = BicoherenceSettings::default();
    let b = spectral::bicoherence(error, &settings);
    let reference = "Choudhury, Shah and Thornhill (2004): bicoherence of the control error".into();
    let threshold = format!(
        "non-Gaussian when NGI > {}, then non-linear (stiction-like) when NLI > {}; Gaussian: linear cause",
        settings.ngi_threshold, settings.nli_threshold
    );
    match b {
        None => Index {
            name: "bicoherence".into(),
            reference,
            value: None,
            threshold,
            vote: Vote::Undetermined,
            weight: 0.0,
            only_votes: None,
            note: format!("too few samples for {} segments", spectral::MIN_SEGMENTS),
        },
        Some(b) => Index {
            name: "bicoherence".into(),
            reference,
            value: Some(b.ngi),
            threshold,
            vote: if b.non_linear {
                Vote::Stiction
            } else if !b.non_gaussian {
                Vote::NoStiction
            } else {
                Vote::Undetermined
            },
            weight: 0.0,
            only_votes: None,
            note: format!(
                "NGI {:.4}, NLI {:.3} ({} segments of {}); value shown: NGI; not counted in the verdict",
                b.ngi, b.nli, b.segments, b.segment_length
            ),
        },
    }
}

/// The indices' weighted vote (+1 stiction, -1 none, 0 undetermined): the family's vote, the
/// score, and the weighted share of the indices that vote for it.
pub fn combine(indices: &[Index], margin: f64) -> (Vote, f64, f64) {
    // a one-sided index that does not cast its vote is silent by design: not counted
    let counted = |i: &&Index| i.only_votes.is_none() || i.vote != Vote::Undetermined;
    let total: f64 = indices.iter().filter(counted).map(|i| i.weight).sum();
    if total <= 0.0 {
        return (Vote::Undetermined, 0.0, 0.0);
    }
    let score: f64 = indices
        .iter()
        .map(|i| i.weight * i.vote.sign())
        .sum::<f64>()
        / total;
    let vote = if score >= margin {
        Vote::Stiction
    } else if score <= -margin {
        Vote::NoStiction
    } else {
        Vote::Undetermined
    };
    let support = indices
        .iter()
        .filter(|i| i.vote == vote && vote != Vote::Undetermined)
        .map(|i| i.weight)
        .sum::<f64>()
        / total;
    (vote, score, support)
}
