//! Charts as PNG and SVG files (`quantify --plot`, `reproduce`). The charts themselves, what
//! they show and how they are drawn, are [`stiction_report::chart`]'s (shared with the HTML
//! pages); PNG text goes through [`glyphs::GlyphText`], which spaces the glyphs right.

mod glyphs;

pub use stiction_report::chart::{Chart, HBand, Kind, Series};

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use stiction_report::chart::{draw, register_font, FONT};

/// Write `stem.png` and `stem.svg`; returns both paths.
pub fn save(chart: &Chart, stem: &Path) -> Result<Vec<PathBuf>> {
    save_panels(std::slice::from_ref(chart), stem)
}

/// Several charts stacked in one figure (shared page, each with its own axes).
pub fn save_panels(charts: &[Chart], stem: &Path) -> Result<Vec<PathBuf>> {
    register_font();
    if let Some(dir) = stem.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    }
    let png = stem.with_extension("png");
    let svg = stem.with_extension("svg");
    let size = (1000, 600 * charts.len().max(1) as u32);
    // the PNG encoder writes to a path: it gets the atomic write's temporary file
    crate::atomic::write_via(&png, |tmp| {
        let backend = glyphs::GlyphText::new(BitMapBackend::new(tmp, size), FONT)
            .ok_or_else(|| anyhow!("the embedded font cannot be read"))?;
        let bitmap = backend.into_drawing_area();
        for (area, chart) in bitmap
            .split_evenly((charts.len(), 1))
            .into_iter()
            .zip(charts)
        {
            draw(area, chart)
                .map_err(|e| anyhow!("{}: cannot draw the chart: {e}", png.display()))?;
        }
        bitmap
            .present()
            .map_err(|e| anyhow!("{}: cannot write the chart: {e}", png.display()))
    })?;
    let mut text = String::new();
    {
        let vector = SVGBackend::with_string(&mut text, size).into_drawing_area();
        for (area, chart) in vector
            .split_evenly((charts.len(), 1))
            .into_iter()
            .zip(charts)
        {
            draw(area, chart)
                .map_err(|e| anyhow!("{}: cannot draw the chart: {e}", svg.display()))?;
        }
        vector
            .present()
            .map_err(|e| anyhow!("{}: cannot write the chart: {e}", svg.display()))?;
    }
    crate::atomic::write_atomic(&svg, text.as_bytes())?;
    Ok(vec![png, svg])
}
