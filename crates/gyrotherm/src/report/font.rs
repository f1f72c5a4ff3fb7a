//! The embedded font. plotters' `ab_glyph` backend loads no system font: every family used
//! must be registered from bytes. We register DejaVu Sans (Bitstream Vera license, see
//! `assets/DejaVuSans-LICENSE.txt`) once, for the `sans-serif` family, for all styles.

use std::sync::OnceLock;

use ab_glyph::{point, Font, FontRef, InvalidFont, ScaleFont};
use plotters::style::{register_font, FontStyle};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

use super::ReportError;

/// The family every figure draws its text with.
pub(crate) const FONT_FAMILY: &str = "sans-serif";

/// DejaVu Sans, unmodified.
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();

/// Register the embedded font with plotters, once per process; thread-safe. Every figure
/// writer calls this before drawing, so callers need not.
pub(crate) fn ensure_font() -> Result<(), ReportError> {
    REGISTERED
        .get_or_init(|| {
            for style in [
                FontStyle::Normal,
                FontStyle::Bold,
                FontStyle::Italic,
                FontStyle::Oblique,
            ] {
                register_font(FONT_FAMILY, style, DEJAVU_SANS)
                    .map_err(|_| "DejaVuSans.ttf is not a valid font file".to_owned())?;
            }
            Ok(())
        })
        .clone()
        .map_err(ReportError::Font)
}

/// The embedded font as an `ab_glyph` face, for [`GlyphFix`].
fn face() -> Result<&'static FontRef<'static>, InvalidFont> {
    static FACE: OnceLock<Result<FontRef<'static>, InvalidFont>> = OnceLock::new();
    FACE.get_or_init(|| FontRef::try_from_slice(DEJAVU_SANS))
        .as_ref()
        .map_err(|e| *e)
}

/// A bitmap backend wrapper that draws text with correct glyph placement.
///
/// plotters 0.3.7 `ab_glyph` text drawing places each glyph's bitmap at the pen position,
/// dropping the glyph's left side bearing (`px_bounds().min.x`), so letters are unevenly
/// spaced ("tim e"). This wrapper renders text itself, same layout box, anchor, rotation and
/// vertical placement as plotters, but with each glyph positioned by ab_glyph; every other
/// call goes to the wrapped backend unchanged.
pub(crate) struct GlyphFix<B> {
    inner: B,
}

impl<B: DrawingBackend> GlyphFix<B> {
    pub(crate) fn new(inner: B) -> Self {
        GlyphFix { inner }
    }
}

type DrawResult<E> = Result<(), DrawingErrorKind<E>>;

impl<B: DrawingBackend> DrawingBackend for GlyphFix<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> DrawResult<B::ErrorType> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> DrawResult<B::ErrorType> {
        self.inner.present()
    }
    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> DrawResult<B::ErrorType> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> DrawResult<B::ErrorType> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> DrawResult<B::ErrorType> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> DrawResult<B::ErrorType> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> DrawResult<B::ErrorType> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> DrawResult<B::ErrorType> {
        self.inner.fill_polygon(vert, style)
    }
    fn estimate_text_size<S: BackendTextStyle>(
        &self,
        text: &str,
        style: &S,
    ) -> Result<(u32, u32), DrawingErrorKind<B::ErrorType>> {
        self.inner.estimate_text_size(text, style)
    }
    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> DrawResult<B::ErrorType> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn draw_text<S: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &S,
        pos: BackendCoord,
    ) -> DrawResult<B::ErrorType> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let ((min_x, min_y), (max_x, max_y)) = style
            .layout_box(text)
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?;
        let (width, height) = (max_x - min_x, max_y - min_y);
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
        let trans = style.transform();
        let (w, h) = self.get_size();
        let size = style.size() as f32;
        let font = face()
            .map_err(|e| DrawingErrorKind::FontError(Box::new(e)))?
            .as_scaled(size);
        let mut caret = 0f32;
        let mut prev = None;
        for c in text.chars() {
            let id = font.glyph_id(c);
            if let Some(p) = prev {
                caret += font.kern(p, id);
            }
            prev = Some(id);
            let glyph = id.with_scale_and_position(font.scale(), point(caret, 0.0));
            caret += font.h_advance(id);
            let Some(outline) = font.outline_glyph(glyph) else {
                continue; // a space
            };
            let bounds = outline.px_bounds();
            // Vertical placement as plotters draws it (baseline at size / 2 below the top).
            // Rounded down for every glyph alike: truncating towards zero moved a glyph
            // reaching above `size / 2` (most letters) one pixel lower than one that does
            // not (".", ","), so a full stop sat above the baseline ("et al·").
            let (gx, gy) = (
                bounds.min.x.floor() as i32,
                (size / 2.0 + bounds.min.y).floor() as i32,
            );
            let mut pixels = Vec::new();
            outline.draw(|x, y, coverage| {
                if coverage > 0.0 {
                    pixels.push((x as i32 + gx, y as i32 + gy, coverage));
                }
            });
            for (x, y, coverage) in pixels {
                let (x, y) = trans.transform(x + dx - min_x, y + dy - min_y);
                let (x, y) = (pos.0 + x, pos.1 + y);
                if x >= 0 && x < w as i32 && y >= 0 && y < h as i32 {
                    self.inner
                        .draw_pixel((x, y), color.mix(f64::from(coverage)))?;
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

    /// "l." drawn at the legend's size (15 px, odd, so `size / 2` is a half pixel): the full
    /// stop and the l both stand on the baseline, so their lowest inked rows are the same.
    /// DejaVu Sans: neither glyph has a descender.
    #[test]
    fn a_full_stop_sits_on_the_baseline() {
        ensure_font().unwrap();
        let (w, h) = (60u32, 40u32);
        let mut rgb = vec![255u8; (w * h * 3) as usize];
        {
            let root =
                GlyphFix::new(BitMapBackend::with_buffer(&mut rgb, (w, h))).into_drawing_area();
            let style: TextStyle = (FONT_FAMILY, 15).into_font().into();
            root.draw_text("l.", &style.color(&BLACK), (10, 10))
                .unwrap();
            root.present().unwrap();
        }
        let ink = |x: u32, y: u32| rgb[((y * w + x) * 3) as usize] < 128;
        let columns_with_ink: Vec<u32> = (0..w).filter(|&x| (0..h).any(|y| ink(x, y))).collect();
        // The two glyphs are separated by at least one blank column.
        let split = columns_with_ink
            .windows(2)
            .find(|p| p[1] > p[0] + 1)
            .map(|p| p[1])
            .expect("two glyphs");
        let lowest = |xs: std::ops::Range<u32>| {
            xs.flat_map(|x| (0..h).filter(move |&y| ink(x, y)))
                .max()
                .unwrap()
        };
        assert_eq!(
            lowest(0..split),
            lowest(split..w),
            "l and . on different baselines"
        );
    }
}
