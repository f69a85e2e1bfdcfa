//! Sizing the band of a `stiction` verdict, in % of valve span: from the recorded valve position
//! when there is one, else the closed-loop estimate (`quantify`, Stenman exact), else the
//! closed-loop fit's scan, unless the band whose describing function closes the loop's harmonic
//! balance differs from that by more than [`CROSS_CHECK`] (then it is reported), else the
//! closed-loop fit's slip-jump band when it is larger by more than [`SLIP_JUMP_CHECK`]; the
//! stick-slip episodes' median OP travel, the other estimates and the ellipse of an oscillation
//! are given beside it. Where the hidden-valve family decided the verdict (`thorough`), its band is
//! reported: on the sticky loops it decides it is nearer the simulated band than the other sources'
//! (`plant_benchmark --thorough`).

use super::evidence::limit_cycle::StictionBasis;
use super::evidence::Family;
use super::request::DiagnoseRequest;
use super::result::{Band, BandSource, Diagnosis, Oscillation};
use super::LoopRecord;
use crate::estimate::Method;
use crate::models::ModelKind;
use crate::quantify::{quantify, FitComparison, QuantifyRequest};
use crate::spectral;

/// Estimates that differ by more than this factor get a warning.
const DISAGREE: f64 = 2.0;

/// Where the loop family explains a limit cycle, its describing function's band and the closed-loop
/// fit's are two independent estimates; when they differ by more than this factor the describing
/// function's is reported. It needs no single stick resolved, where the fit reads sticks shorter
/// than a sample, a valve's lag or a controller faster than the record as no stick (on the sticky
/// loops the loop family calls sticky it is the nearer of the two; where the closed-loop estimate
/// is exact, the rule mostly keeps it).
const CROSS_CHECK: f64 = 1.5;

/// The closed-loop fit also fits Kano's valve, its slip jump `J` free beside the band `S`. A
/// Stenman fit, bound to jump all the way back to OP, often settles on a small band near OP
/// (stiction-lab/results/sampled-valve.md: the knife-edge partition, a controller moving OP between
/// samples); the slip-jump valve's `S` less so. Where the describing function has not replaced the
/// Stenman band and `S` is larger than it by more than this factor, `S` is reported, the Stenman
/// band beside it: both err low far more often than high, so the larger one corrects the common
/// error.
const SLIP_JUMP_CHECK: f64 = 1.2;

/// A band from the fits under this many of the OP's noise standard deviations is no band they
/// resolve: a valve whose band the OP's noise crosses at most samples moves with OP, and the fits
/// cannot tell it from one that follows OP. The oscillation's ellipse is reported then, or else the
/// stick-slip episodes' median OP travel (the ellipse is then the nearer of the two to the
/// simulated band).
const UNRESOLVED_NOISES: f64 = 2.0;

/// Where the levels test (`thorough`) voted stiction, its band and the closed-loop estimate's are
/// two estimates; when they differ by more than this factor the levels test's is reported. The fit
/// of PV's changes often settles on a small band near OP where the levels test finds the valve
/// (stiction-lab/results/sampled-valve.md).
const LEVELS_CHECK: f64 = 1.5;

/// The band's other estimates (OP units), from the families and the oscillation.
struct Beside<'a> {
    /// The recorded valve position's band, when the valve family voted stiction.
    valve: Option<&'a super::evidence::ValveEvidence>,
    /// The stick-slip episodes' median OP travel.
    stick: Option<f64>,
    /// The band whose describing function closes the loop's harmonic balance, when the loop
    /// family voted stiction.
    describing: Option<f64>,
    /// The width of the PV-OP ellipse of an oscillation.
    ellipse: Option<f64>,
    /// Whether the loop family's stiction vote rests on a cycle that sustains itself.
    self_sustained: bool,
    /// The levels test's band, when it reached its threshold.
    levels: Option<f64>,
    /// The hidden-valve family's band, when it voted stiction.
    hidden: Option<f64>,
    /// The OP's measurement noise standard deviation (from its differences), OP units.
    op_noise: f64,
}

impl<'a> Beside<'a> {
    fn new(d: &'a Diagnosis, sub: &LoopRecord, offset: usize, osc: &Oscillation, ts: f64) -> Self {
        let family = |f: Family| d.families.iter().find(|e| e.family == f);
        let valve = family(Family::Valve)
            .filter(|f| f.vote == super::Vote::Stiction)
            .and_then(|f| f.valve.as_ref());
        let stick = family(Family::StickSlip)
            .and_then(|f| f.stick_slip.as_ref())
            .and_then(|s| s.median_travel);
        // the describing function's band where the valve's lag closes the loop's balance; a
        // cycle that sustains itself in a loop that needs no lag leaves it undetermined
        let basis = family(Family::Loop)
            .filter(|f| f.vote == super::Vote::Stiction)
            .and_then(|f| f.limit_cycle.as_ref())
            .and_then(|l| l.stiction_basis.map(|b| (b, l)));
        let describing = basis
            .filter(|(b, _)| *b == StictionBasis::ValveLag)
            .and_then(|(_, l)| l.describing.as_ref())
            .map(|b| b.band);
        let self_sustained = basis.is_some_and(|(b, _)| b == StictionBasis::SelfSustained);
        let levels = None;
        let ellipse = (osc.oscillating)
            .then_some(osc.period)
            .flatten()
            .and_then(|p| {
                let [s, e] = osc.stretch;
                let f0 = ts / p;
                spectral::apparent_stiction_ellipse(
                    &sub.op[s - offset..e - offset],
                    &sub.pv[s - offset..e - offset],
                    0.5 * f0,
                    (1.5 * f0).min(0.5),
                )
            })
            .map(|el| el.width_along_x);
        let hidden = family(Family::HiddenValve)
            .filter(|f| f.vote == super::Vote::Stiction)
            .and_then(|f| f.hidden_valve.as_ref())
            .map(|h| h.band);
        Self {
            valve,
            stick,
            describing,
            ellipse,
            self_sustained,
            levels,
            hidden,
            // as the families measured it, on the same stretch
            op_noise: family(Family::StickSlip)
                .and_then(|f| f.stick_slip.as_ref())
                .map_or_else(|| crate::detect::held_noise(sub.op), |s| s.op_noise),
        }
    }
}

/// A band of `op_units` from `source`, nothing beside it yet.
fn band_of(op_units: f64, source: BandSource, req: &DiagnoseRequest) -> Band {
    Band {
        band_percent_of_span: req.percent_of_span(op_units),
        op_units,
        interval_percent_of_span: None,
        source,
        others: Vec::new(),
        ellipse_percent_of_span: None,
    }
}

/// Fill `d.band` (and the closed-loop estimate) for the analysed stretch `sub`, which starts at
/// sample `offset` of the record.
pub(super) fn size(
    d: &mut Diagnosis,
    sub: &LoopRecord,
    offset: usize,
    osc: &Oscillation,
    fits: Option<&FitComparison>,
    req: &DiagnoseRequest,
) {
    let beside = Beside::new(d, sub, offset, osc, req.ts);
    let (stick, describing, ellipse) = (beside.stick, beside.describing, beside.ellipse);
    let (self_sustained, levels, hidden) = (beside.self_sustained, beside.levels, beside.hidden);
    // what stands in for a band the fits do not resolve
    let stand_in = ellipse
        .map(|e| (e, BandSource::Ellipse))
        .or(stick.map(|t| (t, BandSource::StickSlip)));
    let op_noise = beside.op_noise;
    let mut band = beside.valve.map(|v| Band {
        band_percent_of_span: v.d_percent_of_span,
        op_units: v.d,
        interval_percent_of_span: v.interval,
        source: BandSource::Valve,
        others: Vec::new(),
        ellipse_percent_of_span: None,
    });
    if band.is_none() && req.quantify {
        band = closed_loop_band(d, sub, offset, req);
    }
    if band.is_none() {
        band = match fits {
            Some(f) => Some(band_of(f.stenman.params[0], BandSource::FitScan, req)),
            None => stick
                .map(|t| band_of(t, BandSource::StickSlip, req))
                .or(describing.map(|b| band_of(b, BandSource::DescribingFunction, req))),
        };
    }
    let Some(mut band) = band else {
        return;
    };
    let pct = |v: f64| req.percent_of_span(v);
    if let Some(b) = describing.filter(|&b| {
        matches!(band.source, BandSource::ClosedLoop | BandSource::FitScan)
            && differ(band.op_units, b, CROSS_CHECK)
    }) {
        d.warnings.push(format!(
            "the describing function's band ({:.2} % of span) and {} ({:.2} %) differ by more than {CROSS_CHECK}x: \
             the band reported is the describing function's, which needs no single stick resolved (a fit reads sticks shorter \
             than a sample as no stick)",
            pct(b),
            band.source.words(),
            band.band_percent_of_span
        ));
        replace(&mut band, b, BandSource::DescribingFunction, req);
    }
    if let Some(s) = fits.map(|f| f.slip_jump.params[0]).filter(|&s| {
        matches!(band.source, BandSource::ClosedLoop | BandSource::FitScan)
            && s > SLIP_JUMP_CHECK * band.op_units
    }) {
        replace(&mut band, s, BandSource::SlipJumpFit, req);
    }
    if let Some(l) = levels {
        if matches!(
            band.source,
            BandSource::ClosedLoop | BandSource::FitScan | BandSource::SlipJumpFit
        ) && differ(band.op_units, l, LEVELS_CHECK)
        {
            d.warnings.push(format!(
                "the levels test's band ({:.2} % of span) and {} ({:.2} %) differ by more than {LEVELS_CHECK}x: the band reported is \
                 the levels test's (the fit of PV's changes often settles on a small band near OP)",
                pct(l),
                band.source.words(),
                band.band_percent_of_span
            ));
            replace(&mut band, l, BandSource::Levels, req);
        } else if band.source != BandSource::Levels {
            band.others.push((BandSource::Levels, pct(l)));
        }
    }
    if let Some(h) = hidden {
        hidden_valve_band(&mut band, h, req);
    }
    unresolved(d, &mut band, stand_in, op_noise, req);
    if let Some(t) = stick.filter(|_| band.source != BandSource::StickSlip) {
        band.others.push((BandSource::StickSlip, pct(t)));
    }
    if let Some(b) = describing.filter(|_| band.source != BandSource::DescribingFunction) {
        band.others.push((BandSource::DescribingFunction, pct(b)));
        if differ(band.op_units, b, DISAGREE) {
            d.warnings.push(format!(
                "the band ({:.2} % of span, {}) and the describing function's band ({:.2} %) disagree by more than {DISAGREE}x: \
                 the band reported is the former; the describing function's needs no single stick resolved",
                band.band_percent_of_span,
                band.source.words(),
                pct(b)
            ));
        }
    }
    if self_sustained && band.source != BandSource::Valve {
        d.warnings.push(format!(
            "the stiction verdict rests on a cycle that sustains itself in a loop that needs no valve lag (near its stability limit): there the \
             describing function cannot size the band and a fit reads sticks shorter than a sample as no stick, so the band ({:.2} % of span, {}) is \
             rough and may understate it (on such simulated loops it fell well short of the true band); a valve travel test sizes it",
            band.band_percent_of_span,
            band.source.words()
        ));
    }
    band.ellipse_percent_of_span = ellipse.map(pct);
    if let Some(el) = ellipse {
        if differ(band.op_units, el, DISAGREE) {
            d.warnings.push(format!(
                "the band ({:.2} % of span) and the ellipse's width ({:.2} %) disagree by more than {DISAGREE}x: the ellipse is a rough measure, the band's source is stated",
                band.band_percent_of_span,
                pct(el)
            ));
        }
    }
    d.band = Some(band);
}

/// Where the fits' band is under [`UNRESOLVED_NOISES`] of the OP's noise (`op_noise`, OP units),
/// report `stand_in` (the ellipse's width, or else the stick-slip travel) instead, and say so.
fn unresolved(
    d: &mut Diagnosis,
    band: &mut Band,
    stand_in: Option<(f64, BandSource)>,
    op_noise: f64,
    req: &DiagnoseRequest,
) {
    let from_fits = matches!(
        band.source,
        BandSource::ClosedLoop | BandSource::FitScan | BandSource::SlipJumpFit
    );
    if !from_fits || band.op_units >= UNRESOLVED_NOISES * op_noise {
        return;
    }
    let Some((by, source)) = stand_in else {
        return;
    };
    d.warnings.push(format!(
        "the fits resolve no band ({:.3} % of span, {}, is under {UNRESOLVED_NOISES} OP noise standard deviations, {:.3} %): the band reported is {}",
        band.band_percent_of_span,
        band.source.words(),
        req.percent_of_span(UNRESOLVED_NOISES * op_noise),
        source.words()
    ));
    replace(band, by, source, req);
}

/// The hidden valve decided the verdict: the fits read the recorded OP as the valve's input,
/// which is what it showed wrong, so its band `h` (OP units) is reported; the recorded valve's
/// still comes first.
fn hidden_valve_band(band: &mut Band, h: f64, req: &DiagnoseRequest) {
    if band.source == BandSource::Valve {
        band.others
            .push((BandSource::HiddenValve, req.percent_of_span(h)));
    } else {
        replace(band, h, BandSource::HiddenValve, req);
    }
}

/// Report `by` (OP units, from `source`) instead of `band`, the replaced estimate beside it (with
/// any it had replaced).
fn replace(band: &mut Band, by: f64, source: BandSource, req: &DiagnoseRequest) {
    let mut others = std::mem::take(&mut band.others);
    others.push((band.source, band.band_percent_of_span));
    *band = band_of(by, source, req);
    band.others = others;
}

/// Whether two positive estimates differ by more than `factor` (either way).
fn differ(a: f64, b: f64, factor: f64) -> bool {
    a > 0.0 && b > 0.0 && (a / b > factor || b / a > factor)
}

/// The closed-loop estimate (`quantify`, Stenman exact) of the stretch, kept in `d`; its band.
fn closed_loop_band(
    d: &mut Diagnosis,
    sub: &LoopRecord,
    offset: usize,
    req: &DiagnoseRequest,
) -> Option<Band> {
    let mut q = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
    q.ts = req.ts;
    q.max_delay = req.max_delay;
    q.estimate_start = req.estimate_start;
    q.integrating = Some(req.integrating);
    let qr = match quantify(sub.op, sub.pv, &q) {
        Ok(qr) => qr,
        Err(err) => {
            d.warnings
                .push(format!("the closed-loop estimate failed: {err}"));
            return None;
        }
    };
    let pct = |v: f64| req.percent_of_span(v);
    let band = qr.apparent_stiction.map(|b| Band {
        interval_percent_of_span: qr.interval.get("d").map(|i| [pct(i[0]), pct(i[1])]),
        ..band_of(b, BandSource::ClosedLoop, req)
    });
    d.warnings.extend(
        qr.warnings
            .iter()
            .map(|w| format!("closed-loop estimate: {w}")),
    );
    d.quantification = Some(qr);
    d.quantified = Some([offset, offset + sub.op.len()]);
    band
}
