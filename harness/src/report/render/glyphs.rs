//! Horizontal glyph metrics (advance width, left side bearing) read from the TrueType font file, so
//! that labels can be set glyph by glyph. plotters' `ab_glyph` text drops each glyph's left side
//! bearing and truncates the pen position per glyph, which spaces letters visibly unevenly at figure
//! sizes ("tin y"); plotters still rasterizes every glyph.
//!
//! Only what that needs is read: `head` (units per em), `hhea` and `hmtx` (metrics) and a format-4
//! `cmap` subtable (characters of the Basic Multilingual Plane). A font without them gives `None`,
//! and the labels fall back to plotters' own placement.

use std::path::Path;

/// Metrics of one font file, in font units.
#[derive(Clone, Debug)]
pub struct GlyphMetrics {
    data: Vec<u8>,
    /// Offsets of the `hmtx` table and of the format-4 `cmap` subtable.
    hmtx: usize,
    cmap4: usize,
    n_h_metrics: usize,
    n_glyphs: usize,
}

impl GlyphMetrics {
    /// Read the font file at `path`; `None` when it cannot be read or lacks a table used here.
    pub fn load(path: &Path) -> Option<GlyphMetrics> {
        GlyphMetrics::parse(std::fs::read(path).ok()?)
    }

    /// Parse the bytes of a TrueType / OpenType file (not a collection).
    pub fn parse(data: Vec<u8>) -> Option<GlyphMetrics> {
        let n_tables = u16_at(&data, 4)? as usize;
        let table = |tag: &[u8; 4]| {
            (0..n_tables).map(|i| 12 + 16 * i).find(|&r| data.get(r..r + 4) == Some(&tag[..])).and_then(|r| {
                let offset = u32_at(&data, r + 8)? as usize;
                let length = u32_at(&data, r + 12)? as usize;
                (offset.checked_add(length)? <= data.len()).then_some(offset)
            })
        };
        let (hhea, hmtx, maxp, cmap) = (table(b"hhea")?, table(b"hmtx")?, table(b"maxp")?, table(b"cmap")?);
        let n_h_metrics = u16_at(&data, hhea + 34)? as usize;
        let n_glyphs = u16_at(&data, maxp + 4)? as usize;
        let n_encodings = u16_at(&data, cmap + 2)? as usize;
        // Unicode BMP subtables: Windows (3, 1) or Unicode (0, 3); both are format 4 in practice.
        let cmap4 = (0..n_encodings).find_map(|i| {
            let record = cmap + 4 + 8 * i;
            let ids = (u16_at(&data, record)?, u16_at(&data, record + 2)?);
            let sub = cmap.checked_add(u32_at(&data, record + 4)? as usize)?;
            (matches!(ids, (3, 1) | (0, 3)) && u16_at(&data, sub)? == 4).then_some(sub)
        })?;
        let metrics = GlyphMetrics { data, hmtx, cmap4, n_h_metrics, n_glyphs };
        // Every offset read later must be inside the file; check the ends of both tables once.
        (n_h_metrics > 0 && metrics.h_metrics(n_glyphs.saturating_sub(1) as u16).is_some()).then_some(metrics)
    }

    /// Glyph index of `c`; `None` for a character the font does not have.
    pub fn glyph(&self, c: char) -> Option<u16> {
        let c = u16::try_from(c as u32).ok()?;
        let d = &self.data;
        let t = self.cmap4;
        let seg_x2 = u16_at(d, t + 6)? as usize;
        let (ends, starts) = (t + 14, t + 16 + seg_x2);
        let (deltas, ranges) = (starts + seg_x2, starts + 2 * seg_x2);
        let seg = (0..seg_x2 / 2).find(|&s| u16_at(d, ends + 2 * s).is_some_and(|end| end >= c))?;
        let start = u16_at(d, starts + 2 * seg)?;
        if c < start {
            return None;
        }
        let delta = u16_at(d, deltas + 2 * seg)?;
        let range = u16_at(d, ranges + 2 * seg)? as usize;
        let glyph = if range == 0 {
            c.wrapping_add(delta)
        } else {
            // idRangeOffset counts bytes from its own position into glyphIdArray.
            match u16_at(d, ranges + 2 * seg + range + 2 * (c - start) as usize)? {
                0 => 0,
                g => g.wrapping_add(delta),
            }
        };
        (glyph != 0 && (glyph as usize) < self.n_glyphs).then_some(glyph)
    }

    /// `(advance width, left side bearing)` of glyph `g`, in font units.
    pub fn h_metrics(&self, g: u16) -> Option<(u16, i16)> {
        let g = g as usize;
        let last = self.n_h_metrics - 1;
        // Glyphs past the last full record share its advance and list only their bearing.
        let advance = u16_at(&self.data, self.hmtx + 4 * g.min(last))?;
        let lsb = if g <= last {
            u16_at(&self.data, self.hmtx + 4 * g + 2)?
        } else {
            u16_at(&self.data, self.hmtx + 4 * self.n_h_metrics + 2 * (g - self.n_h_metrics))?
        };
        Some((advance, lsb as i16))
    }

    /// Advance width in font units of `text`; `None` if a character is missing.
    pub fn advance(&self, text: &str) -> Option<f64> {
        text.chars().map(|c| Some(self.h_metrics(self.glyph(c)?)?.0 as f64)).sum()
    }
}

fn u16_at(data: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes(data.get(at..at.checked_add(2)?)?.try_into().ok()?))
}

fn u32_at(data: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_be_bytes(data.get(at..at.checked_add(4)?)?.try_into().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_registered_font_maps_characters_and_has_bearings() {
        let path = crate::report::fonts::register_sans_serif().unwrap();
        let m = GlyphMetrics::load(path).expect("the figure font has hmtx and a format-4 cmap");
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

    #[test]
    fn garbage_is_rejected_without_panicking() {
        assert!(GlyphMetrics::parse(Vec::new()).is_none());
        assert!(GlyphMetrics::parse(vec![0xff; 64]).is_none());
        let mut header = vec![0u8; 12 + 16];
        header[5] = 1;
        header[12..16].copy_from_slice(b"hhea");
        header[20..24].copy_from_slice(&u32::MAX.to_be_bytes());
        assert!(GlyphMetrics::parse(header).is_none());
    }
}
