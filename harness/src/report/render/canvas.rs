//! An 8-bit RGB image: the rendered cells, the grids they are pasted into, and their PNG encoding.

/// A `width x height` RGB image, 3 bytes per pixel, row-major from the top (the layout plotters'
/// `BitMapBackend::with_buffer` draws into).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RgbImage {
    width: u32,
    height: u32,
    data: Vec<u8>,
}

impl RgbImage {
    /// A `width x height` image filled with `color`.
    pub fn filled(width: u32, height: u32, color: [u8; 3]) -> RgbImage {
        let n = width as usize * height as usize;
        RgbImage { width, height, data: color.iter().copied().cycle().take(3 * n).collect() }
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// `3 * width * height` bytes.
    pub fn data(&self) -> &[u8] {
        &self.data
    }

    pub(crate) fn data_mut(&mut self) -> &mut [u8] {
        &mut self.data
    }

    /// The colour at `(x, y)`; `None` outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> Option<[u8; 3]> {
        (x < self.width && y < self.height).then(|| {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            [self.data[i], self.data[i + 1], self.data[i + 2]]
        })
    }

    /// Set `(x, y)`; nothing outside the image.
    pub fn set_pixel(&mut self, x: u32, y: u32, color: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = 3 * (y as usize * self.width as usize + x as usize);
            self.data[i..i + 3].copy_from_slice(&color);
        }
    }

    /// Fill the `w x h` rectangle with top-left corner `(x, y)`, clipped to the image.
    pub fn fill_rect(&mut self, x: i64, y: i64, w: u32, h: u32, color: [u8; 3]) {
        for (px, py) in self.clip(x, y, w, h) {
            self.set_pixel(px, py, color);
        }
    }

    /// The border, `thickness` pixels wide inwards, of the `w x h` rectangle at `(x, y)`, clipped.
    pub fn outline_rect(&mut self, x: i64, y: i64, w: u32, h: u32, thickness: u32, color: [u8; 3]) {
        let t = thickness.min(w).min(h);
        self.fill_rect(x, y, w, t, color);
        self.fill_rect(x, y + (h - t) as i64, w, t, color);
        self.fill_rect(x, y, t, h, color);
        self.fill_rect(x + (w - t) as i64, y, t, h, color);
    }

    /// Copy `src` with its top-left corner at `(x, y)`, clipped to this image.
    pub fn paste(&mut self, src: &RgbImage, x: i64, y: i64) {
        for (px, py) in self.clip(x, y, src.width, src.height) {
            let color = src.pixel((px as i64 - x) as u32, (py as i64 - y) as u32).unwrap_or([255; 3]);
            self.set_pixel(px, py, color);
        }
    }

    /// Pixels of this image inside the `w x h` rectangle at `(x, y)`.
    fn clip(&self, x: i64, y: i64, w: u32, h: u32) -> impl Iterator<Item = (u32, u32)> {
        let (x0, x1) = (x.max(0), (x + w as i64).min(self.width as i64));
        let (y0, y1) = (y.max(0), (y + h as i64).min(self.height as i64));
        (y0..y1).flat_map(move |py| (x0..x1).map(move |px| (px as u32, py as u32)))
    }

    /// The PNG file of this image (8-bit RGB, deterministic: same pixels, same bytes).
    pub fn encode_png(&self) -> Result<Vec<u8>, image::ImageError> {
        use image::ImageEncoder;
        let mut bytes = Vec::new();
        image::codecs::png::PngEncoder::new_with_quality(
            &mut bytes,
            image::codecs::png::CompressionType::Default,
            image::codecs::png::FilterType::Adaptive,
        )
        .write_image(&self.data, self.width, self.height, image::ColorType::Rgb8)?;
        Ok(bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paste_and_fill_clip_to_the_image_and_png_round_trips() {
        let mut canvas = RgbImage::filled(6, 4, [255; 3]);
        canvas.fill_rect(-2, -2, 4, 4, [1, 2, 3]);
        assert_eq!(canvas.pixel(1, 1), Some([1, 2, 3]));
        assert_eq!(canvas.pixel(2, 2), Some([255; 3]));
        canvas.paste(&RgbImage::filled(3, 3, [9, 9, 9]), 5, 3);
        assert_eq!(canvas.pixel(5, 3), Some([9, 9, 9]));
        assert_eq!(canvas.pixel(4, 3), Some([255; 3]));
        assert_eq!(canvas.pixel(6, 3), None);
        let png = canvas.encode_png().unwrap();
        assert_eq!(png, canvas.encode_png().unwrap());
        let decoded = image::load_from_memory_with_format(&png, image::ImageFormat::Png).unwrap().to_rgb8();
        assert_eq!(decoded.as_raw(), canvas.data());
    }
}
