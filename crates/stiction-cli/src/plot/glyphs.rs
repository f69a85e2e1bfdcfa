//! Text in the PNG charts, laid out glyph by glyph with each glyph's left side bearing.
//!
//! plotters 0.3.7 rasterises ab_glyph outlines at the pen position but drops the glyph's own
//! offset (`px_bounds().min.x`), so narrow and wide letters collide or gape: "tim e (s)". This
//! backend wraps the bitmap backend, passes every shape through unchanged and draws text itself:
//! each glyph is positioned at the pen (advance widths and kerning, sub-pixel) and its coverage
//! is blended where ab_glyph puts it. The layout box is plotters' (so labels land where plotters
//! measured room for them); within it, capitals and digits are centred on the anchor.

use ab_glyph::{Font, FontRef, Glyph, ScaleFont};
use plotters::backend::DrawingBackend;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
};

/// A drawing backend that draws text with correct glyph spacing and everything else through
/// `inner`.
pub struct GlyphText<DB> {
    inner: DB,
    font: FontRef<'static>,
}

impl<DB> GlyphText<DB> {
    pub fn new(inner: DB, font: &'static [u8]) -> Option<Self> {
        let font = FontRef::try_from_slice(font).ok()?;
        Some(GlyphText { inner, font })
    }
}

/// The glyphs of `text` at `size` pixels, pen positions from x = 0 with the baseline at y = 0,
/// and the advance of the whole line.
pub fn layout(font: &FontRef<'_>, size: f32, text: &str) -> (Vec<Glyph>, f32) {
    let scaled = font.as_scaled(size);
    let mut glyphs = Vec::with_capacity(text.len());
    let mut pen = 0.0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = scaled.glyph_id(c);
        if let Some(p) = prev {
            pen += scaled.kern(p, id);
        }
        glyphs.push(id.with_scale_and_position(size, ab_glyph::point(pen, 0.0)));
        pen += scaled.h_advance(id);
        prev = Some(id);
    }
    (glyphs, pen)
}

impl<DB: DrawingBackend> DrawingBackend for GlyphText<DB> {
    type ErrorType = DB::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }
    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let size = style.size() as f32;
        let (glyphs, width) = layout(&self.font, size, text);
        // plotters' layout box: the advance wide, size / 1.24 high, the baseline at size / 2
        let (width, height) = (width.round() as i32, (size / 1.24) as i32);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -width,
            HPos::Center => -width / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -height / 2,
            VPos::Bottom => -height,
        };
        // the baseline sits so that capitals and digits are centred on a centre-anchored
        // position (DejaVu's cap height is about 0.63 of the scaled size; the box is 0.81 high)
        let baseline = height as f32 / 2.0 + 0.315 * size;
        let trans = style.transform();
        let (w, h) = self.get_size();
        for glyph in glyphs {
            let Some(outline) = self.font.outline_glyph(glyph) else {
                continue; // a space
            };
            let b = outline.px_bounds();
            let mut pixels = Vec::new();
            outline.draw(|x, y, c| pixels.push((x, y, c)));
            for (x, y, c) in pixels {
                let gx = (b.min.x + x as f32) as i32 + dx;
                let gy = (b.min.y + baseline + y as f32) as i32 + dy;
                let (tx, ty) = trans.transform(gx, gy);
                let (px, py) = (pos.0 + tx, pos.1 + ty);
                if c > 0.0 && px >= 0 && py >= 0 && px < w as i32 && py < h as i32 {
                    let ink = BackendColor {
                        alpha: color.alpha * f64::from(c.min(1.0)),
                        rgb: color.rgb,
                    };
                    self.inner.draw_pixel((px, py), ink)?;
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// The widest run of blank pixel columns between the first and the last inked column of
    /// `text` drawn into a small bitmap.
    fn widest_inner_gap(text: &str) -> usize {
        let (w, h) = (200u32, 40u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let bitmap = BitMapBackend::with_buffer(&mut buf, (w, h));
            let backend = GlyphText::new(bitmap, super::super::FONT).unwrap();
            let area = backend.into_drawing_area();
            super::super::register_font();
            area.draw_text(
                text,
                &("sans-serif", 17).into_font().color(&BLACK),
                (10, 10),
            )
            .unwrap();
            area.present().unwrap();
        }
        let inked: Vec<bool> = (0..w as usize)
            .map(|x| (0..h as usize).any(|y| buf[(y * w as usize + x) * 3] < 160))
            .collect();
        let first = inked.iter().position(|&i| i).expect("some ink");
        let last = inked.iter().rposition(|&i| i).unwrap();
        let (mut widest, mut run) = (0, 0);
        for &i in &inked[first..=last] {
            run = if i { 0 } else { run + 1 };
            widest = widest.max(run);
        }
        widest
    }

    #[test]
    fn letters_of_a_word_do_not_gape() {
        // plotters 0.3.7 drew "time" as "tim e": a gap of about a letter's width before the e
        for word in ["time", "minimum", "process"] {
            let gap = widest_inner_gap(word);
            assert!(gap <= 3, "{word}: a gap of {gap} px inside the word");
        }
        // a space is still a space
        assert!(widest_inner_gap("time (s)") >= 3);
    }
}
