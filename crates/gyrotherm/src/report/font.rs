//! The embedded font. plotters' `ab_glyph` backend loads no system font: every family used
//! must be registered from bytes. We register DejaVu Sans (Bitstream Vera license, see
//! `assets/DejaVuSans-LICENSE.txt`) once, for the `sans-serif` family, for all styles.

use std::sync::OnceLock;

use plotters::style::{register_font, FontStyle};

use super::ReportError;

/// The family every figure draws its text with.
pub const FONT_FAMILY: &str = "sans-serif";

/// DejaVu Sans, unmodified.
static DEJAVU_SANS: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");

static REGISTERED: OnceLock<Result<(), String>> = OnceLock::new();

/// Register the embedded font with plotters, once per process; thread-safe. Every figure
/// writer calls this before drawing, so callers need not.
pub fn ensure_font() -> Result<(), ReportError> {
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
