//! The estimates: the band, and the models fitted with and without stiction.

use super::*;

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
            if m.band_fits_better() {
                format!(
                    "R² {} without stiction, {} with a Stenman band of {} % of span, {} with a slip jump (Kano); \
                     the stiction model explains {} % more of the PV's variation above its noise",
                    num(m.r2_without_stiction),
                    num(m.r2_stenman),
                    num(m.stenman_d_percent_of_span),
                    num(m.r2_slip_jump),
                    num(100.0 * m.improvement)
                )
            } else {
                format!(
                    "R² {} without stiction; no band found fits better (the search's best: {} with a Stenman band of {} % of span, \
                     {} with a slip jump)",
                    num(m.r2_without_stiction),
                    num(m.r2_stenman),
                    num(m.stenman_d_percent_of_span),
                    num(m.r2_slip_jump)
                )
            },
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
