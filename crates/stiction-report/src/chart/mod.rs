//! Charts: what one shows ([`Chart`]) and how it is drawn on any plotters backend ([`draw`]);
//! [`svg_string`] for the pages' inline SVG. Plotting takes finished result data; it never
//! computes. (The CLI draws the same charts into PNG and SVG files with its own backend.)
//!
//! Every chart has its title on top, its legend in a strip between the title and the data (never
//! over the data), and tick labels without trailing zeros or a negative zero.

mod ticks;

pub use ticks::tick_label;

use anyhow::{anyhow, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::sync::Once;

/// DejaVu Sans, embedded so charts need no system fonts (licence in assets/).
pub static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Register [`FONT`] as plotters' sans-serif (once): text is measured and drawn with it.
pub fn register_font() {
    REGISTER.call_once(|| {
        for style in [FontStyle::Normal, FontStyle::Bold] {
            // the embedded font is valid; a failure here would only cost the text
            let _ = plotters::style::register_font("sans-serif", style, FONT);
        }
    });
}

#[derive(Clone, Copy, PartialEq)]
pub enum Kind {
    Line,
    /// A staircase: holds each value until the next sample (valve positions).
    Step,
}

pub struct Series<'a> {
    pub label: String,
    pub x: &'a [f64],
    pub y: &'a [f64],
    pub kind: Kind,
    /// Index into the palette.
    pub color: usize,
    /// Thin, unlabelled lines (e.g. one per seed) show in the legend once via `label`.
    pub thin: bool,
}

/// A horizontal band or line with a legend entry.
pub struct HBand {
    pub lo: f64,
    pub hi: f64,
    pub label: String,
    pub color: usize,
}

pub struct Chart<'a> {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series<'a>>,
    pub bands: Vec<HBand>,
    /// Fix the y range instead of fitting the data.
    pub y_range: Option<(f64, f64)>,
}

const PALETTE: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(90, 90, 90),
];

fn color(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

/// One chart as an SVG document in memory (no file), `size` in SVG user units.
pub fn svg_string(chart: &Chart, size: (u32, u32)) -> Result<String> {
    register_font();
    let mut out = String::new();
    {
        // `draw` presents the area, which closes the document into `out`
        let area = SVGBackend::with_string(&mut out, size).into_drawing_area();
        draw(area, chart).map_err(|e| anyhow!("cannot draw the chart '{}': {e}", chart.title))?;
    }
    Ok(out)
}

/// A few samples this far outside the rest (as multiples of the range of the middle
/// [`KEPT_SHARE`] of the values) would squash the rest into a line: the axis keeps to that
/// middle range and the outliers are drawn at its edge.
const OUTLIER_FACTOR: f64 = 20.0;
/// The share of the values whose range the axis keeps when outliers would squash it.
const KEPT_SHARE: f64 = 0.998;

/// The y range of the values `ys`: their whole range, or the middle [`KEPT_SHARE`] of them when
/// a few lie [`OUTLIER_FACTOR`] times that range away (a glitch of 1e308 in a PV).
fn y_span(ys: &mut [f64]) -> (f64, f64) {
    if ys.is_empty() {
        return (f64::INFINITY, f64::NEG_INFINITY);
    }
    ys.sort_by(f64::total_cmp);
    let n = ys.len();
    let whole = (ys[0], ys[n - 1]);
    let share = |kept: f64| {
        let cut = ((1.0 - kept) / 2.0 * n as f64).floor() as usize;
        (ys[cut], ys[n - 1 - cut])
    };
    let width = |(lo, hi): (f64, f64)| hi - lo;
    let middle = share(KEPT_SHARE);
    if width(whole).is_finite()
        && width(whole) <= OUTLIER_FACTOR * width(middle).max(f64::MIN_POSITIVE)
    {
        whole
    } else if width(middle).is_finite() {
        middle
    } else {
        // more than a few samples out of all bounds: the middle half, else a unit range
        Some(share(0.5))
            .filter(|&r| width(r).is_finite())
            .unwrap_or((0.0, 1.0))
    }
}

fn bounds(chart: &Chart) -> ((f64, f64), (f64, f64)) {
    let mut xr = (f64::INFINITY, f64::NEG_INFINITY);
    let mut ys = Vec::new();
    for s in &chart.series {
        for (&x, &y) in s.x.iter().zip(s.y) {
            if x.is_finite() && y.is_finite() {
                xr = (xr.0.min(x), xr.1.max(x));
                ys.push(y);
            }
        }
    }
    let mut yr = y_span(&mut ys);
    for b in &chart.bands {
        yr = (yr.0.min(b.lo), yr.1.max(b.hi));
    }
    if !xr.0.is_finite() {
        xr = (0.0, 1.0);
        yr = (0.0, 1.0);
    }
    if let Some(r) = chart.y_range {
        yr = r;
    }
    let pad = |(lo, hi): (f64, f64), frac: f64| {
        let w = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
        (lo - frac * w, hi + frac * w)
    };
    let xr = if xr.1 > xr.0 { xr } else { pad(xr, 0.5) };
    (xr, pad(yr, 0.08))
}

/// What a legend entry shows beside its label.
#[derive(Clone, Copy)]
enum Swatch {
    Line(RGBColor),
    Band(RGBColor),
}

/// The legend's entries in drawing order: bands, then each labelled series once.
fn legend_entries(c: &Chart) -> Vec<(String, Swatch)> {
    let mut out: Vec<(String, Swatch)> = c
        .bands
        .iter()
        .filter(|b| !b.label.is_empty())
        .map(|b| (b.label.clone(), Swatch::Band(color(b.color))))
        .collect();
    for s in &c.series {
        if !s.label.is_empty() && !out.iter().any(|(l, _)| *l == s.label) {
            out.push((s.label.clone(), Swatch::Line(color(s.color))));
        }
    }
    out
}

const LEGEND_FONT: u32 = 15;
const LEGEND_ROW: i32 = 22;
const SWATCH: i32 = 22;

/// Place the entries in rows from `left`, wrapping at `width`: each entry's top-left corner.
fn legend_places<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Swatch)],
    left: i32,
) -> Vec<(i32, i32)> {
    let width = area.dim_in_pixel().0 as i32;
    let font: TextStyle = ("sans-serif", LEGEND_FONT).into_font().into();
    let (mut x, mut y) = (left, 0);
    let mut places = Vec::with_capacity(entries.len());
    for (label, _) in entries {
        let text = area
            .estimate_text_size(label, &font)
            .map_or(8 * label.len() as i32, |(w, _)| w as i32);
        let need = SWATCH + 6 + text + 22;
        if x > left && x + need > width {
            (x, y) = (left, y + LEGEND_ROW);
        }
        places.push((x, y));
        x += need;
    }
    places
}

/// The legend strip above the data: a swatch and a label per entry.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(String, Swatch)],
    places: &[(i32, i32)],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", LEGEND_FONT)
        .into_font()
        .color(&RGBColor(40, 40, 40))
        .pos(Pos::new(HPos::Left, VPos::Center));
    for ((label, swatch), &(x, y)) in entries.iter().zip(places) {
        let mid = y + LEGEND_ROW / 2;
        match *swatch {
            Swatch::Line(c) => area.draw(&PathElement::new(
                vec![(x, mid), (x + SWATCH, mid)],
                c.stroke_width(3),
            ))?,
            Swatch::Band(c) => area.draw(&Rectangle::new(
                [(x, mid - 5), (x + SWATCH, mid + 5)],
                c.mix(0.4).filled(),
            ))?,
        }
        area.draw_text(label, &font, (x + SWATCH + 6, mid))?;
    }
    Ok(())
}

/// Draw `c` on `root` (any plotters backend) and present it. Call [`register_font`] first.
pub fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    c: &Chart,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    root.fill(&WHITE)?;
    let ((x0, x1), (y0, y1)) = bounds(c);
    // (a range the caller fixed is a zoom it chose: drawn as plotters draws it)
    let clipped = c.y_range.is_none()
        && c.series
            .iter()
            .flat_map(|s| s.y.iter())
            .any(|&y| !y.is_nan() && !(y0..=y1).contains(&y));
    let title = if clipped {
        format!("{} (outliers at the edge)", c.title)
    } else {
        c.title.clone()
    };
    let root_titled = root.titled(&title, ("sans-serif", 24))?;
    let entries = legend_entries(c);
    // the legend starts where the plotting area does (margin + y label area)
    let places = legend_places(&root_titled, &entries, 16 + 70);
    let rows = places.last().map_or(0, |p| p.1 / LEGEND_ROW + 1);
    let (legend, plot) = root_titled.split_vertically(rows * LEGEND_ROW + 4);
    draw_legend(&legend, &entries, &places)?;
    let (x_step, y_step) = (ticks::step(x0, x1), ticks::step(y0, y1));
    let x_fmt = move |v: &f64| tick_label(*v, x_step);
    let y_fmt = move |v: &f64| tick_label(*v, y_step);
    let mut chart = ChartBuilder::on(&plot)
        .margin(16)
        .margin_top(6)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)?;
    chart
        .configure_mesh()
        .x_desc(c.x_label.as_str())
        .y_desc(c.y_label.as_str())
        // about one label per 90 pixels: four-digit times do not touch on a narrow chart
        .x_labels((plot.dim_in_pixel().0 as usize / 90).clamp(3, 10))
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    for b in &c.bands {
        let col = color(b.color);
        let style = if b.hi > b.lo {
            col.mix(0.25).filled()
        } else {
            col.stroke_width(2)
        };
        let rect = if b.hi > b.lo {
            Rectangle::new([(x0, b.lo), (x1, b.hi)], style)
        } else {
            Rectangle::new([(x0, b.lo), (x1, b.lo)], style)
        };
        chart.draw_series(std::iter::once(rect))?;
    }
    for s in &c.series {
        let col = color(s.color);
        // a 2-pixel line looks ragged on dense series in the bitmap backend
        let width = if s.thin || s.x.len() > 300 { 1 } else { 2 };
        let style = if s.thin {
            col.mix(0.55).stroke_width(width)
        } else {
            col.stroke_width(width)
        };
        // outliers the axis leaves out are drawn at its edge
        let pts: Vec<(f64, f64)> =
            s.x.iter()
                .copied()
                .zip(
                    s.y.iter()
                        .map(|&y| if clipped { y.clamp(y0, y1) } else { y }),
                )
                .collect();
        match s.kind {
            Kind::Line => chart.draw_series(LineSeries::new(pts, style))?,
            Kind::Step => {
                let mut stairs = Vec::with_capacity(pts.len() * 2);
                for (i, &(x, y)) in pts.iter().enumerate() {
                    if i > 0 {
                        stairs.push((x, pts[i - 1].1));
                    }
                    stairs.push((x, y));
                }
                chart.draw_series(LineSeries::new(stairs, style))?
            }
        };
    }
    root.present()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chart_of<'a>(x: &'a [f64], y: &'a [f64]) -> Chart<'a> {
        Chart {
            title: "t".into(),
            x_label: "x".into(),
            y_label: "y".into(),
            series: vec![Series {
                label: "pv".into(),
                x,
                y,
                kind: Kind::Line,
                color: 0,
                thin: false,
            }],
            bands: Vec::new(),
            y_range: None,
        }
    }

    #[test]
    fn a_glitch_far_outside_the_data_does_not_stretch_the_axis() {
        let x: Vec<f64> = (0..1000).map(f64::from).collect();
        let mut y: Vec<f64> = x.iter().map(|t| 50.0 + (t / 20.0).sin()).collect();
        y[10] = 1e308;
        y[11] = -1e308;
        y[12] = f64::INFINITY;
        let (_, (lo, hi)) = bounds(&chart_of(&x, &y));
        assert!(lo > 48.0 && hi < 52.0, "{lo} {hi}");
        // and the chart is drawn (plotters' ticks never end on an infinite range), saying so
        let svg = svg_string(&chart_of(&x, &y), (400, 300)).unwrap();
        assert!(svg.contains("(outliers at the edge)"), "{svg}");
    }

    #[test]
    fn a_real_excursion_keeps_the_whole_range() {
        let x: Vec<f64> = (0..1000).map(f64::from).collect();
        // a step that holds for a tenth of the record is the process, not a glitch
        let y: Vec<f64> = x
            .iter()
            .map(|&t| {
                if t > 900.0 {
                    80.0
                } else {
                    50.0 + (t / 20.0).sin()
                }
            })
            .collect();
        let (_, (lo, hi)) = bounds(&chart_of(&x, &y));
        assert!(lo < 49.0 && hi > 80.0, "{lo} {hi}");
        let svg = svg_string(&chart_of(&x, &y), (400, 300)).unwrap();
        assert!(!svg.contains("outliers"));
    }
}
