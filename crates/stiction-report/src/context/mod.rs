//! The loop report's context: every value the template shows, built from the loop's data and
//! its diagnosis as plain serialisable structs (text, numbers already in words, figures as SVG).
//! The template lays it out and escapes every text; nothing here writes HTML but the charts.

use super::plots::{self, Figure, PHASE_SIZE, TREND_SIZE};
use super::sections::{self, Estimates, Evidence, KvRow, Notes, Quality, Windows};
use super::series::{self, LONG_RECORD};
use super::PageOptions;
use crate::words::{self, capital, duration, num, verdict};
use crate::{ColumnNames, LoopData};
use anyhow::Result;
use serde::Serialize;
use stiction_core::diagnose::{Diagnosis, Reason, Verdict, VerdictModel};
use stiction_core::quantify::{Quantification, QuantifyStatus};

mod figures;

use figures::{phase, trends, zoom};
pub use figures::{Trends, Zoom};

/// Text with a little markup: plain runs, `code` runs and `strong` runs.
#[derive(Serialize, Default)]
pub struct Rich(Vec<Piece>);

#[derive(Serialize)]
struct Piece {
    kind: &'static str,
    text: String,
}

impl Rich {
    fn push(mut self, kind: &'static str, text: impl Into<String>) -> Rich {
        self.0.push(Piece {
            kind,
            text: text.into(),
        });
        self
    }
    pub fn text(self, t: impl Into<String>) -> Rich {
        self.push("text", t)
    }
    pub fn code(self, t: impl Into<String>) -> Rich {
        self.push("code", t)
    }
    pub fn strong(self, t: impl Into<String>) -> Rich {
        self.push("strong", t)
    }
}

/// Plain text as [`Rich`].
pub fn rich(t: impl Into<String>) -> Rich {
    Rich::default().text(t)
}

#[derive(Serialize)]
pub struct VerdictBox {
    pub code: &'static str,
    pub word: String,
    /// The probability of a sticky valve, as the page prints it.
    pub probability: Option<String>,
    pub bar_percent: Option<f64>,
    /// The verdict's thresholds on the bar, % of its width, and in words.
    pub thresholds: Thresholds,
    /// The one or two findings that decided the verdict, in words.
    pub reasons: Vec<String>,
    pub band: Option<BandLine>,
    pub next_step: String,
    /// What a record like this one can show (verdicts other than stiction).
    pub reach: Option<String>,
}

/// The verdict model's thresholds, where the bar marks them.
#[derive(Serialize)]
pub struct Thresholds {
    pub below_percent: f64,
    pub from_percent: f64,
    pub words: String,
}

#[derive(Serialize)]
pub struct BandLine {
    pub percent: String,
    pub set: Option<String>,
    pub source: &'static str,
}

#[derive(Serialize)]
pub struct Link {
    pub href: String,
    pub text: String,
}

/// Everything the report template shows.
#[derive(Serialize)]
pub struct Report {
    pub version: &'static str,
    pub title: String,
    pub loop_id: String,
    pub verdict_words: &'static str,
    pub back: Option<Link>,
    pub meta: String,
    pub columns: Vec<Rich>,
    pub toc: Vec<Link>,
    pub verdict: VerdictBox,
    pub trends: Trends,
    pub zoom: Option<Zoom>,
    pub phase: Figure,
    pub evidence: Evidence,
    pub oscillation: Option<Vec<KvRow>>,
    pub estimates: Estimates,
    pub convergence: Option<sections::Convergence>,
    pub quality: Quality,
    pub windows: Option<Windows>,
    pub notes: Notes,
    pub seconds: String,
}

pub fn build(loop_id: &str, data: &LoopData, d: &Diagnosis, o: &PageOptions) -> Result<Report> {
    let q = d
        .quantification
        .as_ref()
        .filter(|q| q.status == QuantifyStatus::Ok);
    let zoom = if data.op.len() > LONG_RECORD {
        Some(zoom(data, d, q)?)
    } else {
        None
    };
    Ok(Report {
        version: env!("CARGO_PKG_VERSION"),
        title: format!("{loop_id}: {}", verdict(d.verdict)),
        loop_id: loop_id.to_string(),
        verdict_words: verdict(d.verdict),
        back: o.back_link.as_ref().map(|(href, text)| Link {
            href: href.clone(),
            text: text.clone(),
        }),
        meta: meta(data, d),
        columns: o.columns.map(|c| columns(c, data)).unwrap_or_default(),
        toc: toc(d, zoom.is_some()),
        verdict: verdict_box(d),
        trends: trends(data, d, q)?,
        zoom,
        phase: phase(data, d, q)?,
        evidence: sections::evidence(d),
        oscillation: sections::oscillation(d),
        estimates: sections::estimates(d, q),
        convergence: q.map(sections::convergence),
        quality: sections::quality(d),
        windows: sections::windows(d),
        notes: sections::notes(d, q, o.reading),
        seconds: num(d.seconds),
    })
}

fn meta(data: &LoopData, d: &Diagnosis) -> String {
    let [s, e] = d.analysed;
    format!(
        "{} samples at {} s, {} in all; analysed samples {s} to {e}{}{}{}.",
        d.samples,
        num(d.ts),
        duration(d.samples as f64 * d.ts),
        if data.auto.is_some() {
            ", in automatic"
        } else {
            ""
        },
        setpoint_words(data.sp, [s, e]),
        d.judged_on.as_ref().map_or(String::new(), |j| format!(
            "; {}",
            crate::words::judged_on(j, d.analysed)
        )),
    )
}

/// What the setpoint does over the analysed samples `[s, e)`, for the page's header.
fn setpoint_words(sp: Option<&[f64]>, [s, e]: [usize; 2]) -> &'static str {
    match sp.and_then(|sp| sp.get(s..e)) {
        Some(sp) if sp.windows(2).all(|w| w[0] == w[1]) => " with a constant setpoint",
        Some(_) => " with its setpoint changes",
        None => "",
    }
}

fn columns(c: &ColumnNames, data: &LoopData) -> Vec<Rich> {
    let mut parts = vec![rich("OP ").code(&c.op), rich("PV ").code(&c.pv)];
    if let Some(sp) = &c.sp {
        parts.push(rich("SP ").code(sp));
    }
    if let Some(m) = &c.mode {
        parts.push(rich("mode ").code(m));
    }
    match (&c.time, &data.time) {
        (Some(t), _) => parts.push(rich("time ").code(t)),
        (None, Some(_)) => parts.push(rich("time column found by its name")),
        (None, None) => {}
    }
    if c.integrating {
        parts.push(rich("integrating process"));
    }
    parts
}

fn toc(d: &Diagnosis, zoom: bool) -> Vec<Link> {
    let mut links = vec![("trends", "Trends")];
    if zoom {
        links.push(("zoom", "Zoom"));
    }
    links.extend([
        ("phase", "PV against OP"),
        ("evidence", "How it was decided"),
        ("oscillation", "Oscillation"),
        ("estimates", "Estimates"),
        ("convergence", "Convergence"),
        ("quality", "Data quality"),
    ]);
    if !d.windows.is_empty() {
        links.push(("windows", "Windows"));
    }
    links.push(("notes", "Notes"));
    links
        .into_iter()
        .map(|(id, text)| Link {
            href: format!("#{id}"),
            text: text.into(),
        })
        .collect()
}

fn verdict_box(d: &Diagnosis) -> VerdictBox {
    let model = VerdictModel::embedded();
    VerdictBox {
        code: d.verdict.as_str(),
        word: capital(verdict(d.verdict)),
        probability: d.probability.map(|p| format!("{p:.2}")),
        bar_percent: d.probability.map(|p| (p.clamp(0.0, 1.0) * 100.0).round()),
        thresholds: Thresholds {
            below_percent: (100.0 * model.no_stiction_below).round(),
            from_percent: (100.0 * model.stiction_from).round(),
            words: format!(
                "no stiction under {:.2}, stiction from {:.2}, undetermined between",
                model.no_stiction_below, model.stiction_from
            ),
        },
        reasons: d.reasons.iter().map(reason_text).collect(),
        band: d.band.as_ref().map(|b| BandLine {
            percent: num(b.band_percent_of_span),
            set: b
                .interval_percent_of_span
                .map(|[lo, hi]| format!("optimal set {} to {} %", num(lo), num(hi))),
            source: b.source.words(),
        }),
        next_step: if d.next_step.text.is_empty() {
            words::next_step(&d.next_step)
        } else {
            d.next_step.text.clone()
        },
        reach: d
            .reach
            .as_ref()
            .filter(|_| d.verdict != Verdict::Stiction)
            .map(words::reach),
    }
}

/// A reason's words: its `text` when the front end filled it, else worded here.
pub fn reason_text(r: &Reason) -> String {
    if r.text.is_empty() {
        words::reason(r)
    } else {
        r.text.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::setpoint_words;

    #[test]
    fn the_header_says_what_the_setpoint_does_where_the_diagnosis_looked() {
        let sp = [50.0, 50.0, 50.0, 55.0, 55.0];
        assert_eq!(
            setpoint_words(Some(&sp), [0, 3]),
            " with a constant setpoint"
        );
        assert_eq!(
            setpoint_words(Some(&sp), [0, 5]),
            " with its setpoint changes"
        );
        assert_eq!(setpoint_words(None, [0, 5]), "");
    }
}
