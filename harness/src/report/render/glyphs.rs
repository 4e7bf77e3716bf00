//! Horizontal glyph metrics (advance width, left side bearing) of the figure font, so that labels
//! can be set glyph by glyph. plotters' `ab_glyph` text drops each glyph's left side bearing and
//! truncates the pen position per glyph, which spaces letters visibly unevenly at figure sizes
//! ("tin y"); plotters still rasterizes every glyph.
//!
//! The font is read with `ttf-parser` (the parser under `ab_glyph`, so plotters and these metrics
//! agree on the file). Only the `hmtx` and `cmap` tables are used; a font without them gives `None`,
//! and the labels fall back to plotters' own placement.

use ttf_parser::{Face, GlyphId};

/// Metrics of one font, in font units, borrowing the font file's bytes.
#[derive(Clone, Debug)]
pub struct GlyphMetrics<'a> {
    face: Face<'a>,
}

impl<'a> GlyphMetrics<'a> {
    /// Parse the bytes of a TrueType / OpenType file (the first face of a collection, as plotters
    /// takes); `None` when they are not a font or it has no `hmtx` or `cmap` table.
    pub fn parse(data: &'a [u8]) -> Option<GlyphMetrics<'a>> {
        let face = Face::parse(data, 0).ok()?;
        // ttf-parser parses without them, but then every lookup below would fail.
        (face.tables().hmtx.is_some() && face.tables().cmap.is_some()).then_some(GlyphMetrics { face })
    }

    /// Glyph index of `c`; `None` for a character the font does not have.
    pub fn glyph(&self, c: char) -> Option<u16> {
        // A format-4 segment can map a character to glyph 0 (`.notdef`), the font's "missing" box:
        // that is a character the font does not have, so the label falls back to plotters.
        self.face.glyph_index(c).map(|g| g.0).filter(|&g| g != 0 && g < self.face.number_of_glyphs())
    }

    /// `(advance width, left side bearing)` of glyph `g`, in font units.
    pub fn h_metrics(&self, g: u16) -> Option<(u16, i16)> {
        let g = GlyphId(g);
        Some((self.face.glyph_hor_advance(g)?, self.face.glyph_hor_side_bearing(g)?))
    }

    /// Advance width in font units of `text`; `None` if a character is missing.
    pub fn advance(&self, text: &str) -> Option<f64> {
        text.chars().map(|c| Some(self.h_metrics(self.glyph(c)?)?.0 as f64)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn font_bytes() -> Vec<u8> {
        std::fs::read(crate::report::fonts::register_sans_serif().unwrap()).unwrap()
    }

    #[test]
    fn the_registered_font_maps_characters_and_has_bearings() {
        let data = font_bytes();
        let m = GlyphMetrics::parse(&data).expect("the figure font has hmtx and cmap");
        for c in ['a', 'i', 'n', 'E', '0', '\u{3b8}', '\u{3c6}', '\u{b0}', '\u{2265}', ' '] {
            assert!(m.glyph(c).is_some(), "{c:?}");
        }
        let (i, n) = (m.glyph('i').unwrap(), m.glyph('n').unwrap());
        assert_ne!(i, n);
        let (advance, lsb) = m.h_metrics(i).unwrap();
        assert!(advance > 0 && lsb > 0, "`i` has ink right of its origin: {advance} {lsb}");
        assert_eq!(m.glyph('\u{e000}'), None, "private use: not in the font");
        assert!(m.advance("nn").unwrap() == 2.0 * m.h_metrics(n).unwrap().0 as f64);
    }

    /// `Face::glyph_index` tries every Unicode subtable; on the Basic Multilingual Plane it must give
    /// what the font's Windows BMP (3, 1) format-4 subtable alone gives, which is what the labels
    /// were set from before ttf-parser was used. And the metrics are the `hmtx` records.
    #[test]
    fn lookups_match_the_fonts_bmp_subtable_and_hmtx() {
        use ttf_parser::cmap::Format;
        use ttf_parser::PlatformId;
        let data = font_bytes();
        let m = GlyphMetrics::parse(&data).unwrap();
        let face = Face::parse(&data, 0).unwrap();
        let bmp = face
            .tables()
            .cmap
            .unwrap()
            .subtables
            .into_iter()
            .find_map(|s| match s.format {
                Format::SegmentMappingToDeltaValues(t)
                    if s.platform_id == PlatformId::Windows && s.encoding_id == 1 =>
                {
                    Some(t)
                }
                _ => None,
            })
            .expect("the figure font has a Windows BMP format-4 cmap");
        let hmtx = face.tables().hmtx.unwrap();
        let mut mapped = 0;
        for c in (0..=0xffffu32).filter_map(char::from_u32) {
            let expected = bmp.glyph_index(c as u32).map(|g| g.0).filter(|&g| g != 0);
            assert_eq!(m.glyph(c), expected, "{c:?}");
            if let Some(g) = expected {
                let record = (hmtx.advance(GlyphId(g)).unwrap(), hmtx.side_bearing(GlyphId(g)).unwrap());
                assert_eq!(m.h_metrics(g), Some(record), "{c:?}");
                mapped += 1;
            }
        }
        assert!(mapped > 1000, "{mapped} characters mapped");
        let digits = "0123456789";
        let sum: f64 =
            digits.chars().map(|c| hmtx.advance(GlyphId(m.glyph(c).unwrap())).unwrap() as f64).sum();
        assert_eq!(m.advance(digits), Some(sum));
    }

    #[test]
    fn garbage_is_rejected_without_panicking() {
        assert!(GlyphMetrics::parse(&[]).is_none());
        assert!(GlyphMetrics::parse(&[0xff; 64]).is_none());
        let mut header = vec![0u8; 12 + 16];
        header[5] = 1;
        header[12..16].copy_from_slice(b"hhea");
        header[20..24].copy_from_slice(&u32::MAX.to_be_bytes());
        assert!(GlyphMetrics::parse(&header).is_none());
    }
}
