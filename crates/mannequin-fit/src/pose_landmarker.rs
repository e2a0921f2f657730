//! BlazePose landmarks for one person: the network reads a rotation-aligned square crop around
//! the person, and its outputs are brought back into the image as MediaPipe does (heatmap
//! refinement, then the crop's rotation and scale undone). The crop comes from a detection's
//! keypoints or, in video, from the previous frame's auxiliary landmarks.

use mannequin_data::{Image, Mask};

use crate::blazepose;
use crate::crop::{Border, RotatedRect, crop, uncrop};
use crate::error::FitError;
use crate::network::{Network, sigmoid};
use crate::ssd_detector::Detection;

pub const INPUT_SIZE: usize = 256;
/// The 33 BlazePose landmarks (then 2 auxiliary points for tracking, and 4 unused).
pub const NUM_LANDMARKS: usize = 33;
const NUM_OUTPUTS: usize = 39;
const HEATMAP_SIZE: usize = 64;
/// The refinement window. MediaPipe 0.10.21's graph asks for 7, but its output is matched (to
/// 0.3 px, against 4–22 px with 7) only by RefineLandmarksFromHeatmap's default of 9.
const REFINE_WINDOW: usize = 9;
const MIN_REFINE_CONFIDENCE: f32 = 0.5;
/// The crop around the alignment points' span is enlarged by this much.
const ROI_SCALE: f32 = 1.25;
/// Below this pose flag the crop holds no person.
pub const MIN_POSE_FLAG: f32 = 0.5;

/// One person's landmarks and mask in the image.
#[derive(Debug, Clone)]
pub struct PoseLandmarks {
    /// The crop they were read from.
    pub roi: RotatedRect,
    /// The network's confidence that the crop holds a person.
    pub flag: f32,
    /// x, y in image pixels; z (depth relative to the hips, camera-ward negative) on x's scale.
    pub points: Vec<[f32; 3]>,
    pub visibility: Vec<f32>,
    pub presence: Vec<f32>,
    /// Metric, hip-centred, in the camera's axes (x right, y down, z away).
    pub world: Vec<[f32; 3]>,
    /// The crop for the next video frame, from the two auxiliary points.
    pub next_roi: RotatedRect,
    /// Person probability per image pixel, row-major.
    pub mask: Vec<f32>,
}

impl PoseLandmarks {
    /// The person's mask as pixels: probability above one half.
    pub fn person_mask(&self, width: usize, height: usize) -> Mask {
        Mask { width, height, values: self.mask.iter().map(|&p| p > 0.5).collect() }
    }

    /// The other reading of the same picture: left and right swapped, depth turned over (about
    /// the hips). Seen from the side or behind, a landmarker can return this mirror of the
    /// person; both project to the same points.
    pub fn mirrored(&self) -> Self {
        let from = |i: usize| blazepose::mirror(i);
        let n = self.points.len();
        Self {
            points: (0..n)
                .map(|i| {
                    let [x, y, z] = self.points[from(i)];
                    [x, y, -z]
                })
                .collect(),
            visibility: (0..n).map(|i| self.visibility[from(i)]).collect(),
            presence: (0..n).map(|i| self.presence[from(i)]).collect(),
            world: (0..n)
                .map(|i| {
                    let [x, y, z] = self.world[from(i)];
                    [x, y, -z]
                })
                .collect(),
            mask: self.mask.clone(),
            ..*self
        }
    }
}

/// MediaPipe's AlignmentPointsRects + RectTransformation: a square centred on `centre`, its
/// side 2.5 × the distance to `scale_point`, turned so that the direction centre → scale point
/// points up in the crop.
pub fn aligned_roi(centre: [f32; 2], scale_point: [f32; 2]) -> RotatedRect {
    let (dx, dy) = (scale_point[0] - centre[0], scale_point[1] - centre[1]);
    let side = 2.0 * dx.hypot(dy) * ROI_SCALE;
    let angle = std::f32::consts::FRAC_PI_2 - (-dy).atan2(dx);
    let rotation =
        angle - std::f32::consts::TAU * ((angle + std::f32::consts::PI) / std::f32::consts::TAU).floor();
    RotatedRect { cx: centre[0], cy: centre[1], width: side, height: side, rotation }
}

/// The landmark crop for a detection: its keypoints 0 (hip centre) and 1 (scale point).
pub fn detection_roi(d: &Detection) -> RotatedRect {
    aligned_roi(d.keypoints[0], d.keypoints[1])
}

/// The network's 39 landmarks in the crop's [0, 1] square, x and y refined on the heatmaps:
/// (x, y, z, visibility, presence) with the last two as probabilities.
pub fn decode(raw: &[f32], heatmaps: &[f32]) -> Vec<[f32; 5]> {
    let n = INPUT_SIZE as f32;
    raw.chunks_exact(5)
        .enumerate()
        .map(|(k, r)| {
            let [mut x, mut y] = [r[0] / n, r[1] / n];
            if let Some([rx, ry]) = refine(heatmaps, k, x, y) {
                (x, y) = (rx, ry);
            }
            [x, y, r[2] / n, sigmoid(r[3]), sigmoid(r[4])]
        })
        .collect()
}

/// The confidence-weighted mean position in a window of landmark k's heatmap about (x, y),
/// when the window is confident enough.
fn refine(heatmaps: &[f32], k: usize, x: f32, y: f32) -> Option<[f32; 2]> {
    let size = HEATMAP_SIZE as i64;
    let (col, row) = ((x * size as f32) as i64, (y * size as f32) as i64);
    if col < 0 || row < 0 || col >= size || row >= size {
        return None;
    }
    let half = (REFINE_WINDOW as i64 - 1) / 2;
    let (mut sum, mut max, mut wx, mut wy) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
    for r in (row - half).max(0)..(row + half + 1).min(size) {
        for c in (col - half).max(0)..(col + half + 1).min(size) {
            let conf = sigmoid(heatmaps[((r * size + c) as usize) * NUM_OUTPUTS + k]);
            sum += conf;
            max = max.max(conf);
            wx += c as f32 * conf;
            wy += r as f32 * conf;
        }
    }
    (max >= MIN_REFINE_CONFIDENCE && sum > 0.0).then(|| [wx / size as f32 / sum, wy / size as f32 / sum])
}

/// Runs the landmark network on `roi` of the image.
pub fn estimate(network: &Network, image: &Image, roi: RotatedRect) -> Result<PoseLandmarks, FitError> {
    let out = network.run(crop(image, &roi, INPUT_SIZE, Border::Replicate))?;
    let get = |name: &str| -> Result<&[f32], FitError> { Ok(&out[network.output_index(name)?].values) };
    let crop_points = decode(get("landmarks")?, get("heatmaps")?);
    let n = INPUT_SIZE;
    let to_image = |p: &[f32; 5]| -> [f32; 3] {
        let [x, y] = roi.to_image(p[0] * n as f32, p[1] * n as f32, n);
        [x, y, p[2] * roi.width]
    };
    let (s, c) = roi.rotation.sin_cos();
    let world = get("world_landmarks")?
        .chunks_exact(3)
        .take(NUM_LANDMARKS)
        .map(|w| [c * w[0] - s * w[1], s * w[0] + c * w[1], w[2]])
        .collect();
    let [hip, scale] = [to_image(&crop_points[NUM_LANDMARKS]), to_image(&crop_points[NUM_LANDMARKS + 1])];
    let mask: Vec<f32> = get("mask")?.iter().map(|&v| sigmoid(v)).collect();
    Ok(PoseLandmarks {
        roi,
        flag: get("pose_flag")?[0],
        points: crop_points[..NUM_LANDMARKS].iter().map(to_image).collect(),
        visibility: crop_points[..NUM_LANDMARKS].iter().map(|p| p[3]).collect(),
        presence: crop_points[..NUM_LANDMARKS].iter().map(|p| p[4]).collect(),
        world,
        next_roi: aligned_roi([hip[0], hip[1]], [scale[0], scale[1]]),
        mask: uncrop(&mask, n, &roi, image.width, image.height),
    })
}
