//! MediaPipe's single-shot detectors (the pose detector and BlazeFace) on a whole picture: the
//! letterboxed image through the network, its regressions decoded against the SSD anchors, then
//! weighted non-maximum suppression (boxes and keypoints averaged over each cluster, weighted by
//! score). The pose detector's keypoints 0 and 1 are the hip centre and a point that sets the
//! body's scale and direction; BlazeFace's six are the right and left eye, the nose tip, the
//! mouth and the right and left ear tragion (the person's right and left).

use mannequin_data::Image;

use crate::crop::{Border, RotatedRect, crop};
use crate::error::FitError;
use crate::network::{Network, sigmoid};

/// Scores are logits clipped to ±100; MediaPipe keeps detections at probability ≥ 0.5.
const SCORE_CLIP: f32 = 100.0;
pub const MIN_SCORE: f32 = 0.5;
/// Boxes overlapping the cluster's best by more than this IoU join its cluster.
const NMS_IOU: f32 = 0.3;

/// One detector's layout, as MediaPipe's SsdAnchorsCalculator and TensorsToDetections see it.
pub struct Ssd {
    /// The square input's side, in pixels.
    pub input_size: usize,
    /// Strides of the anchor layers; layers of equal stride share one feature map.
    pub strides: &'static [usize],
    pub keypoints: usize,
}

/// The pose detector: 224², 2,254 anchors, 4 keypoints.
pub const POSE: Ssd = Ssd { input_size: 224, strides: &[8, 16, 32, 32, 32], keypoints: 4 };
/// BlazeFace, short range: 128², 896 anchors, 6 keypoints.
pub const FACE: Ssd = Ssd { input_size: 128, strides: &[8, 16, 16, 16], keypoints: 6 };

/// A detection, in image pixels (or the detector input's [0, 1] square before [`Ssd::detect`]
/// maps it).
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    pub score: f32,
    /// xmin, ymin, xmax, ymax.
    pub bbox: [f32; 4],
    pub keypoints: Vec<[f32; 2]>,
}

impl Detection {
    /// The box's long side: how large the object is in the picture.
    pub fn side(&self) -> f32 {
        (self.bbox[2] - self.bbox[0]).max(self.bbox[3] - self.bbox[1])
    }

    pub fn area(&self) -> f32 {
        box_area(&self.bbox)
    }

    /// Intersection over union of the two boxes.
    pub fn iou(&self, other: &Self) -> f32 {
        box_iou(&self.bbox, &other.bbox)
    }
}

/// Intersection over union of two boxes (xmin, ymin, xmax, ymax).
pub fn box_iou(a: &[f32; 4], b: &[f32; 4]) -> f32 {
    let inter = box_intersection(a, b);
    let union = box_area(a) + box_area(b) - inter;
    if union > 0.0 { inter / union } else { 0.0 }
}

/// The area two boxes share.
pub(crate) fn box_intersection(a: &[f32; 4], b: &[f32; 4]) -> f32 {
    let w = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
    let h = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
    w * h
}

pub(crate) fn box_area(r: &[f32; 4]) -> f32 {
    (r[2] - r[0]).max(0.0) * (r[3] - r[1]).max(0.0)
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

impl Ssd {
    /// Anchor centres in [0, 1] of the input, in the network's output order: two anchors per
    /// cell and layer (aspect ratio 1 and the interpolated scale, also 1), centres at
    /// ((x + 0.5) / f, (y + 0.5) / f) of an f×f feature map, fixed unit size.
    pub fn anchors(&self) -> Vec<[f32; 2]> {
        let mut out = Vec::new();
        let mut layer = 0;
        while layer < self.strides.len() {
            let stride = self.strides[layer];
            let mut per_cell = 0;
            while layer < self.strides.len() && self.strides[layer] == stride {
                per_cell += 2;
                layer += 1;
            }
            let f = self.input_size.div_ceil(stride);
            for y in 0..f {
                for x in 0..f {
                    let centre = [(x as f32 + 0.5) / f as f32, (y as f32 + 0.5) / f as f32];
                    out.extend(std::iter::repeat_n(centre, per_cell));
                }
            }
        }
        out
    }

    /// The input tensor for an image: the letterbox, RGB in [−1, 1].
    pub fn input(&self, image: &Image) -> Vec<f32> {
        self.input_in(image, &letterbox(image))
    }

    /// The input tensor for a square `region` of an image, RGB in [−1, 1].
    fn input_in(&self, image: &Image, region: &RotatedRect) -> Vec<f32> {
        crop(image, region, self.input_size, Border::Zero).into_iter().map(|v| v * 2.0 - 1.0).collect()
    }

    /// Candidates above [`MIN_SCORE`], decoded from the raw outputs into the input's [0, 1]
    /// square: box centre and size, and keypoints, are offsets in input pixels from each anchor.
    pub fn decode(&self, regressors: &[f32], scores: &[f32]) -> Vec<Detection> {
        let scale = self.input_size as f32;
        self.anchors()
            .iter()
            .zip(regressors.chunks_exact(4 + 2 * self.keypoints))
            .zip(scores)
            .filter_map(|((a, r), &s)| {
                let score = sigmoid(s.clamp(-SCORE_CLIP, SCORE_CLIP));
                (score >= MIN_SCORE).then(|| {
                    let (cx, cy) = (r[0] / scale + a[0], r[1] / scale + a[1]);
                    let (w, h) = (r[2] / scale, r[3] / scale);
                    Detection {
                        score,
                        bbox: [cx - w / 2.0, cy - h / 2.0, cx + w / 2.0, cy + h / 2.0],
                        keypoints: r[4..]
                            .chunks_exact(2)
                            .map(|k| [k[0] / scale + a[0], k[1] / scale + a[1]])
                            .collect(),
                    }
                })
            })
            .collect()
    }

    /// Everything the detector finds in the image, best score first, in image pixels.
    pub fn detect(&self, network: &Network, image: &Image) -> Result<Vec<Detection>, FitError> {
        self.detect_in(network, image, &letterbox(image))
    }

    /// Everything the detector finds in a square `region` of the image (read as if it were the
    /// whole picture), best score first, in image pixels.
    pub fn detect_in(
        &self,
        network: &Network,
        image: &Image,
        region: &RotatedRect,
    ) -> Result<Vec<Detection>, FitError> {
        let out = network.run(self.input_in(image, region))?;
        let regressors = &out[network.output_index("regressors")?].values;
        let scores = &out[network.output_index("scores")?].values;
        Ok(suppress(self.decode(regressors, scores)).iter().map(|d| to_image(d, region)).collect())
    }
}

/// Weighted non-maximum suppression, best score first.
pub fn suppress(mut candidates: Vec<Detection>) -> Vec<Detection> {
    candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
    let mut out = Vec::new();
    while let Some(best) = candidates.first().cloned() {
        let (cluster, rest): (Vec<_>, Vec<_>) = candidates.into_iter().partition(|d| best.iou(d) > NMS_IOU);
        candidates = rest;
        let total: f32 = cluster.iter().map(|d| d.score).sum();
        let mut merged =
            Detection { score: best.score, bbox: [0.0; 4], keypoints: vec![[0.0; 2]; best.keypoints.len()] };
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

/// Maps a detection from the [0, 1] square of the region the detector read into image pixels.
fn to_image(d: &Detection, region: &RotatedRect) -> Detection {
    let map = |x: f32, y: f32| region.to_image(x, y, 1);
    let [x0, y0] = map(d.bbox[0], d.bbox[1]);
    let [x1, y1] = map(d.bbox[2], d.bbox[3]);
    Detection {
        score: d.score,
        bbox: [x0, y0, x1, y1],
        keypoints: d.keypoints.iter().map(|&[x, y]| map(x, y)).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_detectors_have_as_many_anchors_as_outputs() {
        let a = POSE.anchors();
        // 28²·2 + 14²·2 + 7²·6, the length of the pose network's outputs.
        assert_eq!(a.len(), 2254);
        assert_eq!(a[0], [0.5 / 28.0, 0.5 / 28.0]);
        assert_eq!(a[2253], [6.5 / 7.0, 6.5 / 7.0]);
        // 16²·2 + 8²·6, BlazeFace's.
        let a = FACE.anchors();
        assert_eq!(a.len(), 896);
        assert_eq!(a[511], [15.5 / 16.0, 15.5 / 16.0]);
        assert_eq!(a[512], [0.5 / 8.0, 0.5 / 8.0]);
    }
}
