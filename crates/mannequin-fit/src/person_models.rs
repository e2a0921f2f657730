//! The shipped person models, loaded once: MediaPipe's pose detector, pose landmarker and
//! selfie segmenter, and BlazeFace to find a body from its face (Apache-2.0, converted to ONNX
//! by `tools/person_models`; see `models/NOTICE.md`).

use mannequin_data::Image;

use crate::blazepose::LANDMARKS;
use crate::crop::{Border, RotatedRect, crop, uncrop};
use crate::error::FitError;
use crate::face_models::FACE_DETECTION;
use crate::network::Network;
use crate::person_search::{body_seeds, windows};
use crate::pose_landmarker::{MIN_POSE_FLAG, PoseLandmarks, aligned_roi, detection_roi, estimate};
use crate::ssd_detector::{Detection, FACE, POSE, box_area, box_intersection, box_iou, letterbox, suppress};

const POSE_DETECTION: &[u8] = include_bytes!("../models/pose_detection.onnx");
const POSE_LANDMARK: &[u8] = include_bytes!("../models/pose_landmark_full.onnx");
const SELFIE_SEGMENTATION: &[u8] = include_bytes!("../models/selfie_segmentation.onnx");
const SELFIE_SIZE: usize = 256;
/// Two people whose boxes are this close in area are too alike to pick between.
const SAME_SIZE: f32 = 0.85;
/// Two readings whose bodies' boxes overlap by more than this IoU are of one person.
const SAME_BODY: f32 = 0.5;
/// The landmarker's confidence a person found by searching (windows, faces) needs: many more
/// crops are read than in the whole picture, so more that hold no one pass MediaPipe's own
/// [`MIN_POSE_FLAG`] (a chest pack, a horse's head).
const MIN_SEARCHED_FLAG: f32 = 0.9;

/// The four networks, ready to run.
pub struct PersonModels {
    pub detector: Network,
    pub landmarker: Network,
    pub segmenter: Network,
    /// BlazeFace, whose faces seed the search for a body the pose detector misses.
    pub face_detector: Network,
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
            face_detector: Network::load("face_detection_short_range", FACE_DETECTION)?,
        })
    }

    /// Everyone found in the picture, largest box first: those the detector finds in the whole
    /// picture; where that is fewer than `person` needs (`--person n` needs n + 1, none needs
    /// one), also those it finds in overlapping square parts of it
    /// ([`PersonModels::in_windows`]); where that is still fewer, also the bodies below the
    /// faces BlazeFace finds ([`PersonModels::below_faces`]). The landmarker confirms each. The detector can miss one small person of two side by side that a window finds.
    pub fn people(&self, image: &Image, person: Option<usize>) -> Result<Vec<Person>, FitError> {
        let wanted = person.map_or(1, |n| n + 1);
        let mut found = self.in_whole_picture(image)?;
        if found.len() >= wanted {
            return Ok(found);
        }
        let more = self.in_windows(image)?;
        found.extend(elsewhere(&found, more));
        if found.len() >= wanted {
            return Ok(by_size(found));
        }
        let more = self.below_faces(image)?;
        found.extend(elsewhere(&found, more));
        Ok(by_size(found))
    }

    /// Everyone the detector finds in the whole picture (letterboxed) whose landmark crop the
    /// landmarker confirms, largest box first: what MediaPipe's own pipeline finds.
    pub fn in_whole_picture(&self, image: &Image) -> Result<Vec<Person>, FitError> {
        self.confirmed(image, POSE.detect(&self.detector, image)?, MIN_POSE_FLAG)
    }

    /// Everyone the detector finds in the overlapping square windows of [`windows`] (two or
    /// three scales), the windows' detections merged where they overlap, each confirmed by the
    /// landmarker at [`MIN_SEARCHED_FLAG`], each person once.
    pub fn in_windows(&self, image: &Image) -> Result<Vec<Person>, FitError> {
        let mut candidates = Vec::new();
        for window in windows(image.width, image.height) {
            candidates.extend(POSE.detect_in(&self.detector, image, &window)?);
        }
        Ok(distinct(self.confirmed(image, suppress(candidates), MIN_SEARCHED_FLAG)?))
    }

    /// The bodies below the faces BlazeFace finds in the whole picture and in the windows of
    /// [`windows`]: for each face, the landmarks read in the body regions [`body_seeds`]
    /// proposes, the surest kept where the landmarker confirms it at [`MIN_SEARCHED_FLAG`] with
    /// the body's nose on the face, each person once. The person's box is the face's, as the
    /// pose detector's own box is.
    pub fn below_faces(&self, image: &Image) -> Result<Vec<Person>, FitError> {
        let mut faces = FACE.detect(&self.face_detector, image)?;
        for window in windows(image.width, image.height) {
            faces.extend(FACE.detect_in(&self.face_detector, image, &window)?);
        }
        let mut out = Vec::new();
        for face in suppress(faces) {
            let mut best: Option<Person> = None;
            for [hip, scale] in body_seeds(&face) {
                let landmarks = estimate(&self.landmarker, image, aligned_roi(hip, scale))?;
                if landmarks.flag >= MIN_SEARCHED_FLAG
                    && nose_on_face(&landmarks, &face)
                    && best.as_ref().is_none_or(|b| landmarks.flag > b.landmarks.flag)
                {
                    let detection = Detection { keypoints: vec![hip, scale], ..face.clone() };
                    best = Some(Person { detection, landmarks });
                }
            }
            out.extend(best);
        }
        Ok(distinct(out))
    }

    /// The detections whose landmark crop the landmarker confirms (its flag at least `min_flag`),
    /// largest box first.
    fn confirmed(
        &self,
        image: &Image,
        detections: Vec<Detection>,
        min_flag: f32,
    ) -> Result<Vec<Person>, FitError> {
        let mut out = Vec::new();
        for detection in detections {
            let landmarks = estimate(&self.landmarker, image, detection_roi(&detection))?;
            if landmarks.flag >= min_flag {
                out.push(Person { detection, landmarks });
            }
        }
        Ok(by_size(out))
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

/// `people` less those read twice: windows of two scales (or two faces' seeds) can give the same
/// person two detections too unlike to merge (one the face, one the head), but the landmarks
/// read from both put the body in the same place. The surer reading is kept; largest box first.
fn distinct(mut people: Vec<Person>) -> Vec<Person> {
    people.sort_by(|a, b| b.landmarks.flag.total_cmp(&a.landmarks.flag));
    let mut out: Vec<Person> = Vec::new();
    for person in people {
        let body = body_box(&person.landmarks);
        if !out.iter().any(|o| box_iou(&body_box(&o.landmarks), &body) > SAME_BODY) {
            out.push(person);
        }
    }
    by_size(out)
}

/// Those of `more` whose bodies lie mostly outside every body in `found`: a window or a face
/// that sees part of someone already found (their head, their chest) reads a smaller body
/// within theirs, too unlike their own reading for [`distinct`] to merge.
fn elsewhere(found: &[Person], more: Vec<Person>) -> Vec<Person> {
    more.into_iter()
        .filter(|p| {
            let body = body_box(&p.landmarks);
            !found.iter().any(|f| share_of_smaller(&body_box(&f.landmarks), &body) > SAME_BODY)
        })
        .collect()
}

/// The share of the smaller of two boxes that lies within the other.
fn share_of_smaller(a: &[f32; 4], b: &[f32; 4]) -> f32 {
    let smaller = box_area(a).min(box_area(b));
    if smaller > 0.0 { box_intersection(a, b) / smaller } else { 0.0 }
}

/// `people` largest box first.
fn by_size(mut people: Vec<Person>) -> Vec<Person> {
    people.sort_by(|a, b| b.detection.area().total_cmp(&a.detection.area()));
    people
}

/// Whether the body read below a face is that face's: its nose (landmark 0) on the face's box.
fn nose_on_face(landmarks: &PoseLandmarks, face: &Detection) -> bool {
    let [x, y, _] = landmarks.points[0];
    let [x0, y0, x1, y1] = face.bbox;
    (x0..=x1).contains(&x) && (y0..=y1).contains(&y)
}

/// The box a person's body landmarks span, in image pixels.
pub fn body_box(l: &PoseLandmarks) -> [f32; 4] {
    l.points[..LANDMARKS.len()]
        .iter()
        .fold([f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY], |[x0, y0, x1, y1], p| {
            [x0.min(p[0]), y0.min(p[1]), x1.max(p[0]), y1.max(p[1])]
        })
}

/// The person `wanted` names (counting from 0, largest first), else the only or clearly largest
/// one of `people` (sorted as [`PersonModels::people`] sorts them).
pub fn pick_person(people: &[Person], wanted: Option<usize>) -> Result<&Person, FitError> {
    if people.is_empty() {
        return Err(FitError::Picture("no person found".into()));
    }
    if let Some(n) = wanted {
        return people.get(n).ok_or_else(|| {
            let found = match people.len() {
                1 => "found 1 person (--person 0)".to_string(),
                k => format!("found {k} people (--person 0 to {})", k - 1),
            };
            FitError::input(format!("--person {n}"), found)
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
