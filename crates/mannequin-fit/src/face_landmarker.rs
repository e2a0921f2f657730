//! MediaPipe's face mesh: 468 points over the face, read from a crop turned upright by the
//! eyes. From a BlazeFace detection the crop is the detection box, squared on its long side and
//! grown 1.5× (DetectionsToRects + RectTransformation in `face_detection_front_detection_to_roi`),
//! turned so that the right eye → left eye line is level.

use mannequin_data::Image;

use crate::crop::{Border, RotatedRect, crop};
use crate::error::FitError;
use crate::network::{Network, sigmoid};
use crate::ssd_detector::Detection;

pub const INPUT_SIZE: usize = 192;
pub const NUM_LANDMARKS: usize = 468;
/// MediaPipe keeps a face mesh whose face flag passes one half.
pub const MIN_FACE_FLAG: f32 = 0.5;
/// The crop's side over the detection box's long side.
const ROI_SCALE: f32 = 1.5;

/// One face's mesh points.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLandmarks {
    /// The crop they were read from.
    pub roi: RotatedRect,
    /// The network's confidence that the crop holds a face, a probability.
    pub flag: f32,
    /// x, y in image pixels; z (depth, camera-ward negative) on x's scale, as MediaPipe's
    /// normalised z times the image width.
    pub points: Vec<[f32; 3]>,
}

/// The rotation that levels the line from `right_eye` to `left_eye` (the person's right and
/// left), in MediaPipe's range [−π, π).
fn level(right_eye: [f32; 2], left_eye: [f32; 2]) -> f32 {
    let angle = -(-(left_eye[1] - right_eye[1])).atan2(left_eye[0] - right_eye[0]);
    angle - std::f32::consts::TAU * ((angle + std::f32::consts::PI) / std::f32::consts::TAU).floor()
}

/// The mesh crop for a BlazeFace detection (keypoints 0 and 1: right and left eye).
pub fn detection_roi(d: &Detection) -> RotatedRect {
    let [x0, y0, x1, y1] = d.bbox;
    let side = ROI_SCALE * (x1 - x0).max(y1 - y0);
    RotatedRect {
        cx: (x0 + x1) / 2.0,
        cy: (y0 + y1) / 2.0,
        width: side,
        height: side,
        rotation: level(d.keypoints[0], d.keypoints[1]),
    }
}

impl FaceLandmarks {
    /// The corners (least and greatest x, y) of the box around the points, in pixels.
    pub fn bounds(&self) -> ([f32; 2], [f32; 2]) {
        let (mut lo, mut hi) = ([f32::INFINITY; 2], [f32::NEG_INFINITY; 2]);
        for p in &self.points {
            (0..2).for_each(|c| (lo[c], hi[c]) = (lo[c].min(p[c]), hi[c].max(p[c])));
        }
        (lo, hi)
    }

    /// The next video frame's crop from these points (MediaPipe's
    /// `face_landmark_landmarks_to_roi`): their bounding box, squared on its long side and grown
    /// 1.5×, levelled by the outer eye corners (points 33 and 263).
    pub fn next_roi(&self) -> RotatedRect {
        let (lo, hi) = self.bounds();
        let side = ROI_SCALE * (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let eye = |i: usize| [self.points[i][0], self.points[i][1]];
        RotatedRect {
            cx: (lo[0] + hi[0]) / 2.0,
            cy: (lo[1] + hi[1]) / 2.0,
            width: side,
            height: side,
            rotation: level(eye(33), eye(263)),
        }
    }
}

/// Runs the face mesh network on `roi` of the image.
pub fn estimate(network: &Network, image: &Image, roi: RotatedRect) -> Result<FaceLandmarks, FitError> {
    let out = network.run(crop(image, &roi, INPUT_SIZE, Border::Replicate))?;
    let get = |name: &str| -> Result<&[f32], FitError> { Ok(&out[network.output_index(name)?].values) };
    let n = INPUT_SIZE;
    let points = get("landmarks")?
        .chunks_exact(3)
        .map(|p| {
            let [x, y] = roi.to_image(p[0], p[1], n);
            [x, y, p[2] / n as f32 * roi.width]
        })
        .collect();
    Ok(FaceLandmarks { roi, flag: sigmoid(get("face_flag")?[0]), points })
}
