//! Training and test views: a frame's camera and body pose, with its targets cropped to the
//! subject (masks give the box). Losses only look inside the crop, which keeps SSIM cheap.

use mannequin_data::{Dataset, Split};

use crate::error::AvatarError;

/// Pixels added around the mask's bounding box, so silhouette errors stay inside the crop.
const CROP_MARGIN: usize = 16;
/// SSIM's window: crops are at least this large.
const MIN_CROP: usize = 11;

/// Near and far planes of the splatting camera, in metres.
const NEAR: f64 = 0.01;
const FAR: f64 = 100.0;

/// The camera of a dataset frame, clipping at the avatar's depth range (datasets store none).
pub fn frame_camera(dataset: &Dataset, frame: usize) -> mannequin_splat::Camera {
    mannequin_splat::Camera { near: NEAR, far: FAR, ..dataset.camera(frame).clone() }
}

/// A pixel rectangle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Crop {
    pub x: usize,
    pub y: usize,
    pub width: usize,
    pub height: usize,
}

#[derive(Debug, Clone)]
pub struct View {
    pub frame: usize,
    pub camera: mannequin_splat::Camera,
    /// Axis-angle body pose, 72 values (SMPL layout).
    pub pose: Vec<f32>,
    pub transl: [f32; 3],
    pub crop: Crop,
    /// Targets over the crop, [C, h, w]: colour over white, then camera-space normals (zero on
    /// the background) where the dataset has them (C = 6, else 3), stacked as the losses read
    /// them.
    pub targets: Vec<f32>,
    /// [h, w] in {0, 1}.
    pub mask: Vec<f32>,
}

impl View {
    /// Channels of `targets`: 6 with normal maps, 3 without.
    pub fn target_channels(&self) -> usize {
        self.targets.len() / (self.crop.width * self.crop.height)
    }

    pub fn has_normals(&self) -> bool {
        self.target_channels() == 6
    }

    /// Target colour over white, [3, h, w].
    pub fn rgb(&self) -> &[f32] {
        &self.targets[..3 * self.crop.width * self.crop.height]
    }

    /// The camera that renders just the crop.
    pub fn crop_camera(&self) -> mannequin_splat::Camera {
        let c = &self.crop;
        self.camera.crop(c.x, c.y, c.width, c.height)
    }

    /// The crop at half resolution: each pixel the mean of a 2×2 block (an odd last row or
    /// column dropped), mask included, so edges become fractional coverage as a render's alpha
    /// is. Its camera is the crop's, downscaled, and its crop the whole of it. `None` when the
    /// halved crop would be smaller than SSIM's window.
    pub fn halved(&self) -> Option<View> {
        let (w, h) = (self.crop.width / 2, self.crop.height / 2);
        if w < MIN_CROP || h < MIN_CROP {
            return None;
        }
        let (stride, n) = (self.crop.width, self.crop.width * self.crop.height);
        let block = |plane: &[f32], x: usize, y: usize| {
            let at = |dx: usize, dy: usize| plane[(2 * y + dy) * stride + 2 * x + dx];
            0.25 * (at(0, 0) + at(1, 0) + at(0, 1) + at(1, 1))
        };
        let half = |planes: &[f32]| -> Vec<f32> {
            planes
                .chunks_exact(n)
                .flat_map(|plane| (0..w * h).map(move |q| block(plane, q % w, q / w)))
                .collect()
        };
        Some(View {
            camera: self.crop_camera().downscale(2),
            crop: Crop { x: 0, y: 0, width: w, height: h },
            targets: half(&self.targets),
            mask: half(&self.mask),
            ..self.clone()
        })
    }
}

/// The mask's bounding box grown by the margin, clamped to the image, at least `MIN_CROP` wide.
fn crop_of(mask: &mannequin_data::Mask) -> Crop {
    let (w, h) = (mask.width, mask.height);
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for (i, _) in mask.values.iter().enumerate().filter(|(_, m)| **m) {
        let (x, y) = (i % w, i / w);
        (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
    }
    if x1 <= x0 {
        // An empty mask: use the whole image so the avatar learns to vanish there.
        return Crop { x: 0, y: 0, width: w, height: h };
    }
    let grow = |lo: usize, hi: usize, size: usize| {
        let lo = lo.saturating_sub(CROP_MARGIN);
        let hi = (hi + CROP_MARGIN).min(size);
        let hi = hi.max((lo + MIN_CROP).min(size));
        let lo = lo.min(hi.saturating_sub(MIN_CROP));
        (lo, hi - lo)
    };
    let (x, width) = grow(x0, x1, w);
    let (y, height) = grow(y0, y1, h);
    Crop { x, y, width, height }
}

/// Loads every frame of `split`, calling `progress(done, total)` after each.
pub fn load_views(
    dataset: &Dataset,
    split: &Split,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<View>, AvatarError> {
    let mut views = Vec::with_capacity(split.frames.len());
    for (i, &frame) in split.frames.iter().enumerate() {
        let f = dataset.frame(frame)?;
        let camera = frame_camera(dataset, frame);
        if camera.width < MIN_CROP || camera.height < MIN_CROP {
            return Err(AvatarError::Invalid(format!(
                "frame {frame}: images of {}×{} are too small to train on (at least {MIN_CROP}×{MIN_CROP})",
                camera.width, camera.height
            )));
        }
        let crop = crop_of(&f.mask);
        let (w, n) = (f.image.width, crop.width * crop.height);
        let channels = if f.normals.is_some() { 6 } else { 3 };
        let mut targets = vec![0.0f32; channels * n];
        let mut mask = vec![0.0f32; n];
        for y in 0..crop.height {
            for x in 0..crop.width {
                let (p, q) = ((crop.y + y) * w + crop.x + x, y * crop.width + x);
                let fg = f.mask.values[p];
                mask[q] = f32::from(u8::from(fg));
                for c in 0..3 {
                    targets[c * n + q] = if fg { f.image.pixels[p][c] } else { 1.0 };
                }
                if let Some(map) = &f.normals {
                    for c in 0..3 {
                        targets[(3 + c) * n + q] = map.normals[p][c];
                    }
                }
            }
        }
        let pose = split.poses.pose72(i);
        views.push(View { frame, camera, pose, transl: split.poses.transl[i], crop, targets, mask });
        progress(i + 1, split.frames.len());
    }
    Ok(views)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn halving_averages_blocks_and_keeps_the_camera_on_them() {
        let camera =
            mannequin_splat::Camera::look_at([0.0, 0.0, 3.0], [0.0; 3], [0.0, 1.0, 0.0], 0.8, 64, 48);
        // A 25 × 23 crop at (9, 7): the halved view is 12 × 11, dropping the odd last column and
        // row. Channel c of pixel (x, y) holds 1000c + 100y + x.
        let crop = Crop { x: 9, y: 7, width: 25, height: 23 };
        let n = crop.width * crop.height;
        let value = |c: usize, x: usize, y: usize| (1000 * c + 100 * y + x) as f32;
        let targets = (0..6 * n).map(|i| value(i / n, i % n % crop.width, i % n / crop.width)).collect();
        let mask = (0..n).map(|i| f32::from(u8::from(i % crop.width < 13))).collect();
        let view = View { frame: 0, camera, pose: vec![0.0; 72], transl: [0.0; 3], crop, targets, mask };
        let half = view.halved().expect("large enough");
        assert_eq!((half.crop.x, half.crop.y, half.crop.width, half.crop.height), (0, 0, 12, 11));
        assert_eq!(half.target_channels(), 6);
        let m = 12 * 11;
        for (c, x, y) in [(0, 0, 0), (2, 5, 3), (5, 11, 10)] {
            // The mean of x over {2x, 2x + 1} is 2x + ½, likewise for y.
            let expected = 1000.0 * c as f32 + 100.0 * (2 * y) as f32 + 50.0 + (2 * x) as f32 + 0.5;
            assert_eq!(half.targets[c * m + y * 12 + x], expected);
        }
        // Columns 0–12 of the crop are masked: block 6 holds columns 12 and 13, half covered.
        assert_eq!(half.mask[6], 0.5);
        assert_eq!(half.mask[5], 1.0);
        assert_eq!(half.mask[7], 0.0);
        // A world point lands at half its crop coordinates.
        let p = DVec3::new(0.1, -0.05, 0.2);
        let [u, v] = view.crop_camera().project(view.crop_camera().world_to_camera(p));
        let [hu, hv] = half.crop_camera().project(half.crop_camera().world_to_camera(p));
        assert!((hu - u / 2.0).abs() < 1e-9 && (hv - v / 2.0).abs() < 1e-9, "({u}, {v}) → ({hu}, {hv})");
        // Too small to halve: SSIM's window would not fit.
        let small = View { crop: Crop { width: 21, height: 30, ..crop }, ..view };
        assert!(small.halved().is_none());
    }
}
