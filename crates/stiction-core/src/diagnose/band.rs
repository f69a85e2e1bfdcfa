//! Sizing the band of a `stiction` verdict, in % of valve span: from the recorded valve position
//! when there is one, else the closed-loop estimate (`quantify`, Stenman exact), else the
//! closed-loop fit's scan; the stick-slip episodes' median OP travel, the band whose describing
//! function closes the loop's harmonic balance, and the ellipse of an oscillation are given
//! beside it.

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
    let pct = |v: f64| req.percent_of_span(v);
    let family = |f: Family| d.families.iter().find(|e| e.family == f);
    let valve = family(Family::Valve)
        .and_then(|f| f.valve.as_ref())
        .filter(|_| family(Family::Valve).is_some_and(|f| f.vote == super::Vote::Stiction));
    let stick = family(Family::StickSlip)
        .and_then(|f| f.stick_slip.as_ref())
        .and_then(|s| s.median_travel);
    // the band whose describing function closes the loop's harmonic balance, when the loop
    // family voted stiction (OP units)
    let describing = family(Family::Loop)
        .filter(|f| f.vote == super::Vote::Stiction)
        .and_then(|f| f.limit_cycle.as_ref())
        .and_then(|l| l.describing.as_ref())
        .map(|b| b.band);
    let ellipse = (osc.oscillating)
        .then_some(osc.period)
        .flatten()
        .and_then(|p| {
            let [s, e] = osc.stretch;
            let f0 = req.ts / p;
            spectral::apparent_stiction_ellipse(
                &sub.op[s - offset..e - offset],
                &sub.pv[s - offset..e - offset],
                0.5 * f0,
                (1.5 * f0).min(0.5),
            )
        })
        .map(|el| el.width_along_x);
    let mut band = None;
    if let Some(v) = valve {
        band = Some(Band {
            band_percent_of_span: v.d_percent_of_span,
            op_units: v.d,
            interval_percent_of_span: v.interval,
            source: BandSource::Valve,
            others: Vec::new(),
            ellipse_percent_of_span: None,
        });
    } else if req.quantify {
        let mut q = QuantifyRequest::new(ModelKind::Stenman, Method::Exact);
        q.ts = req.ts;
        q.max_delay = req.max_delay;
        q.estimate_start = req.estimate_start;
        q.integrating = Some(req.integrating);
        match quantify(sub.op, sub.pv, &q) {
            Ok(qr) => {
                if let Some(b) = qr.apparent_stiction {
                    band = Some(Band {
                        band_percent_of_span: pct(b),
                        op_units: b,
                        interval_percent_of_span: qr
                            .interval
                            .get("d")
                            .map(|i| [pct(i[0]), pct(i[1])]),
                        source: BandSource::ClosedLoop,
                        others: Vec::new(),
                        ellipse_percent_of_span: None,
                    });
                }
                d.warnings.extend(
                    qr.warnings
                        .iter()
                        .map(|w| format!("closed-loop estimate: {w}")),
                );
                d.quantification = Some(qr);
                d.quantified = Some([offset, offset + sub.op.len()]);
            }
            Err(err) => d
                .warnings
                .push(format!("the closed-loop estimate failed: {err}")),
        }
    }
    if band.is_none() {
        if let Some(f) = fits {
            let v = f.stenman.params[0];
            band = Some(Band {
                band_percent_of_span: pct(v),
                op_units: v,
                interval_percent_of_span: None,
                source: BandSource::FitScan,
                others: Vec::new(),
                ellipse_percent_of_span: None,
            });
        } else if let Some((t, source)) = stick
            .map(|t| (t, BandSource::StickSlip))
            .or(describing.map(|b| (b, BandSource::DescribingFunction)))
        {
            band = Some(Band {
                band_percent_of_span: pct(t),
                op_units: t,
                interval_percent_of_span: None,
                source,
                others: Vec::new(),
                ellipse_percent_of_span: None,
            });
        }
    }
    let Some(mut band) = band else {
        return;
    };
    if let Some(t) = stick.filter(|_| band.source != BandSource::StickSlip) {
        band.others.push((BandSource::StickSlip, pct(t)));
    }
    if let Some(b) = describing.filter(|_| band.source != BandSource::DescribingFunction) {
        band.others.push((BandSource::DescribingFunction, pct(b)));
        let a = band.op_units;
        if a > 0.0 && b > 0.0 && (a / b > DISAGREE || b / a > DISAGREE) {
            d.warnings.push(format!(
                "the band ({:.2} % of span, {}) and the describing function's band ({:.2} %) disagree by more than {DISAGREE}x: \
                 the band reported is the former; the describing function's needs no single stick resolved",
                band.band_percent_of_span,
                band.source.words(),
                pct(b)
            ));
        }
    }
    band.ellipse_percent_of_span = ellipse.map(pct);
    if let Some(el) = ellipse {
        let (a, b) = (band.op_units, el);
        if a > 0.0 && b > 0.0 && (a / b > DISAGREE || b / a > DISAGREE) {
            d.warnings.push(format!(
                "the band ({:.2} % of span) and the ellipse's width ({:.2} %) disagree by more than {DISAGREE}x: the ellipse is a rough measure, the band's source is stated",
                band.band_percent_of_span,
                pct(el)
            ));
        }
    }
    d.band = Some(band);
}
