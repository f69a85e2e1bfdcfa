//! Diagnosing a loop from routine data, as a control engineer does: which samples can be judged
//! (automatic mode, every signal present, OP off its limits; setpoint changes are kept, they are
//! the best excitation a loop gets), then independent families of evidence, each with its value,
//! threshold and vote, and a verdict that says why.
//!
//! - `bridge`, `stretch` and `gates`: short gaps bridged, the usable stretches and the
//!   data-quality findings;
//! - [`oscillation`]: does the loop oscillate (for the shape family);
//! - [`evidence`]: the families (valve, model, stick-slip, shape, loop and, with `thorough`, the
//!   hidden valve), one file each behind a trait;
//! - `verdict`: families that agree decide, families that conflict give `undetermined`;
//! - `band`: when the verdict is `stiction`, the band in % of valve span and where it comes from;
//! - [`reach`]: the bands a record like this one shows and hides, from OP's noise;
//! - [`Thresholds`]: the families' thresholds as one table, for studies and tests;
//! - `windows`: the same judgement per window of the record.

mod band;
mod bridge;
pub mod combined;
pub mod evidence;
mod gates;
pub mod oscillation;
pub mod reach;
mod request;
mod result;
mod saturation;
pub mod setpoint;
mod stretch;
mod thresholds;
mod verdict;
mod windows;

pub use evidence::{Family, FamilyEvidence};
pub use oscillation::noise_std;
pub use reach::Reach;
pub use request::{DiagnoseError, DiagnoseRequest};
pub use result::{
    Band, BandSource, Diagnosis, Index, Oscillation, SetpointReadOff, Verdict, Vote, WindowVerdict,
};
pub use thresholds::Thresholds;

/// The signals of one loop record (op, pv, and when recorded sp, mv, time in seconds, and
/// `auto`: `true` where the controller is in automatic). Missing values are NaN.
pub use crate::quality::Record as LoopRecord;

use crate::checked::Checked;
use crate::quality::{self, Finding, Gate};
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
    /// The families' statistics read together ([`combined`]).
    combined: Option<combined::CombinedEvidence>,
    fits: Option<crate::quantify::FitComparison>,
    /// Without a recorded setpoint, the setpoint read off OP and PV ([`setpoint`]).
    setpoint: Option<setpoint::Inferred>,
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
        integrating: Some(req.integrating),
        lag: None,
    };
    let (fits, lag_bound) = evidence::model::compared(r.op, r.pv, &compare);
    let ctx = Context {
        req,
        op: r.op,
        pv: r.pv,
        sp: r.sp,
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
    let motion = verdict::Motion::of(&ctx.oscillation, req.ts, sp).with_pv_not_recorded(
        ctx.unrecorded_share(0, r.pv.len()),
        req.limits.repeated_share,
    );
    let mut decision = verdict::decide(&families, &motion);
    // the hidden valve costs seconds: only with `thorough`, only where it can change the verdict
    if req.thorough {
        if decision.verdict == Verdict::Stiction {
            families.push(evidence::hidden_valve::not_needed());
        } else {
            families.push(evidence::EvidenceFamily::evaluate(
                &evidence::hidden_valve::HiddenValve,
                &ctx,
            ));
            decision = verdict::decide(&families, &motion);
        }
    }
    let mut combined = combined::CombinedEvidence::of(&combined::features::Stretch {
        families: &families,
        oscillation: &ctx.oscillation,
        indices: ctx.indices.get().map_or(&[], Vec::as_slice),
        op_noise: reach::op_noise(&families, || ctx.op_noise),
        ts: req.ts,
        samples: r.op.len(),
    });
    if let Some(c) = combined.as_mut() {
        c.for_verdict(decision.verdict);
        if c.decides(decision.verdict, &families) {
            c.decided = true;
            c.before = Some(decision.verdict);
            decision = verdict::decided_by_combination(decision, c, &families, &motion);
        }
        decision.evidence.push(c.line());
    }
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
        combined,
        fits,
        setpoint: inferred,
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
    let mut d = Diagnosis {
        verdict: Verdict::InsufficientData,
        confidence: None,
        reason: None,
        evidence: Vec::new(),
        next_step: String::new(),
        samples: n,
        analysed: [s, e],
        stretches: stretches.iter().map(|&(a, b)| [a, b]).collect(),
        ts: req.ts,
        quality,
        oscillation: None,
        families: Vec::new(),
        combined: None,
        indices: Vec::new(),
        reach: None,
        band: None,
        quantification: None,
        quantified: None,
        windows,
        setpoint_read_off: None,
        warnings,
        seconds: 0.0,
    };
    if e - s < req.min_samples {
        if let Some((family, osc)) = saturation::bounded(r, req, e - s) {
            return Ok(saturation_bound(d, family, osc, r.sp, req, started));
        }
        let reason = too_short(&d.quality, e - s, req);
        let next_step = "use a longer record in automatic with every signal present".into();
        return Ok(unjudged(d, reason, next_step, started));
    }
    let sub = r.slice(s, e);
    if let Some((reason, next_step)) = gates::still(sub.op, sub.pv) {
        return Ok(unjudged(d, reason, next_step, started));
    }
    let j = judge(&sub, req);
    if let Some(read) = &j.setpoint {
        if let Some(w) = d.warnings.iter_mut().find(|w| w.starts_with(NO_SETPOINT)) {
            *w = setpoint::words(read.steps.len());
        }
        d.setpoint_read_off = Some(read.in_record(s));
    }
    d.verdict = j.decision.verdict;
    d.confidence = j.decision.confidence;
    d.reason = j.decision.reason;
    d.evidence = j.decision.evidence;
    d.next_step = j.decision.next_step;
    d.families = j.families;
    d.combined = j.combined;
    d.indices = j.indices;
    d.reach = reach::of(&d, sub.op, req);
    let mut osc = j.oscillation;
    osc.stretch = [osc.stretch[0] + s, osc.stretch[1] + s];
    if d.verdict == Verdict::Stiction {
        band::size(&mut d, &sub, s, &osc, j.fits.as_ref(), req);
    }
    d.oscillation = Some(osc);
    d.seconds = started.elapsed().as_secs_f64();
    Ok(d)
}

/// `d` judged on the loop family's saturation rule alone, over the whole record
/// ([`saturation::bounded`]).
fn saturation_bound(
    mut d: Diagnosis,
    family: FamilyEvidence,
    osc: Osc,
    sp: Option<&[f64]>,
    req: &DiagnoseRequest,
    started: Instant,
) -> Diagnosis {
    let families = vec![family];
    let decision = verdict::decide(&families, &verdict::Motion::of(&osc, req.ts, sp));
    d.verdict = decision.verdict;
    d.confidence = decision.confidence;
    d.reason = decision.reason;
    d.evidence = decision.evidence;
    d.next_step = decision.next_step;
    d.families = families;
    d.oscillation = Some(osc);
    let [s, e] = d.analysed;
    for f in d
        .quality
        .iter_mut()
        .filter(|f| f.gate == Gate::RecordLength)
    {
        f.message = format!(
            "the longest usable stretch, samples {s} to {e}, is too short for the families ({} of {} samples, of {} usable stretches); the whole record was read for OP's saturation",
            e - s,
            d.samples,
            d.stretches.len()
        );
    }
    d.warnings.push(format!(
        "OP's limits cut the record into stretches too short to judge the valve (the longest {} samples): only the saturation was judged, over the whole record",
        e - s
    ));
    d.analysed = [0, d.samples];
    d.seconds = started.elapsed().as_secs_f64();
    d
}

/// `d` as `insufficient_data` (its default verdict) for `reason`, with the next step.
fn unjudged(mut d: Diagnosis, reason: String, next_step: String, started: Instant) -> Diagnosis {
    d.evidence = vec![reason.clone()];
    d.reason = Some(reason);
    d.next_step = next_step;
    d.seconds = started.elapsed().as_secs_f64();
    d
}

/// Why a record too short to judge is so.
fn too_short(quality: &[Finding], used: usize, req: &DiagnoseRequest) -> String {
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
