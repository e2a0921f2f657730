//! Rotated square crops, as MediaPipe cuts them for its networks: a rectangle in the image maps
//! onto an n×n tensor (its corners onto the tensor's corners). Geometry is in image pixels with
//! pixel i spanning [i, i + 1) (MediaPipe's normalised coordinates times the size, the project's
//! convention), but the crop samples as OpenCV's warp does, reading coordinate x as pixel index x:
//! half a pixel off, kept so the networks see exactly what they see inside MediaPipe. For the
//! same reason the crop is computed as OpenCV's fixed-point warp of an 8-bit frame computes it:
//! a plain float bilinear crop moves visible landmarks by about a pixel, and landmarks near the
//! heatmap refinement's threshold by tens. The inverse map brings the networks' outputs back
//! into the image.

use mannequin_data::Image;

/// A rectangle in image pixels, rotated by `rotation` radians (clockwise on screen, y down).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotatedRect {
    pub cx: f32,
    pub cy: f32,
    pub width: f32,
    pub height: f32,
    pub rotation: f32,
}

/// What a crop reads outside the image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Border {
    /// Black (MediaPipe's BORDER_ZERO: the detector's letterbox).
    Zero,
    /// The nearest edge pixel (its default for the landmark crop).
    Replicate,
}

impl RotatedRect {
    /// The image point for crop coordinates (u, v) of an n×n crop, u, v in [0, n].
    pub fn to_image(&self, u: f32, v: f32, n: usize) -> [f32; 2] {
        let x = (u / n as f32 - 0.5) * self.width;
        let y = (v / n as f32 - 0.5) * self.height;
        let (s, c) = self.rotation.sin_cos();
        [self.cx + c * x - s * y, self.cy + s * x + c * y]
    }

    /// The crop coordinates of an image point (the inverse of [`RotatedRect::to_image`]).
    pub fn to_crop(&self, px: f32, py: f32, n: usize) -> [f32; 2] {
        let (dx, dy) = (px - self.cx, py - self.cy);
        let (s, c) = self.rotation.sin_cos();
        let x = c * dx + s * dy;
        let y = -s * dx + c * dy;
        [(x / self.width + 0.5) * n as f32, (y / self.height + 0.5) * n as f32]
    }

    /// The square of side max(width, height) about the same centre: what a crop that keeps the
    /// aspect ratio covers (MediaPipe's letterbox).
    pub fn letterboxed(&self) -> Self {
        let side = self.width.max(self.height);
        Self { width: side, height: side, ..*self }
    }
}

/// OpenCV's warp resolves sample positions to 1/32 pixel.
const SUBPIXEL: f64 = 32.0;

/// One crop sample as OpenCV's fixed-point bilinear warp of an 8-bit image computes it: the
/// position rounded to 1/32 pixel, integer weights (32 − f)·(32 − g) … summing to 1024, and the
/// sum rounded half up to a byte.
fn sample(bytes: &[[u8; 3]], width: usize, height: usize, x: f64, y: f64, border: Border) -> [u8; 3] {
    let (fx, fy) = ((x * SUBPIXEL).round() as i64, (y * SUBPIXEL).round() as i64);
    let (i, j) = (fx >> 5, fy >> 5);
    let (a, b) = (fx & 31, fy & 31);
    let (w, h) = (width as i64, height as i64);
    let texel = |i: i64, j: i64| -> [u8; 3] {
        match border {
            Border::Zero if i < 0 || j < 0 || i >= w || j >= h => [0; 3],
            _ => bytes[(j.clamp(0, h - 1) * w + i.clamp(0, w - 1)) as usize],
        }
    };
    let taps = [
        (texel(i, j), (32 - a) * (32 - b)),
        (texel(i + 1, j), a * (32 - b)),
        (texel(i, j + 1), (32 - a) * b),
        (texel(i + 1, j + 1), a * b),
    ];
    std::array::from_fn(|c| ((taps.iter().map(|(p, w)| p[c] as i64 * w).sum::<i64>() + 512) >> 10) as u8)
}

/// The n×n×3 crop of `rect`, row-major RGB in [0, 1] (in steps of 1/255).
pub fn crop(image: &Image, rect: &RotatedRect, n: usize, border: Border) -> Vec<f32> {
    let bytes: Vec<[u8; 3]> =
        image.pixels.iter().map(|p| p.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8)).collect();
    let (s, c) = (rect.rotation as f64).sin_cos();
    let mut out = Vec::with_capacity(n * n * 3);
    for v in 0..n {
        for u in 0..n {
            let lx = (u as f64 / n as f64 - 0.5) * rect.width as f64;
            let ly = (v as f64 / n as f64 - 0.5) * rect.height as f64;
            let (x, y) = (rect.cx as f64 + c * lx - s * ly, rect.cy as f64 + s * lx + c * ly);
            out.extend(sample(&bytes, image.width, image.height, x, y, border).map(|b| b as f32 / 255.0));
        }
    }
    out
}

/// An n×n map over the crop (a mask) brought back onto a width×height image, bilinearly; zero
/// outside the crop.
pub fn uncrop(map: &[f32], n: usize, rect: &RotatedRect, width: usize, height: usize) -> Vec<f32> {
    let mut out = vec![0.0; width * height];
    for y in 0..height {
        for x in 0..width {
            let [u, v] = rect.to_crop(x as f32, y as f32, n);
            let (u0, v0) = (u.floor(), v.floor());
            let (fu, fv) = (u - u0, v - v0);
            let at = |i: f32, j: f32| -> f32 {
                if i < 0.0 || j < 0.0 || i >= n as f32 || j >= n as f32 {
                    0.0
                } else {
                    map[j as usize * n + i as usize]
                }
            };
            out[y * width + x] = (at(u0, v0) * (1.0 - fu) + at(u0 + 1.0, v0) * fu) * (1.0 - fv)
                + (at(u0, v0 + 1.0) * (1.0 - fu) + at(u0 + 1.0, v0 + 1.0) * fu) * fv;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crop_coordinates_invert() {
        let r = RotatedRect { cx: 120.0, cy: 80.0, width: 64.0, height: 40.0, rotation: 0.7 };
        let [x, y] = r.to_image(37.0, 201.0, 256);
        let [u, v] = r.to_crop(x, y, 256);
        assert!((u - 37.0).abs() < 1e-3 && (v - 201.0).abs() < 1e-3, "{u} {v}");
    }

    #[test]
    fn a_quarter_turn_maps_the_crop_top_edge_onto_the_right() {
        // Rotated by +90° (clockwise on screen), the crop's top-left corner lies at the
        // rectangle's top-right on screen.
        let r =
            RotatedRect { cx: 0.0, cy: 0.0, width: 2.0, height: 2.0, rotation: std::f32::consts::FRAC_PI_2 };
        let [x, y] = r.to_image(0.0, 0.0, 4);
        assert!((x - 1.0).abs() < 1e-6 && (y + 1.0).abs() < 1e-6, "{x} {y}");
    }

    #[test]
    fn half_way_between_two_pixels_rounds_half_up() {
        // OpenCV's fixed-point warp: (10 + 11) / 2 = 10.5 → 11.
        let bytes = [[10, 0, 0], [11, 0, 0]];
        assert_eq!(sample(&bytes, 2, 1, 0.5, 0.0, Border::Replicate)[0], 11);
        // Positions snap to 1/32 pixel: 0.01 reads the first pixel alone.
        assert_eq!(sample(&bytes, 2, 1, 0.01, 0.0, Border::Replicate)[0], 10);
        assert_eq!(sample(&bytes, 2, 1, -3.0, 0.0, Border::Zero)[0], 0);
    }

    #[test]
    fn an_axis_aligned_crop_at_pixel_scale_copies_pixels() {
        let pixels = (0..16).map(|i| [(10 * i) as f32 / 255.0, 0.0, 1.0]).collect();
        let image = Image { width: 4, height: 4, pixels };
        // Crop index i samples image coordinate i when the rect spans [0, 4) at scale 1.
        let r = RotatedRect { cx: 2.0, cy: 2.0, width: 4.0, height: 4.0, rotation: 0.0 };
        let c = crop(&image, &r, 4, Border::Zero);
        for (k, px) in c.chunks(3).enumerate() {
            assert_eq!(px[0], (10 * k) as f32 / 255.0, "pixel {k}");
        }
    }
}
