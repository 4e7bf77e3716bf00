//! Text on an [`RgbImage`] through plotters (font family `sans-serif`, registered by
//! [`crate::report::fonts::register_sans_serif`]), placed by baseline, with subscripts for `E_theta`, and
//! set glyph by glyph from the font's metrics ([`GlyphMetrics`]) where it has them.

use std::sync::OnceLock;

use plotters::backend::BitMapBackend;
use plotters::drawing::IntoDrawingArea;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::{FontDesc, FontFamily, FontStyle, RGBColor};

use super::canvas::RgbImage;
use super::glyphs::GlyphMetrics;

const FAMILY: &str = "sans-serif";

/// Subscripts are this fraction of the font size, their baseline this fraction of it lower.
const SUB_SCALE: f64 = 0.7;
const SUB_DROP: f64 = 0.22;

/// A run of text in one size and baseline.
#[derive(Clone, Debug, PartialEq)]
pub struct Span {
    pub text: String,
    pub subscript: bool,
}

/// Horizontal placement of a line relative to its `x`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Align {
    Left,
    Center,
}

/// One line of text: spans drawn one after the other at font `size` (pixels), baseline at `(x, y)`.
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    pub spans: Vec<Span>,
    pub size: f64,
    pub color: [u8; 3],
    pub x: f64,
    pub y: f64,
    pub align: Align,
}

impl Label {
    /// A plain line.
    pub fn new(
        text: impl Into<String>,
        size: f64,
        color: [u8; 3],
        (x, y): (f64, f64),
        align: Align,
    ) -> Label {
        Label { spans: vec![Span { text: text.into(), subscript: false }], size, color, x, y, align }
    }

    /// A line of spans; `(text, true)` is a subscript.
    pub fn rich(
        spans: &[(&str, bool)],
        size: f64,
        color: [u8; 3],
        (x, y): (f64, f64),
        align: Align,
    ) -> Label {
        let spans = spans.iter().map(|(t, s)| Span { text: t.to_string(), subscript: *s }).collect();
        Label { spans, size, color, x, y, align }
    }

    /// Width in pixels of the whole line.
    pub fn width(&self) -> Result<f64, String> {
        self.spans.iter().map(|s| span_width(s, self.size)).sum()
    }
}

fn span_size(span: &Span, size: f64) -> f64 {
    if span.subscript {
        size * SUB_SCALE
    } else {
        size
    }
}

fn font(size: f64) -> FontDesc<'static> {
    FontDesc::new(FontFamily::Name(FAMILY), size, FontStyle::Normal)
}

/// The figure font's metrics, read once; `None` if the font file lacks what [`GlyphMetrics`] reads.
fn metrics() -> Option<&'static GlyphMetrics<'static>> {
    // The metrics borrow the file's bytes, so both live for the process, like plotters' copy.
    static DATA: OnceLock<Option<Vec<u8>>> = OnceLock::new();
    static METRICS: OnceLock<Option<GlyphMetrics<'static>>> = OnceLock::new();
    METRICS
        .get_or_init(|| {
            let data =
                DATA.get_or_init(|| std::fs::read(crate::report::fonts::register_sans_serif().ok()?).ok());
            GlyphMetrics::parse(data.as_deref()?)
        })
        .as_ref()
}

/// How a span is set: each glyph's text with the offset of its ink from the span's start (pen
/// position plus left side bearing), and the span's advance width; pixels at font size `size`.
struct Setting {
    glyphs: Vec<(String, f64)>,
    width: f64,
}

/// Glyph by glyph from the font's metrics, scaled to match plotters' glyph outlines: the scale is
/// calibrated on plotters' own width of a digit string (whose glyphs are not kerned), which sidesteps
/// which vertical metrics `ab_glyph` sizes fonts by. `None` without metrics or for a missing glyph;
/// the span is then drawn by plotters whole.
fn set_glyphs(text: &str, size: f64) -> Option<Setting> {
    const REFERENCE: &str = "0123456789012345678901234567890123456789";
    let m = metrics()?;
    let (reference_px, _) = font(size).box_size(REFERENCE).ok()?;
    let scale = reference_px as f64 / m.advance(REFERENCE)?;
    let mut pen = 0.0f64;
    let mut glyphs = Vec::with_capacity(text.len());
    for c in text.chars() {
        let (advance, lsb) = m.h_metrics(m.glyph(c)?)?;
        // plotters draws a glyph's bitmap from its first inked pixel column, floor(bearing) right of
        // the origin; putting the origin on a whole pixel keeps the bitmap's sub-pixel coverage right.
        glyphs.push((c.to_string(), pen.round() + (lsb as f64 * scale).floor()));
        pen += advance as f64 * scale;
    }
    Some(Setting { glyphs, width: pen })
}

fn span_width(span: &Span, size: f64) -> Result<f64, String> {
    let size = span_size(span, size);
    if let Some(setting) = set_glyphs(&span.text, size) {
        return Ok(setting.width);
    }
    let (w, _) =
        font(size).box_size(&span.text).map_err(|e| format!("measuring text `{}`: {e}", span.text))?;
    Ok(w as f64)
}

/// Draw `labels` onto `image` (anti-aliased, clipped to the image).
pub fn draw_labels(image: &mut RgbImage, labels: &[Label]) -> Result<(), String> {
    let (w, h) = (image.width(), image.height());
    let area = BitMapBackend::with_buffer(image.data_mut(), (w, h)).into_drawing_area();
    for label in labels {
        let width = label.width()?;
        let mut x = match label.align {
            Align::Left => label.x,
            Align::Center => label.x - width / 2.0,
        };
        let [r, g, b] = label.color;
        for span in &label.spans {
            let size = span_size(span, label.size);
            let baseline = label.y + if span.subscript { SUB_DROP * label.size } else { 0.0 };
            let style = font(size).color(&RGBColor(r, g, b)).pos(Pos::new(HPos::Left, VPos::Top));
            // plotters' ab_glyph text puts the baseline half a font size below a top-anchored position.
            let top = (baseline - size / 2.0).round() as i32;
            let draw = |text: &str, at: f64| {
                area.draw_text(text, &style, (at.round() as i32, top))
                    .map_err(|e| format!("drawing text `{}`: {e}", span.text))
            };
            match set_glyphs(&span.text, size) {
                Some(setting) => {
                    let origin = x.round();
                    for (glyph, offset) in setting.glyphs.iter().filter(|(g, _)| g.trim() != "") {
                        draw(glyph, origin + offset)?;
                    }
                    x += setting.width;
                }
                None => {
                    draw(&span.text, x)?;
                    x += span_width(span, label.size)?;
                }
            }
        }
    }
    area.present().map_err(|e| format!("drawing text: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_drawn_above_its_baseline_where_it_is_aligned() {
        crate::report::fonts::register_sans_serif().unwrap();
        let mut image = RgbImage::filled(200, 60, [255; 3]);
        let label = Label::rich(
            &[("E", false), ("θ", true), (" 1.00°", false)],
            20.0,
            [0; 3],
            (100.0, 40.0),
            Align::Center,
        );
        let width = label.width().unwrap();
        assert!(width > 40.0 && width < 150.0, "{width}");
        draw_labels(&mut image, &[label]).unwrap();
        let dark: Vec<(u32, u32)> = (0..60)
            .flat_map(|y| (0..200).map(move |x| (x, y)))
            .filter(|&(x, y)| image.pixel(x, y).unwrap()[0] < 128)
            .collect();
        assert!(!dark.is_empty());
        let (xs, ys): (Vec<u32>, Vec<u32>) = dark.into_iter().unzip();
        let (x0, x1) = (*xs.iter().min().unwrap() as f64, *xs.iter().max().unwrap() as f64);
        assert!(
            (x0 - (100.0 - width / 2.0)).abs() < 6.0 && (x1 - (100.0 + width / 2.0)).abs() < 6.0,
            "{x0}..{x1}"
        );
        // Capitals sit on the baseline; only the subscript goes below it.
        assert!(*ys.iter().min().unwrap() >= 40 - 20 && *ys.iter().max().unwrap() <= 40 + 10, "{ys:?}");
    }
}
