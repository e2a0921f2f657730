//! The shipped face models, loaded once: MediaPipe's BlazeFace detector (short range) and face
//! mesh (Apache-2.0, converted to ONNX by `tools/person_models`; see `models/NOTICE.md`).

use mannequin_data::Image;

use crate::crop::RotatedRect;
use crate::error::FitError;
use crate::face_landmarker::{FaceLandmarks, MIN_FACE_FLAG, detection_roi, estimate};
use crate::network::Network;
use crate::ssd_detector::{Detection, FACE};

pub(crate) const FACE_DETECTION: &[u8] = include_bytes!("../models/face_detection_short_range.onnx");
const FACE_LANDMARK: &[u8] = include_bytes!("../models/face_landmark.onnx");

/// The face mesh reads a 192² crop 1.5× the face box: a box much under 48 pixels is upsampled
/// past what the network saw in training.
pub const MIN_FACE_PX: f32 = 48.0;

/// The two networks, ready to run.
pub struct FaceModels {
    pub detector: Network,
    pub landmarker: Network,
}

/// One face found in a picture.
#[derive(Debug, Clone)]
pub struct Face {
    pub detection: Detection,
    pub landmarks: FaceLandmarks,
}

impl FaceModels {
    pub fn load() -> Result<Self, FitError> {
        Ok(Self {
            detector: Network::load("face_detection_short_range", FACE_DETECTION)?,
            landmarker: Network::load("face_landmark", FACE_LANDMARK)?,
        })
    }

    /// Every face the detector finds whose mesh the landmarker confirms, largest box first.
    pub fn faces(&self, image: &Image) -> Result<Vec<Face>, FitError> {
        let mut out = Vec::new();
        for detection in FACE.detect(&self.detector, image)? {
            let landmarks = estimate(&self.landmarker, image, detection_roi(&detection))?;
            if landmarks.flag >= MIN_FACE_FLAG {
                out.push(Face { detection, landmarks });
            }
        }
        out.sort_by(|a, b| b.detection.area().total_cmp(&a.detection.area()));
        Ok(out)
    }

    /// A video frame's face mesh: read in `previous` (the last frame's next crop) while the
    /// network still sees a face there, else from the largest face the detector finds (MediaPipe's
    /// tracking); None when there is no face.
    pub fn track(
        &self,
        image: &Image,
        previous: Option<RotatedRect>,
    ) -> Result<Option<FaceLandmarks>, FitError> {
        if let Some(roi) = previous {
            let landmarks = estimate(&self.landmarker, image, roi)?;
            if landmarks.flag >= MIN_FACE_FLAG {
                return Ok(Some(landmarks));
            }
        }
        Ok(self.faces(image)?.into_iter().next().map(|f| f.landmarks))
    }
}
