//! The verdict per window, as a strip and a table.

use super::*;

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
    pub probability: String,
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
            probability: w.probability.map_or("–".into(), |p| format!("{p:.2}")),
            period: w.period.map_or("–".into(), duration),
            votes: w
                .votes
                .iter()
                .map(|(n, v)| (n.words(), vote_chip(*v)))
                .collect(),
            reason: w
                .reasons
                .iter()
                .map(crate::context::reason_text)
                .collect::<Vec<_>>()
                .join("; "),
        })
        .collect();
    Some(Windows {
        strip,
        legend,
        reasons: d.windows.iter().any(|w| !w.reasons.is_empty()),
        rows,
    })
}
