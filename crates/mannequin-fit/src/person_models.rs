//! The shipped person models, loaded once: MediaPipe's pose detector, pose landmarker and
//! selfie segmenter (Apache-2.0, converted to ONNX by `tools/person_models`; see
//! `models/NOTICE.md`).

use mannequin_data::Image;

use crate::crop::{Border, RotatedRect, crop, uncrop};
use crate::error::FitError;
use crate::network::Network;
use crate::pose_landmarker::{MIN_POSE_FLAG, PoseLandmarks, detection_roi, estimate};
use crate::ssd_detector::{Detection, POSE, letterbox};

const POSE_DETECTION: &[u8] = include_bytes!("../models/pose_detection.onnx");
const POSE_LANDMARK: &[u8] = include_bytes!("../models/pose_landmark_full.onnx");
const SELFIE_SEGMENTATION: &[u8] = include_bytes!("../models/selfie_segmentation.onnx");
const SELFIE_SIZE: usize = 256;
/// Two people whose boxes are this close in area are too alike to pick between.
const SAME_SIZE: f32 = 0.85;

/// The three networks, ready to run.
pub struct PersonModels {
    pub detector: Network,
    pub landmarker: Network,
    pub segmenter: Network,
}

/// One person found in a picture.
#[derive(Debug, Clone)]
pub struct Person {
    pub detection: Detection,
    pub landmarks: PoseLandmarks,
}

impl PersonModels {
    pub fn load() -> Result<Self, FitError> {
        Ok(Self {
            detector: Network::load("pose_detection", POSE_DETECTION)?,
            landmarker: Network::load("pose_landmark_full", POSE_LANDMARK)?,
            segmenter: Network::load("selfie_segmentation", SELFIE_SEGMENTATION)?,
        })
    }

    /// Everyone the detector finds whose landmark crop the landmarker confirms, largest box
    /// first.
    pub fn people(&self, image: &Image) -> Result<Vec<Person>, FitError> {
        let mut out = Vec::new();
        for detection in POSE.detect(&self.detector, image)? {
            let landmarks = estimate(&self.landmarker, image, detection_roi(&detection))?;
            if landmarks.flag >= MIN_POSE_FLAG {
                out.push(Person { detection, landmarks });
            }
        }
        out.sort_by(|a, b| b.detection.area().total_cmp(&a.detection.area()));
        Ok(out)
    }

    /// The landmarks read again in the crop they themselves point to: the detector's crop is
    /// set by two keypoints alone, the landmarks' by the whole body, as MediaPipe crops every
    /// video frame after the first. Kept when the landmarker is at least as sure of them.
    pub fn refine(&self, image: &Image, landmarks: PoseLandmarks) -> Result<PoseLandmarks, FitError> {
        let again = estimate(&self.landmarker, image, landmarks.next_roi)?;
        Ok(if again.flag >= landmarks.flag { again } else { landmarks })
    }

    /// The same person in the next video frame, read in the crop their landmarks in the previous
    /// frame point to (`next_roi`, MediaPipe's tracking); None once the landmarker loses them.
    pub fn follow(&self, image: &Image, roi: RotatedRect) -> Result<Option<PoseLandmarks>, FitError> {
        let landmarks = estimate(&self.landmarker, image, roi)?;
        Ok((landmarks.flag >= MIN_POSE_FLAG).then_some(landmarks))
    }

    /// The probability that each pixel shows a person (anyone), from the selfie segmenter run
    /// on the whole picture letterboxed to 256².
    pub fn segment(&self, image: &Image) -> Result<Vec<f32>, FitError> {
        let lb = letterbox(image);
        let out = self.segmenter.run(crop(image, &lb, SELFIE_SIZE, Border::Zero))?;
        let mask = &out[self.segmenter.output_index("mask")?].values;
        Ok(uncrop(mask, SELFIE_SIZE, &lb, image.width, image.height))
    }
}

/// The person `wanted` names (counting from 0, largest first), else the only or clearly largest
/// one of `people` (sorted as [`PersonModels::people`] sorts them).
pub fn pick_person(people: &[Person], wanted: Option<usize>) -> Result<&Person, FitError> {
    if people.is_empty() {
        return Err(FitError::Picture("no person found".into()));
    }
    if let Some(n) = wanted {
        return people.get(n).ok_or_else(|| {
            FitError::input(
                format!("--person {n}"),
                format!("found {} people (0 to {})", people.len(), people.len() - 1),
            )
        });
    }
    if people.len() > 1 && people[1].detection.area() >= SAME_SIZE * people[0].detection.area() {
        let boxes: Vec<String> = people
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let b = p.detection.bbox;
                format!("{i}: x {:.0}–{:.0}, y {:.0}–{:.0}", b[0], b[2], b[1], b[3])
            })
            .collect();
        return Err(FitError::Picture(format!(
            "{} people of about the same size; choose one with --person N ({})",
            people.len(),
            boxes.join("; ")
        )));
    }
    Ok(&people[0])
}
