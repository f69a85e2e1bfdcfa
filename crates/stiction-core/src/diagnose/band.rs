//! Sizing the band of a `stiction` verdict, in % of valve span. The band reported first is the
//! estimator that the lab's calibration on simulated valves with known bands shows to be right
//! (`band_calibration`, crates/stiction-lab/results/band-calibration.md): the recorded valve
//! position's when there is one, else the largest of the three closed-loop estimates (the fit's
//! slip-jump band, Kano's S with its jump free; the closed-loop estimate, `quantify`'s Stenman
//! exact, with its interval; the fit's scan): each errs low far more often than high. Every other
//! estimate is given beside it as what it is: the other closed-loop estimates, the OP travel per
//! stick, the band whose describing function closes the loop's harmonic balance, the width of the
//! oscillation's PV-OP ellipse (an apparent stiction that the tuning inflates, not the band).

use super::evidence::limit_cycle::StictionBasis;
use super::evidence::Family;
use super::request::DiagnoseRequest;
use super::result::{Band, BandSource, Diagnosis, Oscillation};
use super::LoopRecord;
use crate::estimate::Method;
use crate::models::ModelKind;
use crate::quantify::{quantify, FitComparison, QuantifyRequest};
use crate::spectral;

/// The band's other estimates (OP units), from the families and the oscillation.
struct Beside {
    /// The recorded valve position's band (OP units, % of span, its interval), when the valve
    /// family voted stiction.
    valve: Option<(f64, f64, Option<[f64; 2]>)>,
    /// The sticks' median OP travel.
    stick: Option<f64>,
    /// The band whose describing function closes the loop's harmonic balance, where a valve's
    /// lag is what the linear loop needs to sustain the cycle.
    describing: Option<f64>,
    /// The width of the PV-OP ellipse of an oscillation.
    ellipse: Option<f64>,
}

impl Beside {
    fn new(d: &Diagnosis, sub: &LoopRecord, offset: usize, osc: &Oscillation, ts: f64) -> Self {
        let family = |f: Family| d.families.iter().find(|e| e.family == f);
        let valve = family(Family::Valve)
            .filter(|f| f.vote == super::Vote::Stiction)
            .and_then(|f| f.valve.as_ref())
            .map(|v| (v.d, v.d_percent_of_span, v.interval));
        let stick = family(Family::StickSlip)
            .and_then(|f| f.stick_slip.as_ref())
            .and_then(|s| s.median_travel);
        let describing = family(Family::Loop)
            .and_then(|f| f.limit_cycle.as_ref())
            .filter(|l| l.stiction_basis == Some(StictionBasis::ValveLag))
            .and_then(|l| l.describing.as_ref())
            .map(|b| b.band);
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
        Self {
            valve,
            stick,
            describing,
            ellipse,
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
    let op_noise = d
        .families
        .iter()
        .find_map(|f| f.stick_slip.as_ref())
        .map_or_else(|| crate::detect::held_noise(sub.op), |s| s.op_noise);
    let mut band = beside.valve.map(|(d, pct, interval)| Band {
        band_percent_of_span: pct,
        op_units: d,
        interval_percent_of_span: interval,
        source: BandSource::Valve,
        others: Vec::new(),
        ellipse_percent_of_span: None,
    });
    // the closed-loop estimate runs beside the fit's band (its interval of equally good bands
    // goes with it); the fit's slip-jump band comes first: the nearest to the simulated band
    let closed = if req.quantify {
        closed_loop_band(d, sub, offset, req)
    } else {
        None
    };
    let scan = fits.map(|f| f.stenman.params[0]);
    let slip = fits.map(|f| f.slip_jump.params[0]).filter(|s| *s > 0.0);
    if band.is_none() {
        // the largest of the closed-loop estimates: each errs low far more often than high (a
        // fit settles on a small band near OP), so the largest is nearest the simulated band
        band = [
            slip.map(|s| band_of(s, BandSource::SlipJumpFit, req)),
            closed.clone(),
            scan.map(|b| band_of(b, BandSource::FitScan, req)),
        ]
        .into_iter()
        .flatten()
        .filter(|b| b.op_units > op_noise)
        .max_by(|a, b| a.op_units.total_cmp(&b.op_units))
        .or(beside.stick.map(|t| band_of(t, BandSource::StickSlip, req)))
        .or(beside
            .describing
            .map(|b| band_of(b, BandSource::DescribingFunction, req)));
    }
    let Some(mut band) = band else {
        return;
    };
    let pct = |v: f64| req.percent_of_span(v);
    let mut beside_it = |source: BandSource, v: Option<f64>| {
        if let Some(v) = v.filter(|_| band.source != source) {
            band.others.push((source, pct(v)));
        }
    };
    beside_it(BandSource::ClosedLoop, closed.map(|c| c.op_units));
    beside_it(BandSource::FitScan, scan);
    beside_it(BandSource::SlipJumpFit, slip);
    beside_it(BandSource::StickSlip, beside.stick);
    beside_it(BandSource::DescribingFunction, beside.describing);
    band.ellipse_percent_of_span = beside.ellipse.map(pct);
    d.band = Some(band);
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
    q.integrating = d
        .loop_kind
        .as_ref()
        .map(|k| k.integrating)
        .or(req.integrating);
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
