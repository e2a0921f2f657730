//! People in a whole picture: MediaPipe's pose detector on the letterboxed image, its SSD
//! regressions decoded against the anchors, then weighted non-maximum suppression (boxes and
//! keypoints averaged over each cluster, weighted by score). Each detection carries the
//! keypoints the landmark crop is aligned with: 0 the hip centre, 1 a point that sets the
//! body's scale and direction.

use mannequin_data::Image;

use crate::crop::{Border, RotatedRect, crop};
use crate::error::FitError;
use crate::network::Network;
use crate::pose_landmarker::sigmoid;
use crate::ssd_anchors::anchors;

pub const INPUT_SIZE: usize = 224;
/// Scores are logits clipped to ±100; MediaPipe keeps detections at probability ≥ 0.5.
const SCORE_CLIP: f32 = 100.0;
pub const MIN_SCORE: f32 = 0.5;
/// Boxes overlapping the cluster's best by more than this IoU join its cluster.
const NMS_IOU: f32 = 0.3;
const KEYPOINTS: usize = 4;

/// A detected person, in image pixels.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    pub score: f32,
    /// xmin, ymin, xmax, ymax.
    pub bbox: [f32; 4],
    pub keypoints: [[f32; 2]; KEYPOINTS],
}

impl Detection {
    pub fn area(&self) -> f32 {
        (self.bbox[2] - self.bbox[0]).max(0.0) * (self.bbox[3] - self.bbox[1]).max(0.0)
    }

    fn iou(&self, other: &Self) -> f32 {
        let w = (self.bbox[2].min(other.bbox[2]) - self.bbox[0].max(other.bbox[0])).max(0.0);
        let h = (self.bbox[3].min(other.bbox[3]) - self.bbox[1].max(other.bbox[1])).max(0.0);
        let inter = w * h;
        let union = self.area() + other.area() - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }
}

/// The letterbox the detector sees: the whole image, padded to a square with black.
pub fn letterbox(image: &Image) -> RotatedRect {
    RotatedRect {
        cx: image.width as f32 / 2.0,
        cy: image.height as f32 / 2.0,
        width: image.width as f32,
        height: image.height as f32,
        rotation: 0.0,
    }
    .letterboxed()
}

/// The detector's input tensor for an image: 224² RGB in [−1, 1].
pub fn detector_input(image: &Image) -> Vec<f32> {
    crop(image, &letterbox(image), INPUT_SIZE, Border::Zero).into_iter().map(|v| v * 2.0 - 1.0).collect()
}

/// Candidates above [`MIN_SCORE`], decoded from the raw outputs into the detector input's
/// [0, 1] square: box centre and size are offsets in input pixels from each anchor.
pub fn decode(regressors: &[f32], scores: &[f32]) -> Vec<Detection> {
    let scale = INPUT_SIZE as f32;
    anchors()
        .iter()
        .zip(regressors.chunks_exact(4 + 2 * KEYPOINTS))
        .zip(scores)
        .filter_map(|((a, r), &s)| {
            let score = sigmoid(s.clamp(-SCORE_CLIP, SCORE_CLIP));
            (score >= MIN_SCORE).then(|| {
                let (cx, cy) = (r[0] / scale + a[0], r[1] / scale + a[1]);
                let (w, h) = (r[2] / scale, r[3] / scale);
                Detection {
                    score,
                    bbox: [cx - w / 2.0, cy - h / 2.0, cx + w / 2.0, cy + h / 2.0],
                    keypoints: std::array::from_fn(|k| {
                        [r[4 + 2 * k] / scale + a[0], r[5 + 2 * k] / scale + a[1]]
                    }),
                }
            })
        })
        .collect()
}

/// Weighted non-maximum suppression, best score first.
pub fn suppress(mut candidates: Vec<Detection>) -> Vec<Detection> {
    candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
    let mut out = Vec::new();
    while let Some(best) = candidates.first().cloned() {
        let (cluster, rest): (Vec<_>, Vec<_>) = candidates.into_iter().partition(|d| best.iou(d) > NMS_IOU);
        candidates = rest;
        let total: f32 = cluster.iter().map(|d| d.score).sum();
        let mut merged = Detection { score: best.score, bbox: [0.0; 4], keypoints: [[0.0; 2]; KEYPOINTS] };
        for d in &cluster {
            let w = d.score / total;
            (0..4).for_each(|i| merged.bbox[i] += w * d.bbox[i]);
            for (m, k) in merged.keypoints.iter_mut().zip(&d.keypoints) {
                m[0] += w * k[0];
                m[1] += w * k[1];
            }
        }
        out.push(merged);
    }
    out
}

/// Maps a detection from the letterbox's [0, 1] square into image pixels.
fn to_image(d: &Detection, letterbox: &RotatedRect) -> Detection {
    let map = |x: f32, y: f32| letterbox.to_image(x, y, 1);
    let [x0, y0] = map(d.bbox[0], d.bbox[1]);
    let [x1, y1] = map(d.bbox[2], d.bbox[3]);
    Detection { score: d.score, bbox: [x0, y0, x1, y1], keypoints: d.keypoints.map(|[x, y]| map(x, y)) }
}

/// Every person the detector finds in the image, best score first, in image pixels.
pub fn detect(network: &Network, image: &Image) -> Result<Vec<Detection>, FitError> {
    let out = network.run(detector_input(image))?;
    let regressors = &out[network.output_index("regressors")?].values;
    let scores = &out[network.output_index("scores")?].values;
    let lb = letterbox(image);
    Ok(suppress(decode(regressors, scores)).iter().map(|d| to_image(d, &lb)).collect())
}
