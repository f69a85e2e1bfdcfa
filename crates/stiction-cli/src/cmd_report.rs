//! `stiction report`: diagnose a loop and write one self-contained HTML page: inline SVG charts,
//! inline CSS, no scripts, fonts, images or links outside the file, readable on a laptop, a phone
//! and on paper. Every text taken from the data (file and column names) is escaped.

use crate::cmd_diagnose::{Columns, LoopFile};
use crate::cmd_simulate;
use crate::plot::{self, Chart, Kind, Series};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use stiction_core::diagnose::{diagnose, BandSource, Diagnosis, Verdict, Vote, WindowVerdict};
use stiction_core::quantify::Quantification;

#[derive(clap::Args)]
#[command(after_help = "Examples:
  stiction report loop.csv --sp sp -o loop.html
  stiction report export.csv --op FIC101.OP --pv FIC101.PV --mode FIC101.MODE -o fic101.html
  stiction report level.csv --op OP --pv PV --integrating --window 2000 -o level.html")]
pub struct Args {
    /// Data file: CSV with a header line, .csv.gz, a workbook, Parquet, or - for standard input
    pub file: PathBuf,
    #[command(flatten)]
    pub columns: Columns,
    /// Add a verdict per window of this many samples (locates intermittent stiction)
    #[arg(long)]
    pub window: Option<usize>,
    /// Skip the closed-loop estimate of the band (faster)
    #[arg(long, conflicts_with = "estimate_start")]
    pub no_quantify: bool,
    /// The HTML file to write (one self-contained page)
    #[arg(short = 'o', long = "output", value_name = "FILE.html")]
    pub output: PathBuf,
    /// Exit with code 4 when the verdict is stiction (after writing the report), for scripts
    #[arg(long, value_enum, value_name = "VERDICT")]
    pub fail_on: Option<crate::cmd_diagnose::FailOn>,
}

pub fn run(a: Args) -> Result<()> {
    let table = a.columns.open(&a.file)?;
    let lf = a.columns.read(&table)?;
    let mut req = a.columns.request(lf.ts);
    req.window = a.window;
    req.quantify = !a.no_quantify;
    let id = table.path.display().to_string();
    let d =
        diagnose(&lf.record(), &req).map_err(|e| crate::cmd_diagnose::core_error(&id, &lf, e))?;
    write_report_with(&a.output, &id, &lf, &d, Some(&a.columns))?;
    println!(
        "{id}: {}{}; report written to {}",
        verdict_words(d.verdict),
        d.confidence
            .map(|c| format!(" (confidence {c:.2})"))
            .unwrap_or_default(),
        a.output.display()
    );
    crate::cmd_diagnose::print_notes(&id, &lf, false);
    crate::cmd_diagnose::FailOn::check(a.fail_on, d.verdict)
}

/// Write the report of one loop to `path` (atomically: a temporary file, then a rename).
/// `loop_id` names the loop in the title (a file name or tag; escaped here).
#[allow(dead_code)] // a library-style entry point; `report` itself passes the columns
pub fn write_report(path: &Path, loop_id: &str, lf: &LoopFile, d: &Diagnosis) -> Result<()> {
    write_report_with(path, loop_id, lf, d, None)
}

/// As [`write_report`], naming the columns the loop was read from when they are known.
pub fn write_report_with(
    path: &Path,
    loop_id: &str,
    lf: &LoopFile,
    d: &Diagnosis,
    columns: Option<&Columns>,
) -> Result<()> {
    let html = render_with(loop_id, lf, d, columns)
        .with_context(|| format!("{}: cannot render the report", path.display()))?;
    cmd_simulate::write_atomic(path, html.as_bytes())
}

/// The report as one HTML document (the batch command adds a link back to its index).
pub fn render(loop_id: &str, lf: &LoopFile, d: &Diagnosis) -> Result<String> {
    render_with(loop_id, lf, d, None)
}

const CSS: &str = include_str!("report/style.css");

/// Chart sizes in SVG user units, the page scales them to its width: each chart is drawn twice,
/// wide for laptops and paper, narrow (relatively larger text) for phones; CSS shows one.
const TREND_SIZE: [(u32, u32); 2] = [(960, 360), (520, 380)];
const PHASE_SIZE: [(u32, u32); 2] = [(960, 600), (520, 480)];
/// Trends keep the first, lowest and highest sample of this many buckets (spikes and envelope
/// survive); the phase plot keeps every k-th sample up to this many points.
const TREND_BUCKETS: usize = 1500;
const PHASE_POINTS: usize = 6000;

pub fn render_with(
    loop_id: &str,
    lf: &LoopFile,
    d: &Diagnosis,
    columns: Option<&Columns>,
) -> Result<String> {
    let q = d.quantification.as_ref().filter(|q| q.status == "ok");
    let mut h = String::with_capacity(256 * 1024);
    let title = format!("{loop_id}: {}", verdict_words(d.verdict));
    let _ = write!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <meta name=\"generator\" content=\"stiction {}\">\n<title>{} · stiction report</title>\n\
         <style>\n{CSS}</style>\n</head>\n<body>\n<main>\n",
        env!("CARGO_PKG_VERSION"),
        esc(&title)
    );
    header(&mut h, loop_id, lf, d, columns);
    verdict_box(&mut h, d);
    trends(&mut h, lf, d, q)?;
    phase(&mut h, lf, d, q)?;
    indices(&mut h, d);
    oscillation(&mut h, d);
    estimates(&mut h, d, q);
    convergence(&mut h, q);
    quality(&mut h, d);
    windows(&mut h, d);
    notes(&mut h, d, q);
    let _ = write!(
        h,
        "<footer>Written by stiction {} · diagnosis in {} s</footer>\n</main>\n</body>\n</html>\n",
        env!("CARGO_PKG_VERSION"),
        num(d.seconds)
    );
    Ok(h)
}

/// Escape text for HTML element content and quoted attribute values.
pub fn esc(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

fn verdict_words(v: Verdict) -> &'static str {
    match v {
        Verdict::Stiction => "stiction",
        Verdict::NoStiction => "no stiction",
        Verdict::Undetermined => "undetermined",
        Verdict::InsufficientData => "insufficient data",
    }
}

fn capital(s: &str) -> String {
    let mut c = s.chars();
    c.next()
        .map(|f| f.to_uppercase().chain(c).collect())
        .unwrap_or_default()
}

fn vote_code(v: Vote) -> &'static str {
    match v {
        Vote::Stiction => "stiction",
        Vote::NoStiction => "no_stiction",
        Vote::Undetermined => "undetermined",
    }
}

fn vote_chip(v: Vote) -> String {
    let words = match v {
        Vote::Stiction => "stiction",
        Vote::NoStiction => "no stiction",
        Vote::Undetermined => "undetermined",
    };
    format!("<span class=\"chip {}\">{words}</span>", vote_code(v))
}

fn verdict_chip(v: Verdict) -> String {
    format!(
        "<span class=\"chip {}\">{}</span>",
        v.as_str(),
        verdict_words(v)
    )
}

/// A number with about four significant digits; ∞ and – for the non-finite.
fn num(v: f64) -> String {
    if v.is_nan() {
        return "–".into();
    }
    if v.is_infinite() {
        return if v > 0.0 {
            "∞".into()
        } else {
            "−∞".into()
        };
    }
    let a = v.abs();
    let s = if a == 0.0 {
        "0".to_string()
    } else if !(1e-3..1e6).contains(&a) {
        format!("{v:.3e}")
    } else if a >= 1000.0 {
        format!("{v:.0}")
    } else if a >= 100.0 {
        format!("{v:.1}")
    } else if a >= 10.0 {
        format!("{v:.2}")
    } else if a >= 1.0 {
        format!("{v:.3}")
    } else {
        format!("{v:.4}")
    };
    // 12.00 → 12, 0.0500 → 0.05 (not in the exponent form)
    let s = if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    s.replace('-', "−")
}

fn opt(v: Option<f64>) -> String {
    v.map_or("–".into(), num)
}

fn seconds(v: f64) -> String {
    if v >= 7200.0 {
        format!("{} s ({} h)", num(v), num(v / 3600.0))
    } else if v >= 120.0 {
        format!("{} s ({} min)", num(v), num(v / 60.0))
    } else {
        format!("{} s", num(v))
    }
}

/// Seconds from the first sample for every sample of the record.
fn time_axis(lf: &LoopFile) -> Vec<f64> {
    match &lf.time {
        Some(t) if !t.is_empty() => t.iter().map(|v| v - t[0]).collect(),
        _ => (0..lf.op.len()).map(|k| k as f64 * lf.ts).collect(),
    }
}

/// The unit the trends' time axis reads best in: its name and seconds per unit.
fn time_unit(span: f64) -> (&'static str, f64) {
    if span > 2.0 * 86400.0 {
        ("d", 86400.0)
    } else if span > 5.0 * 3600.0 {
        ("h", 3600.0)
    } else if span > 3000.0 {
        ("min", 60.0)
    } else {
        ("s", 1.0)
    }
}

/// The first, lowest and highest sample of each of `buckets` buckets, in time order.
fn decimate(x: &[f64], y: &[f64], buckets: usize) -> (Vec<f64>, Vec<f64>) {
    let n = x.len().min(y.len());
    if n <= 3 * buckets {
        return (x[..n].to_vec(), y[..n].to_vec());
    }
    let size = n.div_ceil(buckets);
    let (mut xs, mut ys) = (
        Vec::with_capacity(3 * buckets),
        Vec::with_capacity(3 * buckets),
    );
    let mut start = 0;
    while start < n {
        let end = (start + size).min(n);
        let (mut lo, mut hi) = (start, start);
        for k in start..end {
            if y[k] < y[lo] {
                lo = k;
            }
            if y[k] > y[hi] {
                hi = k;
            }
        }
        let mut keep = [start, lo.min(hi), lo.max(hi)];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for k in keep {
            if k != last {
                xs.push(x[k]);
                ys.push(y[k]);
                last = k;
            }
        }
        start = end;
    }
    (xs, ys)
}

/// Every k-th sample, at most about `points`.
fn thin(v: &[f64], points: usize) -> Vec<f64> {
    let step = v.len().div_ceil(points.max(1)).max(1);
    v.iter().step_by(step).copied().collect()
}

/// A plotters SVG document made fit to inline in HTML: no XML declaration, no namespace URL
/// (the HTML parser puts `<svg>` in the SVG namespace), scaled to the page by its viewBox.
fn inline_svg(svg: &str, size: (u32, u32), class: &str, label: &str) -> String {
    let body = match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    };
    let body = match body.find('>') {
        Some(i) if body.starts_with("<svg") => &body[i + 1..],
        _ => body,
    };
    format!(
        "<svg class=\"{class}\" viewBox=\"0 0 {} {}\" width=\"100%\" preserveAspectRatio=\"xMidYMid meet\" \
         role=\"img\" aria-label=\"{}\">{}",
        size.0,
        size.1,
        esc(label),
        body.trim_end()
    )
}

/// Room above the data for the legend (upper right): the y range with `top` of its span added.
fn headroom(series: &[Series], top: f64) -> Option<(f64, f64)> {
    let (lo, hi) = series
        .iter()
        .flat_map(|s| s.y.iter())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    (hi > lo).then_some((lo, hi + top * (hi - lo)))
}

fn figure(h: &mut String, chart: &Chart, sizes: [(u32, u32); 2], caption: &str) -> Result<()> {
    h.push_str("<figure>\n");
    for (size, class) in sizes.into_iter().zip(["wide", "narrow"]) {
        let svg = plot::svg_string(chart, size)?;
        h.push_str(&inline_svg(&svg, size, class, &chart.title));
        h.push('\n');
    }
    let _ = writeln!(h, "<figcaption>{caption}</figcaption>\n</figure>");
    Ok(())
}

fn header(h: &mut String, loop_id: &str, lf: &LoopFile, d: &Diagnosis, columns: Option<&Columns>) {
    let _ = writeln!(
        h,
        "<header>\n<p class=\"kicker\">Stiction report</p>\n<h1>{}: {}</h1>",
        esc(loop_id),
        verdict_words(d.verdict)
    );
    let [s, e] = d.analysed;
    let _ = writeln!(
        h,
        "<p class=\"meta\">{} samples at {} s, {} in all; analysed samples {s} to {e}{}{}.</p>",
        d.samples,
        num(d.ts),
        seconds(d.samples as f64 * d.ts),
        if lf.auto.is_some() {
            ", in automatic"
        } else {
            ""
        },
        if lf.sp.is_some() {
            " with a constant setpoint"
        } else {
            ""
        },
    );
    if let Some(c) = columns {
        let mut parts = vec![
            format!("OP <code>{}</code>", esc(&c.op)),
            format!("PV <code>{}</code>", esc(&c.pv)),
        ];
        if let Some(sp) = &c.sp {
            parts.push(format!("SP <code>{}</code>", esc(sp)));
        }
        if let Some(m) = &c.mode {
            parts.push(format!("mode <code>{}</code>", esc(m)));
        }
        match (&c.time, &lf.time) {
            (Some(t), _) => parts.push(format!("time <code>{}</code>", esc(t))),
            (None, Some(_)) => parts.push("time column found by its name".into()),
            (None, None) => {}
        }
        if c.integrating {
            parts.push("integrating process".into());
        }
        let _ = writeln!(h, "<p class=\"meta\">Columns: {}.</p>", parts.join(", "));
    }
    h.push_str(
        "<nav class=\"toc\"><a href=\"#trends\">Trends</a><a href=\"#phase\">PV against OP</a>\
         <a href=\"#indices\">Indices</a><a href=\"#oscillation\">Oscillation</a>\
         <a href=\"#estimates\">Estimates</a><a href=\"#convergence\">Convergence</a>\
         <a href=\"#quality\">Data quality</a>",
    );
    if !d.windows.is_empty() {
        h.push_str("<a href=\"#windows\">Windows</a>");
    }
    h.push_str("<a href=\"#notes\">Notes</a></nav>\n</header>\n");
}

fn verdict_box(h: &mut String, d: &Diagnosis) {
    let code = d.verdict.as_str();
    let _ = writeln!(
        h,
        "<section class=\"verdict v-{code}\" id=\"verdict\" aria-label=\"verdict\">\n\
         <div class=\"verdict-head\"><span class=\"verdict-word\">{}</span>{}</div>",
        capital(verdict_words(d.verdict)),
        d.confidence
            .map(|c| format!("<span class=\"confidence\">confidence {c:.2}</span>"))
            .unwrap_or_default()
    );
    if let Some(c) = d.confidence {
        let pct = (c.clamp(0.0, 1.0) * 100.0).round();
        let _ = writeln!(
            h,
            "<div class=\"bar\" aria-hidden=\"true\"><span style=\"width:{pct}%\"></span></div>"
        );
    }
    if let Some(r) = &d.reason {
        let _ = writeln!(
            h,
            "<p class=\"reason\"><strong>Reason:</strong> {}</p>",
            esc(r)
        );
    }
    // for insufficient data and a loop without oscillation the evidence repeats the reason
    let repeats_reason = matches!((d.evidence.as_slice(), &d.reason), ([e], Some(r)) if e == r);
    if !d.evidence.is_empty() && !repeats_reason {
        h.push_str("<p><strong>Evidence</strong></p>\n<ul>\n");
        for e in &d.evidence {
            let _ = writeln!(h, "<li>{}</li>", esc(e));
        }
        h.push_str("</ul>\n");
    }
    if let Some(b) = &d.band {
        let set = b
            .interval_percent_of_span
            .map(|[lo, hi]| format!(" (optimal set {} to {} %)", num(lo), num(hi)))
            .unwrap_or_default();
        let _ = writeln!(
            h,
            "<p class=\"keyfig\"><strong>Stiction band: {} % of valve span</strong>{set}, {}.</p>",
            num(b.band_percent_of_span),
            band_source(b.source)
        );
    }
    let _ = writeln!(
        h,
        "<p><strong>Next step:</strong> {}</p>",
        esc(&d.next_step)
    );
    h.push_str("</section>\n");
}

fn trends(h: &mut String, lf: &LoopFile, d: &Diagnosis, q: Option<&Quantification>) -> Result<()> {
    h.push_str("<section id=\"trends\">\n<h2>Trends</h2>\n");
    let t = time_axis(lf);
    let (unit, per) = time_unit(t.last().copied().unwrap_or(0.0));
    let x_label = format!("time ({unit})");
    let tu: Vec<f64> = t.iter().map(|v| v / per).collect();
    // the fitted model and the estimated valve cover the samples the estimate used
    let [s, e] = d.quantified.unwrap_or(d.analysed);
    let stretch = s < e && e <= t.len();
    let (tp, pv) = decimate(&tu, &lf.pv, TREND_BUCKETS);
    let sp = lf.sp.as_ref().map(|sp| decimate(&tu, sp, TREND_BUCKETS));
    let sim = q
        .filter(|q| stretch && q.pv_simulated.len() == e - s)
        .map(|q| decimate(&tu[s..e], &q.pv_simulated, TREND_BUCKETS));
    let mv = q
        .filter(|q| stretch && q.mv.len() == e - s)
        .map(|q| decimate(&tu[s..e], &q.mv, TREND_BUCKETS));
    let mut series = vec![Series {
        label: "PV".into(),
        x: &tp,
        y: &pv,
        kind: Kind::Line,
        color: 0,
        thin: false,
    }];
    if let Some((x, y)) = &sp {
        series.push(Series {
            label: "SP".into(),
            x,
            y,
            kind: Kind::Line,
            color: 2,
            thin: false,
        });
    }
    if let Some((x, y)) = &sim {
        series.push(Series {
            label: "PV simulated".into(),
            x,
            y,
            kind: Kind::Line,
            color: 1,
            thin: false,
        });
    }
    let chart = Chart {
        title: "Process variable".into(),
        x_label: x_label.clone(),
        y_label: "PV".into(),
        y_range: headroom(&series, 0.45),
        series,
        bands: vec![],
    };
    let mut caption = String::from("Process variable");
    if sp.is_some() {
        caption.push_str(" and setpoint");
    }
    if sim.is_some() {
        caption.push_str(
            "; in red the PV the fitted valve-and-process model simulates from OP alone, over the samples the estimate used",
        );
    }
    caption.push('.');
    figure(h, &chart, TREND_SIZE, &caption)?;

    let (to, op) = decimate(&tu, &lf.op, TREND_BUCKETS);
    let mut series = vec![Series {
        label: "OP".into(),
        x: &to,
        y: &op,
        kind: Kind::Line,
        color: 0,
        thin: false,
    }];
    if let Some((x, y)) = &mv {
        series.push(Series {
            label: "estimated MV".into(),
            x,
            y,
            kind: Kind::Step,
            color: 1,
            thin: false,
        });
    }
    let chart = Chart {
        title: "Controller output".into(),
        x_label,
        y_label: "OP".into(),
        y_range: headroom(&series, 0.35),
        series,
        bands: vec![],
    };
    let caption = if mv.is_some() {
        "Controller output and, in red, the valve position the fitted stiction model estimates \
         (the valve is not measured: it holds until OP has moved more than the band away from it)."
    } else {
        "Controller output."
    };
    figure(h, &chart, TREND_SIZE, caption)?;
    if s > 0 || e < d.samples {
        let _ = writeln!(
            h,
            "<p class=\"note\">The diagnosis uses samples {s} to {e} (t = {} to {} s); \
             the rest of the record is in manual, or has another setpoint.</p>",
            num(t.get(s).copied().unwrap_or(0.0)),
            num(t.get(e.saturating_sub(1)).copied().unwrap_or(0.0))
        );
    }
    h.push_str("</section>\n");
    Ok(())
}

fn phase(h: &mut String, lf: &LoopFile, d: &Diagnosis, q: Option<&Quantification>) -> Result<()> {
    h.push_str("<section id=\"phase\">\n<h2>PV against OP</h2>\n");
    let [s, e] = d.quantified.unwrap_or(d.analysed);
    let (s, e) = if s + 1 < e && e <= lf.op.len() {
        (s, e)
    } else {
        (0, lf.op.len())
    };
    let op = thin(&lf.op[s..e], PHASE_POINTS);
    let pv = thin(&lf.pv[s..e], PHASE_POINTS);
    let sim = q
        .filter(|q| q.pv_simulated.len() == e - s)
        .map(|q| thin(&q.pv_simulated, PHASE_POINTS));
    let mut series = vec![Series {
        label: "measured".into(),
        x: &op,
        y: &pv,
        kind: Kind::Line,
        color: 5,
        thin: false,
    }];
    if let Some(y) = &sim {
        series.push(Series {
            label: "fitted model, simulated".into(),
            x: &op,
            y,
            kind: Kind::Line,
            color: 1,
            thin: false,
        });
    }
    let title = match q.and_then(|q| q.apparent_stiction.map(|b| (q, b))) {
        Some((q, b)) if sim.is_some() => {
            format!(
                "PV against OP, with the fitted {} model (d = {})",
                capital(&q.model.to_string()),
                num(b)
            )
        }
        _ => "PV against OP".into(),
    };
    let chart = Chart {
        title,
        x_label: "controller output OP".into(),
        y_label: "process variable PV".into(),
        y_range: headroom(&series, 0.25),
        series,
        bands: vec![],
    };
    let caption = if sim.is_some() {
        "The measured PV against OP (grey) over the analysed stretch, and the PV the fitted model \
         simulates (red). While a sticky valve holds, OP moves and PV does not follow: the plot draws \
         a loop rather than a line."
    } else {
        "The measured PV against OP over the analysed stretch. While a sticky valve holds, OP moves \
         and PV does not follow: the plot draws a loop rather than a line. No model was fitted."
    };
    figure(h, &chart, PHASE_SIZE, caption)?;
    h.push_str("</section>\n");
    Ok(())
}

fn band_source(s: BandSource) -> &'static str {
    match s {
        BandSource::Valve => "from the recorded valve position",
        BandSource::ClosedLoop => "the closed-loop estimate (Stenman, exact)",
        BandSource::FitScan => "the closed-loop fit's scan of the Stenman band",
        BandSource::StickSlip => "the median OP travel per stick",
        BandSource::DescribingFunction => "the describing function of the loop's limit cycle",
    }
}

fn families(h: &mut String, d: &Diagnosis) {
    h.push_str(
        "<h3>Families of evidence</h3>\n<p class=\"note\">Independent ways of asking whether the \
         valve sticks; families that agree decide, families that conflict leave the verdict \
         undetermined.</p>\n<div class=\"scroll\"><table class=\"wide\">\n<thead><tr><th>Family</th>\
         <th>Value</th><th>Vote</th><th>Statistic</th><th>Threshold</th><th>Why</th></tr></thead>\n<tbody>\n",
    );
    for f in &d.families {
        let _ = writeln!(
            h,
            "<tr><td>{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"text\">{}</td>\
             <td class=\"text\">{}</td><td class=\"text\">{}</td></tr>",
            esc(f.family.words()),
            opt(f.value),
            vote_chip(f.vote),
            esc(&f.statistic),
            esc(&f.threshold),
            esc(&f.note)
        );
    }
    h.push_str("</tbody></table></div>\n");
}

fn indices(h: &mut String, d: &Diagnosis) {
    h.push_str("<section id=\"indices\">\n<h2>Evidence</h2>\n");
    families(h, d);
    h.push_str("<h3>Stiction indices (shape of the oscillation)</h3>\n");
    if d.indices.is_empty() {
        let why = match d.verdict {
            Verdict::InsufficientData => "the record cannot carry a verdict (see the reason above)",
            _ => "the loop does not oscillate regularly with a constant setpoint, so there is no shape for them to read",
        };
        let _ = writeln!(h, "<p>No index was computed: {why}.</p>");
    } else {
        h.push_str(
            "<p class=\"note\">Each index votes stiction, no stiction or undetermined against its \
             published threshold; the shape family's vote is their weighted vote.</p>\n\
             <div class=\"scroll\"><table class=\"wide\">\n<thead><tr><th>Index</th><th>Value</th>\
             <th>Vote</th><th>Threshold</th><th>Weight</th><th>Reference</th><th>Note</th></tr></thead>\n<tbody>\n",
        );
        for i in &d.indices {
            let _ = writeln!(
                h,
                "<tr><td><code>{}</code></td><td class=\"num\">{}</td><td>{}</td><td class=\"text\">{}</td>\
                 <td class=\"num\">{}</td><td class=\"text\">{}</td><td class=\"text\">{}</td></tr>",
                esc(&i.name),
                opt(i.value),
                vote_chip(i.vote),
                esc(&i.threshold),
                num(i.weight),
                esc(&i.reference),
                esc(&i.note)
            );
        }
        h.push_str("</tbody></table></div>\n");
    }
    h.push_str("</section>\n");
}

fn kv(h: &mut String, rows: &[(&str, String)]) {
    h.push_str("<div class=\"scroll\"><table class=\"kv\"><tbody>\n");
    for (k, v) in rows {
        let _ = writeln!(h, "<tr><th scope=\"row\">{k}</th><td>{v}</td></tr>");
    }
    h.push_str("</tbody></table></div>\n");
}

fn oscillation(h: &mut String, d: &Diagnosis) {
    h.push_str("<section id=\"oscillation\">\n<h2>Oscillation</h2>\n");
    match &d.oscillation {
        None => h.push_str("<p>Not assessed: the data-quality gates failed.</p>\n"),
        Some(o) => {
            let r = &o.regularity;
            kv(
                h,
                &[
                    (
                        "Oscillating",
                        if o.oscillating {
                            "yes: regular and above the noise".into()
                        } else {
                            "no".into()
                        },
                    ),
                    ("Period", o.period.map_or("–".into(), seconds)),
                    ("Periods in the analysed stretch", opt(o.periods_in_record)),
                    (
                        "Regularity (Thornhill)",
                        format!(
                            "{} (regular above {}; {} zero crossings of the autocorrelation)",
                            num(r.regularity),
                            num(r.threshold),
                            r.zero_crossings
                        ),
                    ),
                    (
                        "Half periods with a large IAE (Hägglund)",
                        format!(
                            "{} in the record, at most {} in one supervision window of {} (limit {}; IAE limit {})",
                            o.iae.exceedances,
                            o.iae.most_in_window,
                            seconds(o.iae.window),
                            o.iae.n_lim,
                            num(o.iae.iae_limit)
                        ),
                    ),
                    (
                        "Amplitude of the control error",
                        format!("{} (half the 5 %–95 % range)", num(o.amplitude)),
                    ),
                    ("Noise standard deviation", num(o.noise_std)),
                ],
            );
        }
    }
    h.push_str("</section>\n");
}

fn estimates(h: &mut String, d: &Diagnosis, q: Option<&Quantification>) {
    h.push_str("<section id=\"estimates\">\n<h2>Estimates</h2>\n<h3>Apparent stiction</h3>\n");
    let closed = match (&d.band, q) {
        (Some(b), _) => {
            let set = b
                .interval_percent_of_span
                .map(|[lo, hi]| format!("; optimal set {} to {} %", num(lo), num(hi)))
                .unwrap_or_default();
            let failed = d.warnings.iter().any(|w| w.contains("estimate failed"));
            let skipped = if b.source != BandSource::Valve && d.quantification.is_none() && !failed
            {
                " (the exact closed-loop estimate was not run: <code>--no-quantify</code>)"
            } else {
                ""
            };
            format!(
                "<strong>{} % of valve span</strong> ({} OP units), {}{set}{skipped}",
                num(b.band_percent_of_span),
                num(b.op_units),
                band_source(b.source)
            )
        }
        (None, _) => match d.quantification.as_ref() {
            Some(q) if q.status != "ok" => format!(
                "not estimated: {}",
                esc(q.reason.as_deref().unwrap_or("insufficient data"))
            ),
            _ if d.verdict != Verdict::Stiction => {
                "not estimated: the band is sized only when the verdict is stiction".into()
            }
            _ if d.warnings.iter().any(|w| w.contains("estimate failed")) => {
                "not estimated: it failed (see the notes)".into()
            }
            _ => "not estimated (<code>--no-quantify</code>)".into(),
        },
    };
    let ellipse = d
        .band
        .as_ref()
        .and_then(|b| b.ellipse_percent_of_span)
        .map_or("not computed".into(), |v| format!("{} % of span", num(v)));
    let mut rows = vec![
        ("Stiction band", closed),
        ("Ellipse fit of the PV-OP plot (Choudhury et al.)", ellipse),
    ];
    if let Some(m) = d.families.iter().find_map(|f| f.model.as_ref()) {
        rows.push((
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
        let how = match q.and_then(|q| q.valve_start_kind.as_deref()) {
            Some("estimated") => "estimated (<code>--estimate-start</code>)",
            Some("given") => "given",
            _ => "assumed at the first OP (<code>--estimate-start</code> estimates it)",
        };
        rows.push((
            "Valve position at the first sample",
            format!("{}, {how}", num(x0)),
        ));
    }
    kv(h, &rows);
    if let Some(q) = q {
        if !q.interval.is_empty() && q.interval_kind.starts_with("exact") {
            h.push_str(
                "<p class=\"note\">The optimal set holds every d whose valve trajectory gives the \
                 least simulation error: the data cannot tell these values apart.</p>\n",
            );
        }
        if let Some(lm) = &q.linear_model {
            h.push_str("<h3>Linear process model</h3>\n");
            let gain = match (lm.gain, lm.family.as_str()) {
                (Some(g), "integrating") => format!("{} per s (integration rate)", num(g)),
                (Some(g), _) => num(g),
                (None, _) => "–".into(),
            };
            let mut rows = vec![
                ("Family", esc(&lm.family.replace('_', "-"))),
                ("Orders", format!("na = {}, nb = {} (ARX)", lm.na, lm.nb)),
                (
                    "Delay",
                    format!(
                        "{} samples from valve to output (1: the next sample)",
                        lm.nk
                    ),
                ),
                ("Gain", gain),
                (
                    "Time constant",
                    lm.time_constant.map_or("–".into(), seconds),
                ),
                ("Dead time", seconds(lm.dead_time)),
            ];
            if let Some(f) = &q.fit {
                let what = if f.output == "pv" {
                    "PV"
                } else {
                    "the change of PV per sample"
                };
                rows.push((
                    "R² (fit)",
                    format!(
                        "{} in simulation, {} one step ahead, of {what}",
                        num(f.r2_simulation),
                        num(f.r2_one_step)
                    ),
                ));
            }
            rows.push(("Chosen by", esc(&lm.criterion)));
            kv(h, &rows);
        }
    }
    h.push_str("</section>\n");
}

fn convergence(h: &mut String, q: Option<&Quantification>) {
    h.push_str("<section id=\"convergence\">\n<h2>Estimator convergence</h2>\n");
    let Some(q) = q else {
        h.push_str("<p>No closed-loop estimate was run.</p>\n</section>\n");
        return;
    };
    kv(
        h,
        &[
            ("Method", format!("{} ({} model)", q.method, q.model)),
            ("Evaluations", q.evaluations.to_string()),
            (
                "Distinct valve trajectories (cells)",
                q.cells.map_or("–".into(), |c| c.to_string()),
            ),
            ("Time", seconds(q.seconds)),
            ("Samples", format!("{} at {} s", q.samples, num(q.ts))),
        ],
    );
    let why = match q.interval_kind.as_str() {
        "exact" => {
            "The exact method does not search: the band d changes the estimated valve \
                    trajectory only at a finite set of values, so the whole range of d splits into \
                    cells with one valve trajectory each; every cell was fitted once. The optimum \
                    is proven over every distinct valve trajectory, not found by chance."
        }
        "exact_staged" => {
            "The exact method does not search: the band d changes the estimated valve \
                    trajectory only at a finite set of values, so the whole range of d splits into \
                    cells with one valve trajectory each. Every cell of the first samples was fitted, \
                    then, on the whole record, every cell inside the best of them (each cell of the \
                    whole record lies inside one cell of its first samples). The optimum is proven \
                    over every distinct valve trajectory kept, not found by chance."
        }
        "exact_local" => {
            "The exact method fitted every valve trajectory near the best points of a \
                          coarse scan: the optimum is proven there only."
        }
        _ => "A search method: the optimum is the best point found, not proven.",
    };
    let _ = writeln!(h, "<p>{why}</p>");
    h.push_str("</section>\n");
}

fn quality(h: &mut String, d: &Diagnosis) {
    h.push_str("<section id=\"quality\">\n<h2>Data quality</h2>\n");
    let failed = d.quality.iter().filter(|f| !f.passed).count();
    let _ = writeln!(
        h,
        "<p>{}</p>",
        if failed == 0 {
            format!("Every gate passed ({} checked).", d.quality.len())
        } else {
            format!(
                "{failed} of {} gates failed: the record cannot carry a verdict.",
                d.quality.len()
            )
        }
    );
    h.push_str(
        "<div class=\"scroll\"><table class=\"wide\">\n<thead><tr><th>Gate</th><th>Result</th>\
         <th>Value</th><th>Limit</th><th>Finding</th></tr></thead>\n<tbody>\n",
    );
    for f in &d.quality {
        let (class, word) = if f.passed {
            ("passed", "passed")
        } else {
            ("failed", "failed")
        };
        let _ = writeln!(
            h,
            "<tr class=\"{class}\"><td><code>{}</code></td><td><span class=\"chip {class}\">{word}</span></td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td class=\"text\">{}</td></tr>",
            esc(&f.gate),
            num(f.value),
            num(f.limit),
            esc(&f.message)
        );
    }
    h.push_str("</tbody></table></div>\n</section>\n");
}

fn verdict_fill(v: Verdict) -> &'static str {
    match v {
        Verdict::Stiction => "#d9534f",
        Verdict::NoStiction => "#43a047",
        Verdict::Undetermined => "#f0a500",
        Verdict::InsufficientData => "#b7bec5",
    }
}

/// The windows as a coloured strip: hand-written SVG, one rectangle per window.
fn timeline(h: &mut String, ws: &[WindowVerdict], samples: usize) {
    let total = samples.max(1) as f64;
    let (w, ht) = (1000.0, 36.0);
    let _ = write!(
        h,
        "<figure class=\"timeline\"><svg viewBox=\"0 0 {w} {ht}\" width=\"100%\" role=\"img\" \
         aria-label=\"verdict per window\">"
    );
    for win in ws {
        let x = w * win.start as f64 / total;
        let width = (w * (win.end - win.start) as f64 / total - 1.0).max(0.5);
        let _ = write!(
            h,
            "<rect x=\"{x:.1}\" y=\"2\" width=\"{width:.1}\" height=\"{}\" fill=\"{}\">\
             <title>samples {} to {}: {}</title></rect>",
            ht - 4.0,
            verdict_fill(win.verdict),
            win.start,
            win.end,
            verdict_words(win.verdict)
        );
    }
    h.push_str("</svg><figcaption class=\"legend\">");
    for v in [
        Verdict::Stiction,
        Verdict::NoStiction,
        Verdict::Undetermined,
        Verdict::InsufficientData,
    ] {
        let _ = write!(
            h,
            "<span><i style=\"background:{}\"></i>{}</span>",
            verdict_fill(v),
            verdict_words(v)
        );
    }
    h.push_str("</figcaption></figure>\n");
}

fn windows(h: &mut String, d: &Diagnosis) {
    if d.windows.is_empty() {
        return;
    }
    h.push_str("<section id=\"windows\">\n<h2>Verdict per window</h2>\n");
    timeline(h, &d.windows, d.samples);
    h.push_str(
        "<div class=\"scroll\"><table class=\"wide\">\n<thead><tr><th>Samples</th><th>Time (s)</th>\
         <th>Verdict</th><th>Confidence</th><th>Period</th><th>Votes</th>",
    );
    let reasons = d.windows.iter().any(|w| w.reason.is_some());
    if reasons {
        h.push_str("<th>Reason</th>");
    }
    h.push_str("</tr></thead>\n<tbody>\n");
    for w in &d.windows {
        let votes: Vec<String> = w
            .votes
            .iter()
            .map(|(n, v)| format!("{} {}", esc(n.words()), vote_chip(*v)))
            .collect();
        let _ = write!(
            h,
            "<tr><td class=\"num\">{} to {}</td><td class=\"num\">{} to {}</td><td>{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td>",
            w.start,
            w.end,
            num(w.t_start),
            num(w.t_end),
            verdict_chip(w.verdict),
            w.confidence.map_or("–".into(), |c| format!("{c:.2}")),
            w.period.map_or("–".into(), seconds),
            if votes.is_empty() {
                "–".into()
            } else {
                votes.join("<br>")
            },
        );
        if reasons {
            let _ = write!(
                h,
                "<td class=\"text\">{}</td>",
                esc(w.reason.as_deref().unwrap_or(""))
            );
        }
        h.push_str("</tr>\n");
    }
    h.push_str("</tbody></table></div>\n</section>\n");
}

fn notes(h: &mut String, d: &Diagnosis, q: Option<&Quantification>) {
    h.push_str("<section id=\"notes\">\n<h2>Notes and caveat</h2>\n");
    let warnings: Vec<&String> = d
        .warnings
        .iter()
        .chain(q.iter().flat_map(|q| q.warnings.iter()))
        .collect();
    if !warnings.is_empty() {
        h.push_str("<ul>\n");
        for w in warnings {
            let _ = writeln!(h, "<li>{}</li>", esc(w));
        }
        h.push_str("</ul>\n");
    }
    let caveat = match d.quantification.as_ref() {
        Some(q) => capital(&q.caveat),
        None => {
            "No closed-loop estimate was run: the verdict rests on the indices, which read the \
                 valve's behaviour from OP and PV without measuring the valve position"
                .into()
        }
    };
    let _ = writeln!(
        h,
        "<p class=\"caveat\">{}.</p>",
        esc(caveat.trim_end_matches('.'))
    );
    h.push_str("</section>\n");
}
