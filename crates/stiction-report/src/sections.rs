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

#[derive(Serialize)]
pub struct FamilyRow {
    pub family: &'static str,
    pub value: String,
    pub vote: Chip,
    pub statistic: String,
    pub threshold: String,
    pub note: String,
}

#[derive(Serialize)]
pub struct IndexRow {
    pub name: String,
    pub value: String,
    pub vote: Chip,
    pub threshold: String,
    pub weight: String,
    pub reference: String,
    pub note: String,
}

#[derive(Serialize)]
pub struct Evidence {
    pub families: Vec<FamilyRow>,
    pub indices: Vec<IndexRow>,
    /// Why no index was computed, when none was.
    pub no_index: Option<&'static str>,
}

pub fn evidence(d: &Diagnosis) -> Evidence {
    let families = d
        .families
        .iter()
        .map(|f| FamilyRow {
            family: f.family.words(),
            value: opt(f.value),
            vote: vote_chip(f.vote),
            statistic: f.statistic.clone(),
            threshold: f.threshold.clone(),
            note: f.note.clone(),
        })
        .collect();
    let indices = d
        .indices
        .iter()
        .map(|i| IndexRow {
            name: i.name.clone(),
            value: opt(i.value),
            vote: vote_chip(i.vote),
            threshold: i.threshold.clone(),
            weight: num(i.weight),
            reference: i.reference.clone(),
            note: i.note.clone(),
        })
        .collect();
    let no_index = d.indices.is_empty().then_some(match d.verdict {
        Verdict::InsufficientData => "the record cannot carry a verdict (see the reason above)",
        _ => "the loop does not oscillate regularly with a constant setpoint, so there is no shape for them to read",
    });
    Evidence {
        families,
        indices,
        no_index,
    }
}

pub fn oscillation(d: &Diagnosis) -> Option<Vec<KvRow>> {
    let o = d.oscillation.as_ref()?;
    let r = &o.regularity;
    Some(vec![
        kv(
            "Oscillating",
            if o.oscillating && o.across_setpoint_steps {
                "yes: regular and above the noise, across the setpoint's steps (no hold is long enough)"
                    .to_string()
            } else if o.oscillating {
                "yes: regular and above the noise".to_string()
            } else {
                "no".into()
            },
        ),
        kv("Period", o.period.map_or("–".into(), duration)),
        kv("Periods in the analysed stretch", opt(o.periods_in_record)),
        kv(
            "Share of the error's variance in the cycle",
            o.cycle_share.map_or("–".into(), |c| format!("{:.0} %", 100.0 * c.max(0.0))),
        ),
        kv(
            "Regularity (Thornhill)",
            format!(
                "{} (regular above {}; {} zero crossings of the autocorrelation)",
                num(r.regularity),
                num(r.threshold),
                r.zero_crossings
            ),
        ),
        kv(
            "Half periods with a large IAE (Hägglund)",
            format!(
                "{} in the record, at most {} in one supervision window of {} (limit {}; IAE limit {})",
                o.iae.exceedances,
                o.iae.most_in_window,
                duration(o.iae.window),
                o.iae.n_lim,
                num(o.iae.iae_limit)
            ),
        ),
        kv(
            "Amplitude of the control error",
            format!("{} (half the 5 %–95 % range)", num(o.amplitude)),
        ),
        kv("Noise standard deviation", num(o.noise_std)),
    ])
}

#[derive(Serialize)]
pub struct Estimates {
    pub rows: Vec<KvRow>,
    /// The optimal set is exact: say what it means.
    pub exact_set: bool,
    pub model: Option<Vec<KvRow>>,
}

fn band_value(d: &Diagnosis) -> Rich {
    let failed = d.warnings.iter().any(|w| w.contains("estimate failed"));
    if let Some(b) = &d.band {
        let mut r = Rich::default()
            .strong(format!("{} % of valve span", num(b.band_percent_of_span)))
            .text(format!(
                " ({} OP units), {}",
                num(b.op_units),
                b.source.words()
            ));
        if let Some([lo, hi]) = b.interval_percent_of_span {
            r = r.text(format!("; optimal set {} to {} %", num(lo), num(hi)));
        }
        if b.source != BandSource::Valve && d.quantification.is_none() && !failed {
            r = r
                .text(" (the exact closed-loop estimate was not run: ")
                .code("--no-quantify")
                .text(")");
        }
        return r;
    }
    match d.quantification.as_ref() {
        Some(q) if q.status != QuantifyStatus::Ok => rich(format!(
            "not estimated: {}",
            q.reason.as_deref().unwrap_or("insufficient data")
        )),
        _ if d.verdict != Verdict::Stiction => {
            rich("not estimated: the band is sized only when the verdict is stiction")
        }
        _ if failed => rich("not estimated: it failed (see the notes)"),
        _ => rich("not estimated (").code("--no-quantify").text(")"),
    }
}

fn model_rows(q: &Quantification) -> Option<Vec<KvRow>> {
    let lm = q.linear_model.as_ref()?;
    let gain = match (lm.gain, lm.family) {
        (Some(g), LinearFamily::Integrating) => format!("{} per s (integration rate)", num(g)),
        (Some(g), _) => num(g),
        (None, _) => "–".into(),
    };
    let mut rows = vec![
        kv("Family", lm.family.to_string()),
        kv("Orders", format!("na = {}, nb = {} (ARX)", lm.na, lm.nb)),
        kv(
            "Delay",
            format!(
                "{} samples from valve to output (1: the next sample)",
                lm.nk
            ),
        ),
        kv("Gain", gain),
        kv(
            "Time constant",
            lm.time_constant.map_or("–".into(), duration),
        ),
        kv("Dead time", duration(lm.dead_time)),
    ];
    if let Some(f) = &q.fit {
        let what = if f.output == FitOutput::Pv {
            "PV"
        } else {
            "the change of PV per sample"
        };
        rows.push(kv(
            "R² (fit)",
            format!(
                "{} in simulation, {} one step ahead, of {what}",
                num(f.r2_simulation),
                num(f.r2_one_step)
            ),
        ));
    }
    rows.push(kv("Chosen by", lm.criterion.clone()));
    Some(rows)
}

pub fn estimates(d: &Diagnosis, q: Option<&Quantification>) -> Estimates {
    let ellipse = d
        .band
        .as_ref()
        .and_then(|b| b.ellipse_percent_of_span)
        .map_or("not computed".into(), |v| format!("{} % of span", num(v)));
    let mut rows = vec![
        kv("Stiction band", band_value(d)),
        kv("Ellipse fit of the PV-OP plot (Choudhury et al.)", ellipse),
    ];
    if let Some(m) = d.families.iter().find_map(|f| f.model.as_ref()) {
        rows.push(kv(
            "Closed-loop fit with and without stiction",
            format!(
                "R² {} without stiction, {} with a Stenman band of {} % of span, {} with a slip jump (Kano); \
                 the stiction model explains {} % more of the PV's variation above its noise",
                num(m.r2_without_stiction),
                num(m.r2_stenman),
                num(m.stenman_d_percent_of_span),
                num(m.r2_slip_jump),
                num(100.0 * m.improvement)
            ),
        ));
    }
    if let Some(x0) = q.and_then(|q| q.valve_start) {
        let value = rich(format!("{}, ", num(x0)));
        let value = match q.and_then(|q| q.valve_start_kind) {
            Some(ValveStartKind::Estimated) => {
                value.text("estimated (").code("--estimate-start").text(")")
            }
            Some(ValveStartKind::Given) => value.text("given"),
            _ => value
                .text("assumed at the first OP (")
                .code("--estimate-start")
                .text(" estimates it)"),
        };
        rows.push(kv("Valve position at the first sample", value));
    }
    Estimates {
        rows,
        exact_set: q.is_some_and(|q| {
            !q.interval.is_empty()
                && matches!(
                    q.interval_kind,
                    IntervalKind::Exact | IntervalKind::ExactLocal | IntervalKind::ExactStaged
                )
        }),
        model: q.and_then(model_rows),
    }
}

#[derive(Serialize)]
pub struct Convergence {
    pub rows: Vec<KvRow>,
    pub why: &'static str,
}

pub fn convergence(q: &Quantification) -> Convergence {
    let rows = vec![
        kv("Method", format!("{} ({} model)", q.method, q.model)),
        kv("Evaluations", q.evaluations.to_string()),
        kv(
            "Distinct valve trajectories (cells)",
            q.cells.map_or("–".into(), |c| c.to_string()),
        ),
        kv("Time", duration(q.seconds)),
        kv("Samples", format!("{} at {} s", q.samples, num(q.ts))),
    ];
    let why = match q.interval_kind {
        IntervalKind::Exact => {
            "The exact method does not search: the band d changes the estimated valve \
             trajectory only at a finite set of values, so the whole range of d splits into \
             cells with one valve trajectory each; every cell was fitted once. The optimum \
             is proven over every distinct valve trajectory, not found by chance."
        }
        IntervalKind::ExactStaged => {
            "The exact method does not search: the band d changes the estimated valve \
             trajectory only at a finite set of values, so the whole range of d splits into \
             cells with one valve trajectory each. Every cell of the first samples was fitted, \
             then, on the whole record, every cell inside the best of them (each cell of the \
             whole record lies inside one cell of its first samples). The optimum is proven \
             over every distinct valve trajectory kept, not found by chance."
        }
        IntervalKind::ExactLocal => {
            "The exact method fitted every valve trajectory near the best points of a \
             coarse scan: the optimum is proven there only."
        }
        IntervalKind::Grid | IntervalKind::Axis | IntervalKind::None => {
            "A search method: the optimum is the best point found, not proven."
        }
    };
    Convergence { rows, why }
}

#[derive(Serialize)]
pub struct GateRow {
    pub gate: Gate,
    pub passed: bool,
    pub value: String,
    pub limit: String,
    pub message: String,
}

#[derive(Serialize)]
pub struct Quality {
    pub summary: String,
    pub gates: Vec<GateRow>,
}

pub fn quality(d: &Diagnosis) -> Quality {
    let failed = d.quality.iter().filter(|f| !f.passed).count();
    let summary = if failed == 0 {
        format!("Every gate passed ({} checked).", d.quality.len())
    } else {
        format!(
            "{failed} of {} gates failed: the record cannot carry a verdict.",
            d.quality.len()
        )
    };
    let gates = d
        .quality
        .iter()
        .map(|f| GateRow {
            gate: f.gate,
            passed: f.passed,
            value: num(f.value),
            limit: num(f.limit),
            message: f.message.clone(),
        })
        .collect();
    Quality { summary, gates }
}

fn verdict_fill(v: Verdict) -> &'static str {
    match v {
        Verdict::Stiction => "#d9534f",
        Verdict::NoStiction => "#43a047",
        Verdict::Undetermined => "#f0a500",
        Verdict::InsufficientData => "#b7bec5",
    }
}

/// One window's rectangle in the strip (SVG user units of a 1000 × 36 box).
#[derive(Serialize)]
pub struct Strip {
    pub x: String,
    pub width: String,
    pub fill: &'static str,
    pub title: String,
}

#[derive(Serialize)]
pub struct WindowRow {
    pub samples: String,
    pub time: String,
    pub verdict: Chip,
    pub confidence: String,
    pub period: String,
    pub votes: Vec<(&'static str, Chip)>,
    pub reason: String,
}

#[derive(Serialize)]
pub struct Windows {
    pub strip: Vec<Strip>,
    pub legend: Vec<(&'static str, &'static str)>,
    pub reasons: bool,
    pub rows: Vec<WindowRow>,
}

pub fn windows(d: &Diagnosis) -> Option<Windows> {
    if d.windows.is_empty() {
        return None;
    }
    let total = d.samples.max(1) as f64;
    let strip = d
        .windows
        .iter()
        .map(|w| Strip {
            x: format!("{:.1}", 1000.0 * w.start as f64 / total),
            width: format!(
                "{:.1}",
                (1000.0 * (w.end - w.start) as f64 / total - 1.0).max(0.5)
            ),
            fill: verdict_fill(w.verdict),
            title: format!("samples {} to {}: {}", w.start, w.end, verdict(w.verdict)),
        })
        .collect();
    let legend = [
        Verdict::Stiction,
        Verdict::NoStiction,
        Verdict::Undetermined,
        Verdict::InsufficientData,
    ]
    .map(|v| (verdict_fill(v), verdict(v)))
    .to_vec();
    let rows = d
        .windows
        .iter()
        .map(|w| WindowRow {
            samples: format!("{} to {}", w.start, w.end),
            time: format!("{} to {}", num(w.t_start), num(w.t_end)),
            verdict: verdict_chip(w.verdict),
            confidence: w.confidence.map_or("–".into(), |c| format!("{c:.2}")),
            period: w.period.map_or("–".into(), duration),
            votes: w
                .votes
                .iter()
                .map(|(n, v)| (n.words(), vote_chip(*v)))
                .collect(),
            reason: w.reason.clone().unwrap_or_default(),
        })
        .collect();
    Some(Windows {
        strip,
        legend,
        reasons: d.windows.iter().any(|w| w.reason.is_some()),
        rows,
    })
}

#[derive(Serialize)]
pub struct Notes {
    /// What reading the record decided.
    pub reading: Vec<String>,
    pub warnings: Vec<String>,
    pub caveat: String,
}

pub fn notes(d: &Diagnosis, q: Option<&Quantification>, reading: &[String]) -> Notes {
    let warnings = d
        .warnings
        .iter()
        .chain(q.iter().flat_map(|q| q.warnings.iter()))
        .cloned()
        .collect();
    let caveat = match d.quantification.as_ref() {
        Some(q) => capital(&q.caveat),
        None => {
            "No closed-loop estimate was run: the verdict rests on the indices, which read the \
                 valve's behaviour from OP and PV without measuring the valve position"
                .into()
        }
    };
    Notes {
        reading: reading.to_vec(),
        warnings,
        caveat: format!("{}.", caveat.trim_end_matches('.')),
    }
}
