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
