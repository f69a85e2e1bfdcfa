//! Diagnosing a loop from routine data, as a control engineer does: which samples can be judged
//! (automatic mode, every signal present, OP off its limits; setpoint changes are kept, they are
//! the best excitation a loop gets), then independent families of evidence, each measuring what
//! it can, and one calibrated model that reads their statistics and gives the probability of a
//! sticky valve.
//!
//! - `bridge`, `stretch` and `gates`: short gaps bridged, the usable stretches and the
//!   data-quality findings;
//! - [`oscillation`]: does the loop oscillate (for the shape family);
//! - [`evidence`]: the families (valve, model, stick-slip, shape, loop and, with `thorough`, the
//!   hidden valve), one file each behind a trait;
//! - `verdict`: the model ([`VerdictModel`]), the verdict from its probability, and the reasons
//!   and next step as typed values ([`reasons`]);
//! - [`Settings`]: how the families measure, one checked table;
//! - `band`: when the verdict is `stiction`, the band in % of valve span and where it comes from;
//! - [`reach`]: the bands a record like this one shows and hides, from OP's noise;
//! - `windows`: the same judgement per window of the record.

pub mod averaging;
mod band;
mod bridge;
pub mod evidence;
mod gates;
pub mod loop_kind;
pub mod oscillation;
pub mod reach;
pub mod reasons;
mod request;
mod result;
pub mod setpoint;
mod settings;
mod stretch;
mod verdict;
mod windows;

pub use averaging::{AveragingSettings, JudgedOn};
pub use evidence::{Family, FamilyEvidence};
pub use oscillation::noise_std;
pub use reach::Reach;
pub use reasons::{Action, Finding, NextStep, Reason};
pub use request::{DiagnoseError, DiagnoseRequest};
pub use result::{
    Band, BandSource, Diagnosis, Index, Oscillation, SetpointReadOff, Verdict, Vote, WindowVerdict,
};
pub use settings::Settings;
pub use verdict::{
    Contribution, Input, ModelError, Reading, Statistic, Training, VerdictModel, VOTE,
};

/// The signals of one loop record (op, pv, and when recorded sp, mv, time in seconds, and
/// `auto`: `true` where the controller is in automatic). Missing values are NaN.
pub use crate::quality::Record as LoopRecord;

use crate::checked::Checked;
use crate::quality::{self, Finding as GateFinding, Gate};
use crate::quantify::CompareRequest;
use evidence::Context;
use oscillation::mean;
use result::Oscillation as Osc;
use std::time::Instant;

/// One stretch judged: the families, the shape indices, the oscillation and the decision.
struct Judged {
    families: Vec<FamilyEvidence>,
    indices: Vec<Index>,
    oscillation: Osc,
    decision: verdict::Decision,
    fits: Option<crate::quantify::FitComparison>,
    /// Without a recorded setpoint, the setpoint read off OP and PV ([`setpoint`]).
    setpoint: Option<setpoint::Inferred>,
    /// The loop's kind and where it was read.
    kind: loop_kind::LoopKind,
}

/// The warning on a record without SP begins so.
const NO_SETPOINT: &str = "no setpoint column";

/// The control error: SP - PV, or without a setpoint the PV's deviation from its mean.
fn control_error(pv: &[f64], sp: Option<&[f64]>) -> Vec<f64> {
    match sp {
        Some(sp) => sp.iter().zip(pv).map(|(a, b)| a - b).collect(),
        None => {
            let m = mean(pv);
            pv.iter().map(|v| m - v).collect()
        }
    }
}

/// Judge one usable stretch (every sample present, automatic).
fn judge(r: &LoopRecord, req: &DiagnoseRequest) -> Judged {
    let pv_noise = crate::detect::measurement_noise(r.pv);
    let inferred = setpoint::unless_recorded(r, pv_noise);
    let sp = r.sp.or(inferred.as_ref().map(|i| i.sp.as_slice()));
    let error = control_error(r.pv, sp);
    let oscillation = oscillation::of_record(&error, sp, req.ts);
    let compare = CompareRequest {
        ts: req.ts,
        max_delay: req.max_delay,
        integrating: Some(req.integrating.unwrap_or(false)),
        lag: None,
    };
    let (fits, lag_bound) = evidence::model::compared(r.op, r.pv, &compare);
    let kind = loop_kind::LoopKind {
        integrating: req.integrating.unwrap_or(false),
        source: match (&req.integrating, &req.integrating_tag) {
            (Some(_), Some(tag)) => loop_kind::KindSource::Tag { tag: tag.clone() },
            (Some(_), None) => loop_kind::KindSource::Request,
            (None, _) => loop_kind::KindSource::Default,
        },
        behaves_integrating: loop_kind::behaves_integrating(r.op, r.pv, req.max_delay),
    };
    let ctx = Context {
        req,
        op: r.op,
        pv: r.pv,
        sp: r.sp,
        setpoint: sp,
        integrating: kind.integrating,
        mv: r.mv,
        error,
        oscillation,
        pv_noise,
        setpoint_steps: inferred.as_ref().map_or(0, |i| i.steps.len()),
        op_noise: crate::detect::held_noise(r.op),
        pv_quantum: quality::quantum(r.pv),
        unrecorded: quality::unrecorded(r.pv),
        fits,
        lag_bound,
        indices: Default::default(),
    };
    let mut families: Vec<FamilyEvidence> =
        evidence::all().iter().map(|f| f.evaluate(&ctx)).collect();
    // the hidden valve costs seconds: only with `thorough`; it reports, the model does not read it
    if req.thorough {
        families.push(evidence::EvidenceFamily::evaluate(
            &evidence::hidden_valve::HiddenValve,
            &ctx,
        ));
    }
    let motion = verdict::Motion::of(&ctx.oscillation, req.ts, sp, r.op.len())
        .with_pv_not_recorded(
            ctx.unrecorded_share(0, r.pv.len()),
            req.limits.repeated_share,
        );
    let measured = verdict::Measured::of(&families, reach::op_noise(&families, || ctx.op_noise));
    let decision = verdict::decide(&mut families, &measured, &motion);
    let Context {
        oscillation,
        indices,
        fits,
        ..
    } = ctx;
    Judged {
        families,
        indices: indices.into_inner().unwrap_or_default(),
        oscillation,
        decision,
        fits,
        setpoint: inferred,
        kind,
    }
}

/// Check the request and diagnose one loop: [`DiagnoseRequest::check`], then
/// [`diagnose_checked`].
///
/// A healthy valve in the same loop as the crate root's example:
///
/// ```
/// use stiction_core::diagnose::{diagnose, DiagnoseRequest, LoopRecord, Verdict};
/// use stiction_core::models::{Model, Stenman};
/// use stiction_core::sim::ClosedLoop;
///
/// let mut sim = ClosedLoop::new(Model::Stenman(Stenman::new(0.0)?));
/// sim.samples = 1500;
/// sim.noise = 0.05;
/// let data = sim.run()?;
/// let record = LoopRecord { op: &data.op, pv: &data.pv, sp: Some(&data.sp), mv: None, time: None, auto: None };
/// let d = diagnose(&record, &DiagnoseRequest::default())?;
/// assert_ne!(d.verdict, Verdict::Stiction);
/// // every family says what it measured, against which threshold, and how it voted
/// assert!(d.families.iter().all(|f| !f.threshold.is_empty()));
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn diagnose(r: &LoopRecord, req: &DiagnoseRequest) -> Result<Diagnosis, DiagnoseError> {
    diagnose_checked(r, &req.check()?)
}

/// Diagnose one loop with a checked request: gate the record, judge its usable stretches with
/// the families of evidence and, on a stiction verdict, size the band. The signals must all be
/// as long as OP (the one error the data can give).
pub fn diagnose_checked(
    r: &LoopRecord,
    req: &Checked<DiagnoseRequest>,
) -> Result<Diagnosis, DiagnoseError> {
    let started = Instant::now();
    request::check_record(r)?;
    let n = r.op.len();
    let breaks = stretch::time_breaks(r.time, n, req.limits.gap_steps);
    let bridged = bridge::short_gaps_bridged(r, &breaks);
    let filled;
    let r = match &bridged {
        Some(b) => {
            filled = b.record(r);
            &filled
        }
        None => r,
    };
    let (stretches, excluded) = stretch::usable(r, req);
    let (s, e) = stretches
        .iter()
        .copied()
        .max_by_key(|&(a, b)| (b - a, std::cmp::Reverse(a)))
        .unwrap_or((0, 0));
    let quality = gates::findings(r, (s, e), stretches.len(), &excluded, req);
    let mut warnings = Vec::new();
    warnings.extend(gates::op_outside_span(&r.op[s..e], req));
    if let Some(b) = &bridged {
        warnings.push(crate::record::bridged_note(&b.runs, ("sample", "samples")));
    }
    if excluded.spikes > 0 {
        warnings.push(format!(
            "{} left out: a signal far beyond its own range for one to three samples and back (a glitch, not the process); the record is split there",
            gates::plural(excluded.spikes, "sample in a spike", "samples in spikes")
        ));
    }
    if r.sp.is_none() {
        warnings.push(format!(
            "{NO_SETPOINT}: the control error is taken as the PV's deviation from its mean"
        ));
    }
    let windows = req
        .window
        .map_or_else(Vec::new, |w| windows::judge_windows(r, req, w, judge));
    let d = Diagnosis {
        verdict: Verdict::InsufficientData,
        probability: None,
        reasons: Vec::new(),
        next_step: NextStep::plain(Action::UsableRecord),
        statistics: None,
        samples: n,
        analysed: [s, e],
        stretches: stretches.iter().map(|&(a, b)| [a, b]).collect(),
        ts: req.ts,
        quality,
        oscillation: None,
        families: Vec::new(),
        indices: Vec::new(),
        reach: None,
        band: None,
        quantification: None,
        quantified: None,
        windows,
        setpoint_read_off: None,
        loop_kind: None,
        judged_on: None,
        warnings,
        seconds: 0.0,
    };
    if e - s < req.min_samples {
        let reason = too_short(&d.quality, e - s, req);
        return Ok(unjudged(d, reason, Action::UsableRecord, started));
    }
    let sub = r.slice(s, e);
    if let Some((reason, action)) = gates::still(sub.op, sub.pv) {
        return Ok(unjudged(d, reason, action, started));
    }
    Ok(judge_stretch(d, sub, s, req, started))
}

/// Judge the analysed stretch `sub` (from sample `s` of the record) into `d`: on its means at the
/// loop's time scale where it is long ([`averaging`]), then size the band on a `stiction` verdict.
fn judge_stretch(
    mut d: Diagnosis,
    sub: LoopRecord,
    s: usize,
    req: &DiagnoseRequest,
    started: Instant,
) -> Diagnosis {
    // a long record is judged on its means at the loop's own time scale
    let settings = &req.settings.averaging;
    let (over, time_scale) = averaging::factor(&sub, settings);
    let means = (over > 1).then(|| averaging::Means::of(&sub, over));
    let averaged_req;
    let (sub, req) = match &means {
        Some(m) => {
            averaged_req = DiagnoseRequest {
                ts: req.ts * over as f64,
                ..req.clone()
            };
            (m.record(), &averaged_req)
        }
        None => (sub, req),
    };
    // ... and a fast loop's on the part where OP moves most
    let most = averaging::most_judged(settings, over, time_scale);
    let from = averaging::most_moving(sub.op, most);
    let judged = sub.op.len().min(most);
    let whole = sub.op.len();
    let sub = sub.slice(from, from + judged);
    // a judged sample `k` is the record's sample `base + k * over`
    let base = s + from * over;
    let j = judge(&sub, req);
    if let Some(read) = &j.setpoint {
        if let Some(w) = d.warnings.iter_mut().find(|w| w.starts_with(NO_SETPOINT)) {
            *w = setpoint::words(read.steps.len());
        }
        let mut read = read.in_record(0);
        read.steps.iter_mut().for_each(|k| *k = base + *k * over);
        d.setpoint_read_off = Some(read);
    }
    d.verdict = j.decision.verdict;
    d.probability = j.decision.probability;
    d.reasons = j.decision.reasons;
    d.next_step = j.decision.next_step;
    d.statistics = j.decision.reading;
    if let Some(w) = kind_words(&j.kind) {
        d.warnings.push(w);
    }
    d.loop_kind = Some(j.kind);
    d.families = j.families;
    d.indices = j.indices;
    d.reach = reach::of(&d, sub.op, req);
    let mut osc = j.oscillation;
    if d.verdict == Verdict::Stiction {
        band::size(&mut d, &sub, 0, &osc, j.fits.as_ref(), req);
    }
    osc.stretch = osc.stretch.map(|k| base + k * over);
    in_record_samples(&mut d, (base, over), base - s);
    if over > 1 || judged < whole {
        d.judged_on = Some(averaging::JudgedOn {
            over,
            ts: req.ts,
            samples: judged,
            time_scale,
            stretch: [base, base + judged * over],
        });
    }
    if judged < whole {
        d.warnings.push(format!(
            "judged on samples {base} to {} of the record: the {judged} {} where OP moves most; \
             the analysed stretch holds {} times the loop's time scale and its evidence many times over",
            base + judged * over,
            if over > 1 { "means" } else { "samples" },
            whole * over / time_scale.max(1)
        ));
    }
    d.oscillation = Some(osc);
    d.seconds = started.elapsed().as_secs_f64();
    d
}

/// The sample ranges the diagnosis reports, as samples of the record (a judged sample `k` is
/// `base + k * over`): the closed-loop estimate's, and the sticks' and the hold's as samples of
/// the analysed stretch (which starts `shift` samples before `base`); the families' other
/// figures stay in judged samples.
fn in_record_samples(d: &mut Diagnosis, (base, over): (usize, usize), shift: usize) {
    if let Some(q) = &mut d.quantified {
        *q = q.map(|k| base + k * over);
    }
    for f in &mut d.families {
        if let Some(st) = &mut f.stick_slip {
            let at = |k: usize| shift + k * over;
            st.ranges.iter_mut().for_each(|r| *r = r.map(at));
            if let Some(r) = &mut st.stuck_range {
                *r = r.map(at);
            }
        }
    }
}

/// `d` as `insufficient_data` (its default verdict) for `reason`, with the next step.
fn unjudged(mut d: Diagnosis, reason: String, action: Action, started: Instant) -> Diagnosis {
    d.reasons = vec![Reason::plain(reasons::Finding::Record { message: reason })];
    d.next_step = NextStep::plain(action);
    d.seconds = started.elapsed().as_secs_f64();
    d
}

/// What the diagnosis assumed of the loop's kind, where a user should know: a tag's hint, or a
/// record that behaves otherwise than the loop is judged.
fn kind_words(k: &loop_kind::LoopKind) -> Option<String> {
    let (kind, flag) = if k.integrating {
        ("an integrating process (a level)", "--self-regulating")
    } else {
        ("a self-regulating process", "--integrating")
    };
    if let loop_kind::KindSource::Tag { tag } = &k.source {
        return Some(format!(
            "judged as {kind} from the tag {tag} in a column's name ({flag} says otherwise)"
        ));
    }
    match k.behaves_integrating {
        Some(true) if !k.integrating => Some(
            "judged as a self-regulating process, but PV's levels follow OP's integral better than OP, as a level's do: if the loop is a level, say --integrating"
                .into(),
        ),
        Some(false) if k.integrating && k.source == loop_kind::KindSource::Request => Some(
            "judged as an integrating process as asked, but PV's levels follow OP better than its integral, as a self-regulating process's do"
                .into(),
        ),
        _ => None,
    }
}

/// Why a record too short to judge is so.
fn too_short(quality: &[GateFinding], used: usize, req: &DiagnoseRequest) -> String {
    let left: Vec<&str> = quality
        .iter()
        .filter(|f| !f.passed && !matches!(f.gate, Gate::RecordLength | Gate::PvQuantised))
        .map(|f| f.message.as_str())
        .collect();
    let mut reason = format!(
        "the longest usable stretch has {used} samples; a verdict needs at least {}",
        req.min_samples
    );
    if !left.is_empty() {
        reason.push_str(&format!(" ({})", left.join("; ")));
    }
    reason
}
