//! The fleet page (`index.html` of `stiction batch --reports`): every loop ranked, with its
//! verdict, band in % of valve span, a sparkline of PV and OP, and a link to its report. Sorting
//! by any column and a verdict filter take a few lines of inline script; under 600 px the table
//! turns into one card per loop (CSS only).

use super::{render_template, Link};
use crate::words::{self, num};
use anyhow::Result;
use serde::Serialize;
use stiction_core::diagnose::reach;
use stiction_core::fleet::{Counts, Outcome, Row};

/// Points per series of a sparkline: 50 buckets, the lowest and highest sample of each.
pub const SPARK_POINTS: usize = 100;

/// A loop's PV and OP for the fleet page: at most [`SPARK_POINTS`] points each, scaled to 0..=255
/// over the series' own range (the shape is what a sparkline shows): 200 bytes a loop, however
/// long its record.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Spark {
    pub pv: Vec<u8>,
    pub op: Vec<u8>,
}

impl Spark {
    pub fn of(pv: &[f64], op: &[f64]) -> Spark {
        Spark {
            pv: squeeze(pv),
            op: squeeze(op),
        }
    }
}

/// The lowest and highest finite sample of each of `SPARK_POINTS / 2` buckets, in time order
/// (spikes survive), scaled to 0..=255.
fn squeeze(v: &[f64]) -> Vec<u8> {
    let finite = v.iter().copied().filter(|x| x.is_finite());
    let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    });
    if lo > hi {
        return Vec::new();
    }
    let scale = |x: f64| {
        if hi > lo {
            ((x - lo) / (hi - lo) * 255.0).round() as u8
        } else {
            128
        }
    };
    let buckets = SPARK_POINTS / 2;
    if v.len() <= SPARK_POINTS {
        return v
            .iter()
            .filter(|x| x.is_finite())
            .map(|&x| scale(x))
            .collect();
    }
    let mut out = Vec::with_capacity(SPARK_POINTS);
    for b in 0..buckets {
        let part = &v[b * v.len() / buckets..(b + 1) * v.len() / buckets];
        let mut ext: Option<((usize, f64), (usize, f64))> = None;
        for (k, &x) in part.iter().enumerate().filter(|(_, x)| x.is_finite()) {
            ext = Some(match ext {
                None => ((k, x), (k, x)),
                Some((mn, mx)) => (
                    if x < mn.1 { (k, x) } else { mn },
                    if x > mx.1 { (k, x) } else { mx },
                ),
            });
        }
        if let Some((mn, mx)) = ext {
            let (first, second) = if mn.0 <= mx.0 { (mn, mx) } else { (mx, mn) };
            out.push(scale(first.1));
            out.push(scale(second.1));
        }
    }
    out
}

/// SVG polyline points of a scaled series in a 100 × 24 box (1 unit of margin top and bottom).
fn points(v: &[u8]) -> String {
    let n = v.len().max(2) - 1;
    v.iter()
        .enumerate()
        .map(|(i, &y)| {
            let x = 100.0 * i as f64 / n as f64;
            let y = 23.0 - 22.0 * f64::from(y) / 255.0;
            format!("{x:.1},{y:.1}")
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// A loop as the fleet page shows it: what each cell prints, and the value it sorts by.
#[derive(Serialize)]
pub struct FleetRow {
    pub rank: usize,
    pub loop_id: String,
    /// The report's address, relative to the page, when the loop has one.
    pub href: Option<String>,
    pub source: String,
    pub verdict: &'static str,
    pub verdict_words: &'static str,
    /// The verdict's place in the ranking order (stiction first), its sort key.
    pub verdict_rank: usize,
    pub probability: Cell,
    pub severity: Cell,
    pub band: Cell,
    /// Where the verdict is not `stiction`: the band, % of span, under which a sticky valve
    /// mostly goes unseen in a record with this OP's noise (`Reach::small_band_percent_of_span`).
    pub hidden: Cell,
    pub period: Cell,
    pub reason: String,
    pub spark: Option<SparkPoints>,
}

#[derive(Serialize)]
pub struct Cell {
    pub text: String,
    /// The sort key; empty (sorted last) when there is no value.
    pub key: String,
}

fn cell(v: Option<f64>) -> Cell {
    match v {
        Some(x) if x.is_finite() => Cell {
            text: num(x),
            key: format!("{x}"),
        },
        Some(x) if x > 0.0 => Cell {
            text: "∞".into(),
            key: "1e308".into(),
        },
        _ => Cell {
            text: "–".into(),
            key: String::new(),
        },
    }
}

#[derive(Serialize)]
pub struct SparkPoints {
    pub pv: String,
    pub op: String,
}

/// A verdict with its count, for the summary line and the filter.
#[derive(Serialize)]
pub struct Count {
    pub code: &'static str,
    pub words: &'static str,
    pub n: usize,
}

#[derive(Serialize)]
struct FleetPage<'a> {
    version: &'static str,
    loops: usize,
    complete: bool,
    counts: Vec<Count>,
    rows: &'a [FleetRow],
    back: Option<Link>,
    reach: ReachWords,
}

/// What the "hidden under" column means: the small band of `diagnose::reach`, in OP noise
/// standard deviations.
#[derive(Serialize)]
struct ReachWords {
    times: String,
}

/// One loop of the page: the fleet row, its source in words, whether it has a report, its
/// sparkline when the batch kept one.
pub struct Entry<'a> {
    pub row: &'a Row,
    pub source: String,
    pub report: bool,
    pub spark: Option<&'a Spark>,
    /// Other loops of the fleet that oscillate at this loop's period.
    pub same_period: usize,
}

pub fn row(rank: usize, e: &Entry) -> FleetRow {
    let r = e.row;
    FleetRow {
        rank,
        loop_id: r.loop_id.clone(),
        href: e.report.then(|| format!("reports/{}.html", r.loop_id)),
        source: e.source.clone(),
        verdict: r.verdict.as_str(),
        verdict_words: words::outcome(r.verdict),
        verdict_rank: Outcome::ALL
            .iter()
            .position(|&o| o == r.verdict)
            .unwrap_or(0),
        probability: cell(r.probability),
        severity: cell(Some(r.severity)),
        band: cell(r.band_percent_of_span),
        hidden: cell(
            r.small_band_percent_of_span
                .filter(|_| r.verdict != Outcome::Stiction),
        ),
        period: match (cell(r.period_s), e.same_period) {
            (c, 0) => c,
            (Cell { text, key }, n) => Cell {
                text: format!("{text} +{n}"),
                key,
            },
        },
        reason: r.reason.clone(),
        spark: e
            .spark
            .filter(|s| s.pv.len() > 1 && s.op.len() > 1)
            .map(|s| SparkPoints {
                pv: points(&s.pv),
                op: points(&s.op),
            }),
    }
}

/// The page for the rows, in their order (ranked).
pub fn page(rows: &[FleetRow], counts: &Counts, complete: bool) -> Result<String> {
    let counts = Outcome::ALL
        .iter()
        .map(|&o| Count {
            code: o.as_str(),
            words: words::outcome(o),
            n: counts.get(o),
        })
        .filter(|c| c.n > 0)
        .collect();
    render_template(
        "fleet.html",
        FleetPage {
            version: env!("CARGO_PKG_VERSION"),
            loops: rows.len(),
            complete,
            counts,
            rows,
            back: None,
            reach: ReachWords {
                times: format!("{}", reach::SMALL),
            },
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sparkline_is_bounded_and_keeps_spikes() {
        let mut pv = vec![1.0; 1_000_000];
        pv[424_242] = 5.0;
        pv[10] = f64::NAN;
        let s = Spark::of(&pv, &pv);
        assert!(s.pv.len() <= SPARK_POINTS, "{}", s.pv.len());
        assert!(s.pv.contains(&255), "the spike survives");
        assert_eq!(Spark::of(&[1.0, 2.0], &[3.0]).op, vec![128]);
        assert!(Spark::of(&[], &[]).pv.is_empty());
        let p = points(&[0, 255]);
        assert_eq!(p, "0.0,23.0 100.0,1.0");
    }
}
