//! The report's charts: each drawn twice as inline SVG, wide for laptops and paper, narrow (text
//! relatively larger) for phones; the stylesheet shows one. The data come prepared (decimated,
//! thinned, windowed) from [`super::series`]: nothing here computes.

use crate::chart::{self as plot, Chart, Kind, Series};
use anyhow::Result;
use serde::Serialize;

/// Chart sizes in SVG user units; the page scales them to its width (a phone's 360 px or so
/// shows the narrow ones at about 0.85, so their 15-unit labels stay readable).
pub const TREND_SIZE: [(u32, u32); 2] = [(960, 360), (440, 340)];
pub const PHASE_SIZE: [(u32, u32); 2] = [(960, 600), (440, 420)];

/// One figure of the page: the chart for wide and for narrow screens, inline SVG markup.
#[derive(Serialize)]
pub struct Figure {
    pub wide: String,
    pub narrow: String,
    /// The chart's title, for screen readers.
    pub label: String,
    pub caption: String,
}

/// A plotters SVG document made fit to inline in HTML: no XML declaration, no namespace URL
/// (the HTML parser puts `<svg>` in the SVG namespace), scaled to the page by its viewBox. The
/// opening tag is the template's; this is the rest of the element.
fn svg_body(svg: &str) -> String {
    let body = match svg.find("<svg") {
        Some(i) => &svg[i..],
        None => svg,
    };
    let body = match body.find('>') {
        Some(i) if body.starts_with("<svg") => &body[i + 1..],
        _ => body,
    };
    body.trim_end().to_string()
}

/// The opening tag and the body of one chart at one size.
fn inline_svg(chart: &Chart, size: (u32, u32), class: &str) -> Result<String> {
    let svg = plot::svg_string(chart, size)?;
    Ok(format!(
        "<svg class=\"{class}\" viewBox=\"0 0 {} {}\" width=\"100%\" preserveAspectRatio=\"xMidYMid meet\" \
         role=\"img\" aria-label=\"{}\">{}",
        size.0,
        size.1,
        super::esc(&chart.title),
        svg_body(&svg)
    ))
}

pub fn figure(chart: &Chart, sizes: [(u32, u32); 2], caption: String) -> Result<Figure> {
    Ok(Figure {
        wide: inline_svg(chart, sizes[0], "wide")?,
        narrow: inline_svg(chart, sizes[1], "narrow")?,
        label: chart.title.clone(),
        caption,
    })
}

/// A labelled trace in a chart's palette colour.
pub fn line<'a>(label: &str, (x, y): &'a (Vec<f64>, Vec<f64>), color: usize) -> Series<'a> {
    Series {
        label: label.into(),
        x,
        y,
        kind: Kind::Line,
        color,
        thin: false,
    }
}

/// As [`line`], as a staircase (a valve position holds until it moves).
pub fn steps<'a>(label: &str, xy: &'a (Vec<f64>, Vec<f64>), color: usize) -> Series<'a> {
    Series {
        kind: Kind::Step,
        ..line(label, xy, color)
    }
}

/// A chart of `series` against time.
pub fn chart<'a>(title: &str, x_label: &str, y_label: &str, series: Vec<Series<'a>>) -> Chart<'a> {
    Chart {
        title: title.into(),
        x_label: x_label.into(),
        y_label: y_label.into(),
        series,
        bands: vec![],
        y_range: None,
    }
}
