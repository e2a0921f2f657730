//! RGB images and masks: `[0,1]` f32 in memory, 8-bit sRGB PNG on disk (values are stored as
//! they are, `byte = round(255 v)`, with no gamma conversion, as the peers load them). Reading
//! accepts JPEG too (`image_decode.rs`).

use std::path::Path;

use crate::error::DataError;

/// An RGB image, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<[f32; 3]>,
}

/// A foreground mask, row-major, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Mask {
    pub width: usize,
    pub height: usize,
    pub values: Vec<bool>,
}

/// The byte a `[0,1]` value is stored as.
pub fn quantize(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

impl Image {
    pub fn at(&self, x: usize, y: usize) -> [f32; 3] {
        self.pixels[y * self.width + x]
    }

    /// 8-bit RGB PNG bytes, tagged sRGB.
    pub fn encode_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        enc.set_compression(png::Compression::Fast);
        let data: Vec<u8> = self.pixels.iter().flat_map(|p| p.map(quantize)).collect();
        // Encoding into memory with a header matching `data` cannot fail.
        let mut writer = enc.write_header().expect("in-memory PNG header");
        writer.write_image_data(&data).expect("in-memory PNG data");
        writer.finish().expect("in-memory PNG finish");
        out
    }

    pub fn write_png(&self, path: &Path) -> Result<(), DataError> {
        mannequin_io::write_atomic(path, &self.encode_png()).map_err(|e| DataError::os(path, e))
    }

    /// The image as it reads back from an 8-bit PNG.
    pub fn quantized(&self) -> Self {
        let pixels = self.pixels.iter().map(|p| p.map(|v| quantize(v) as f32 / 255.0)).collect();
        Self { width: self.width, height: self.height, pixels }
    }

    /// Box-filter downscale by an integer factor: output pixel `(i, j)` averages the input block
    /// whose centre is at `factor (i + 0.5)`, so intrinsics scale exactly as `K / factor`.
    /// Rows and columns beyond a whole block are dropped.
    pub fn downscale(&self, factor: usize) -> Self {
        let (w, h) = (self.width / factor, self.height / factor);
        let inv = 1.0 / (factor * factor) as f32;
        let pixels = (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                let mut acc = [0.0f32; 3];
                for dy in 0..factor {
                    for dx in 0..factor {
                        let v = self.at(x * factor + dx, y * factor + dy);
                        (0..3).for_each(|c| acc[c] += v[c]);
                    }
                }
                acc.map(|a| a * inv)
            })
            .collect();
        Self { width: w, height: h, pixels }
    }

    /// `self` where `mask` is set, `background` elsewhere.
    pub fn composite(&self, mask: &Mask, background: [f32; 3]) -> Self {
        let pixels =
            self.pixels.iter().zip(&mask.values).map(|(&p, &m)| if m { p } else { background }).collect();
        Self { width: self.width, height: self.height, pixels }
    }
}

impl Mask {
    pub fn at(&self, x: usize, y: usize) -> bool {
        self.values[y * self.width + x]
    }

    /// Intersection over union with a mask of the same size (0 when both are empty).
    pub fn iou(&self, other: &Mask) -> f64 {
        let (mut inter, mut union) = (0usize, 0usize);
        for (a, b) in self.values.iter().zip(&other.values) {
            inter += (*a && *b) as usize;
            union += (*a || *b) as usize;
        }
        if union == 0 { 0.0 } else { inter as f64 / union as f64 }
    }

    pub fn count(&self) -> usize {
        self.values.iter().filter(|&&m| m).count()
    }

    /// Majority vote over each `factor × factor` block (ties count as foreground).
    pub fn downscale(&self, factor: usize) -> Self {
        let (w, h) = (self.width / factor, self.height / factor);
        let values = (0..w * h)
            .map(|p| {
                let (x, y) = (p % w, p / w);
                let on = (0..factor * factor)
                    .filter(|k| self.at(x * factor + k % factor, y * factor + k / factor));
                2 * on.count() >= factor * factor
            })
            .collect();
        Self { width: w, height: h, values }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn iou_counts_shared_pixels_over_covered_ones() {
        let m = |v: [bool; 4]| Mask { width: 2, height: 2, values: v.to_vec() };
        // 1 pixel in both, 3 in either.
        assert_eq!(m([true, true, false, false]).iou(&m([false, true, true, false])), 1.0 / 3.0);
        assert_eq!(m([false; 4]).iou(&m([false; 4])), 0.0);
    }

    #[test]
    fn png_round_trip_is_exact_after_quantisation() {
        let img = Image {
            width: 3,
            height: 2,
            pixels: vec![
                [0.0, 0.5, 1.0],
                [0.1, 0.2, 0.3],
                [1.0, 1.0, 1.0],
                [0.0; 3],
                [0.25; 3],
                [0.9, 0.0, 0.4],
            ],
        };
        let back = Image::decode_png(Path::new("m.png"), &img.encode_png()).unwrap();
        assert_eq!(back, img.quantized());
        assert_eq!((back.width, back.height), (3, 2));
    }

    #[test]
    fn downscale_averages_blocks() {
        let img = Image { width: 4, height: 2, pixels: (0..8).map(|i| [i as f32, 0.0, 1.0]).collect() };
        let d = img.downscale(2);
        assert_eq!((d.width, d.height), (2, 1));
        // Block (0,1,4,5) and block (2,3,6,7).
        assert_eq!(d.pixels, vec![[2.5, 0.0, 1.0], [4.5, 0.0, 1.0]]);
    }
}
