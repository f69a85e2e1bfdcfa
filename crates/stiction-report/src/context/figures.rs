//! The report's figures: the trends (an overview and a zoom on long records) and the PV-OP phase
//! plot, decimated so spikes and the envelope survive.

use super::*;

/// Trends: the record (an overview when it is long), the figures and a note on the stretch.
#[derive(Serialize)]
pub struct Trends {
    pub overview: bool,
    pub figures: Vec<Figure>,
    pub note: Option<String>,
}

/// The zoomed window of a long record.
#[derive(Serialize)]
pub struct Zoom {
    pub heading: String,
    pub how: String,
    pub figures: Vec<Figure>,
}

/// Trends keep the first, lowest and highest sample of this many buckets (spikes and envelope
/// survive); a long record's overview fewer; the phase plot keeps every k-th sample up to this
/// many points.
const TREND_BUCKETS: usize = 1500;
const OVERVIEW_BUCKETS: usize = 600;
const PHASE_POINTS: usize = 6000;
/// Buckets enough to keep every sample of a zoom window (at most 2000).
const EVERY_SAMPLE: usize = 1 << 20;

/// The PV chart (with SP and the simulated PV) and the OP chart (with the estimated valve) over
/// the samples `[a, b)`, `buckets` decimation buckets each.
fn trend_pair(
    data: &LoopData,
    d: &Diagnosis,
    q: Option<&Quantification>,
    [a, b]: [usize; 2],
    buckets: usize,
) -> Result<Vec<Figure>> {
    if b <= a {
        return Ok(vec![]);
    }
    let t = series::time_axis(data);
    let (unit, per) = series::time_unit(t[b - 1] - t[a]);
    let x_label = format!("time ({unit})");
    let tu: Vec<f64> = t[a..b].iter().map(|v| v / per).collect();
    // the fitted model and the estimated valve cover the samples the estimate used
    let [s, e] = d.quantified.unwrap_or(d.analysed);
    let (s2, e2) = (s.max(a), e.min(b));
    let model = |v: &[f64]| {
        (s < e && e <= t.len() && v.len() == e - s && s2 < e2)
            .then(|| series::decimate(&tu[s2 - a..e2 - a], &v[s2 - s..e2 - s], buckets))
    };
    let pv = series::decimate(&tu, &data.pv[a..b], buckets);
    let sp = data
        .sp
        .as_ref()
        .map(|sp| series::decimate(&tu, &sp[a..b], buckets));
    // without SP, the setpoint the diagnosis read off OP and PV, over its analysed stretch
    let [ra, rb] = [a.max(d.analysed[0]), b.min(d.analysed[1])];
    let read_off = d
        .setpoint_read_off
        .as_ref()
        .filter(|_| sp.is_none() && ra < rb)
        .map(|r| series::decimate(&tu[ra - a..rb - a], &r.over([ra, rb]), buckets));
    let sim = q.and_then(|q| model(&q.pv_simulated));
    let mv = q.and_then(|q| model(&q.mv));
    let mut traces = vec![plots::line("PV", &pv, 0)];
    if let Some(sp) = &sp {
        traces.push(plots::line("SP", sp, 2));
    }
    if let Some(r) = &read_off {
        traces.push(plots::steps("SP read off OP and PV", r, 2));
    }
    if let Some(sim) = &sim {
        traces.push(plots::line("PV simulated", sim, 1));
    }
    let mut caption = String::from("Process variable");
    if sp.is_some() {
        caption.push_str(" and setpoint");
    }
    if read_off.is_some() {
        caption.push_str(
            " and, with no SP column, the setpoint read off the record (where OP stepped while PV was still and PV then settled at a new level)",
        );
    }
    if sim.is_some() {
        caption.push_str(
            "; in red the PV the fitted valve-and-process model simulates from OP alone, over the samples the estimate used",
        );
    }
    caption.push('.');
    let pv_fig = plots::figure(
        &plots::chart("Process variable", &x_label, "PV", traces),
        TREND_SIZE,
        caption,
    )?;
    let op = series::decimate(&tu, &data.op[a..b], buckets);
    let mut traces = vec![plots::line("OP", &op, 0)];
    if let Some(mv) = &mv {
        traces.push(plots::steps("estimated MV", mv, 1));
    }
    let caption = if mv.is_some() {
        "Controller output and, in red, the valve position the fitted stiction model estimates \
         (the valve is not measured: it holds until OP has moved more than the band away from it)."
    } else {
        "Controller output."
    };
    let op_fig = plots::figure(
        &plots::chart("Controller output", &x_label, "OP", traces),
        TREND_SIZE,
        caption.into(),
    )?;
    Ok(vec![pv_fig, op_fig])
}

pub(super) fn trends(data: &LoopData, d: &Diagnosis, q: Option<&Quantification>) -> Result<Trends> {
    let n = data.op.len();
    let overview = n > LONG_RECORD;
    let buckets = if overview {
        OVERVIEW_BUCKETS
    } else {
        TREND_BUCKETS
    };
    let mut figures = trend_pair(data, d, q, [0, n], buckets)?;
    if overview {
        for f in &mut figures {
            f.caption = format!(
                "Overview of all {n} samples: the lowest and highest sample of each of {buckets} \
                 stretches, so spikes stay visible. {}",
                f.caption
            );
        }
    }
    let [s, e] = d.quantified.unwrap_or(d.analysed);
    let t = series::time_axis(data);
    let note = (s > 0 || e < d.samples).then(|| {
        format!(
            "The diagnosis uses samples {s} to {e} (t = {} to {} s); the rest of the record is left \
             out (manual mode, OP or PV at a limit, gaps or bad data: see Data quality).",
            num(t.get(s).copied().unwrap_or(0.0)),
            num(t.get(e.saturating_sub(1)).copied().unwrap_or(0.0))
        )
    });
    Ok(Trends {
        overview,
        figures,
        note,
    })
}

/// The window of a long record where OP and PV vary most, inside the analysed stretch, at full
/// resolution.
pub(super) fn zoom(data: &LoopData, d: &Diagnosis, q: Option<&Quantification>) -> Result<Zoom> {
    let n = data.op.len();
    let [s, e] = d.analysed;
    let (s, e) = if s < e && e <= n { (s, e) } else { (0, n) };
    let period = d
        .oscillation
        .as_ref()
        .and_then(|o| o.period)
        .map(|p| p / d.ts);
    let len = series::zoom_length(period, e - s);
    let a = s + series::busiest_window(&data.op[s..e], &data.pv[s..e], len);
    let b = a + len;
    let t = series::time_axis(data);
    let figures = trend_pair(data, d, q, [a, b], EVERY_SAMPLE)?;
    let why = match period {
        Some(p) if 5.0 * p >= 300.0 && 5.0 * p <= 2000.0 => "five periods of the oscillation",
        Some(_) => "about five periods of the oscillation, kept between 300 and 2000 samples",
        None => "no oscillation period to size it by",
    };
    Ok(Zoom {
        heading: format!(
            "Zoom: samples {a} to {b} (t = {} to {})",
            duration(t[a]),
            duration(t[b - 1])
        ),
        how: format!(
            "Every sample of the {len}-sample window ({why}) in which OP and PV vary most: of all \
             windows of that length inside the analysed stretch (samples {s} to {e}), the one with \
             the largest sum of the variances of OP and PV in the window, each relative to its \
             variance over the stretch. Noise weighs alike in every window, so this is where the \
             oscillation, or the stick-slip episodes, are largest."
        ),
        figures,
    })
}

/// A band in OP units in % of valve span, as the verdict's band maps OP (its ratio of % of span
/// to OP units); in OP units where the verdict gives no band to map it by.
fn band_words(d: &Diagnosis, op_units: f64) -> String {
    match &d.band {
        Some(b) if b.op_units > 0.0 => format!(
            "{} % of span",
            num(op_units * b.band_percent_of_span / b.op_units)
        ),
        _ => format!("{} in OP units", num(op_units)),
    }
}

pub(super) fn phase(data: &LoopData, d: &Diagnosis, q: Option<&Quantification>) -> Result<Figure> {
    let [s, e] = d.quantified.unwrap_or(d.analysed);
    let (s, e) = if s + 1 < e && e <= data.op.len() {
        (s, e)
    } else {
        (0, data.op.len())
    };
    let op = series::thin(&data.op[s..e], PHASE_POINTS);
    let measured = (op.clone(), series::thin(&data.pv[s..e], PHASE_POINTS));
    let sim = q
        .filter(|q| q.pv_simulated.len() == e - s)
        .map(|q| (op.clone(), series::thin(&q.pv_simulated, PHASE_POINTS)));
    // the fitted model and its band name the simulated trace (a title that long is cut on a
    // phone's width)
    let fitted = match q.and_then(|q| q.apparent_stiction.map(|b| (q, b))) {
        Some((q, b)) => format!(
            "{} d = {}, simulated",
            capital(&q.model.to_string()),
            band_words(d, b)
        ),
        None => "fitted model, simulated".into(),
    };
    let mut traces = vec![plots::line("measured", &measured, 5)];
    if let Some(sim) = &sim {
        traces.push(plots::line(&fitted, sim, 1));
    }
    let chart = plots::chart(
        "PV against OP",
        "controller output OP",
        "process variable PV",
        traces,
    );
    let caption = if sim.is_some() {
        "The measured PV against OP (grey) over the analysed stretch, and the PV the fitted model \
         simulates (red). While a sticky valve holds, OP moves and PV does not follow: the plot draws \
         a loop rather than a line."
    } else if q.is_some() && d.judged_on.is_some() {
        "The measured PV against OP over the analysed stretch. While a sticky valve holds, OP moves \
         and PV does not follow: the plot draws a loop rather than a line. The model was fitted to \
         the record's means (see the header), so its PV is not drawn over the samples."
    } else {
        "The measured PV against OP over the analysed stretch. While a sticky valve holds, OP moves \
         and PV does not follow: the plot draws a loop rather than a line. No model was fitted."
    };
    plots::figure(&chart, PHASE_SIZE, caption.into())
}
