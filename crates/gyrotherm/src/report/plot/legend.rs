//! Legends of the figures, laid out in rows in a band below the plotting area (outside it, so
//! a legend hides no data).

use super::*;

/// Entries of a legend laid out in rows: each entry's offset inside the box, and the box
/// size, pixels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct LegendLayout {
    pub(super) entries: Vec<(i32, i32)>,
    pub(super) width: i32,
    pub(super) height: i32,
}

/// Lay out entries whose texts are `text_widths` wide left to right, starting a new row
/// when the next one would pass `max_width` (an entry wider than that gets a row of its
/// own).
pub(super) fn legend_layout(text_widths: &[i32], max_width: i32) -> LegendLayout {
    let mut entries = Vec::with_capacity(text_widths.len());
    let (mut x, mut row, mut widest) = (LEGEND_PAD_PX, 0, 0);
    for &tw in text_widths {
        let w = LEGEND_SAMPLE_PX + LEGEND_SAMPLE_GAP_PX + tw;
        if x > LEGEND_PAD_PX && x + w + LEGEND_PAD_PX > max_width {
            x = LEGEND_PAD_PX;
            row += 1;
        }
        entries.push((x, LEGEND_PAD_PX + row * LEGEND_ROW_PX));
        widest = widest.max(x + w);
        x += w + LEGEND_ENTRY_GAP_PX;
    }
    let rows = if text_widths.is_empty() { 0 } else { row + 1 };
    LegendLayout {
        entries,
        width: widest + LEGEND_PAD_PX,
        height: rows * LEGEND_ROW_PX + 2 * LEGEND_PAD_PX,
    }
}

/// Draw the legend box in `area` (the band below a chart), its left edge at the absolute
/// x `left` (the plotting area's), and return the box in figure pixels.
pub(super) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    font: &TextStyle,
    layout: &LegendLayout,
    entries: &[(usize, &Series)],
    left: i32,
) -> Result<PixelRect, String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let (bx, by) = area.get_base_pixel();
    let x0 = left - bx;
    let y0 = LEGEND_GAP_PX;
    let (r, g, b) = LEGEND_BORDER_RGB;
    area.draw(&Rectangle::new(
        [(x0, y0), (x0 + layout.width, y0 + layout.height)],
        RGBColor(r, g, b).stroke_width(1),
    ))
    .map_err(err)?;
    let text_style = font
        .color(&BLACK)
        .pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Left,
            plotters::style::text_anchor::VPos::Center,
        ));
    for (&(i, s), &(ex, ey)) in entries.iter().zip(&layout.entries) {
        let color = color_of(s, i);
        let marker = matches!(s.style, SeriesStyle::Points | SeriesStyle::LinePoints);
        let line = !matches!(s.style, SeriesStyle::Points);
        let none = ShapeStyle::from(&TRANSPARENT);
        let stroke = if line { color.stroke_width(2) } else { none };
        let dot = if marker { color.filled() } else { none };
        // Dashed lines show a gap in the middle of their legend stroke.
        let gap = if matches!(s.style, SeriesStyle::Dashed) {
            none
        } else {
            stroke
        };
        let (x, y) = (x0 + ex, y0 + ey + LEGEND_ROW_PX / 2);
        area.draw(
            &(EmptyElement::at((x, y))
                + PathElement::new(vec![(0, 0), (8, 0)], stroke)
                + PathElement::new(vec![(8, 0), (14, 0)], gap)
                + PathElement::new(vec![(14, 0), (22, 0)], stroke)
                + Circle::new((11, 0), 3, dot)),
        )
        .map_err(err)?;
        area.draw_text(
            &s.label,
            &text_style,
            (x + LEGEND_SAMPLE_PX + LEGEND_SAMPLE_GAP_PX, y),
        )
        .map_err(err)?;
    }
    Ok(PixelRect {
        x0: bx + x0,
        y0: by + y0,
        x1: bx + x0 + layout.width + 1,
        y1: by + y0 + layout.height + 1,
    })
}
