//! A clip to one person's landmarks and body per frame. The person is found in the first frame
//! and followed as MediaPipe follows them (the next crop from this frame's auxiliary points),
//! found again where the landmarker loses them. The body gets one shape for the whole clip, the
//! median of independent fits on a few frames spread over it; then each frame's pose starts from
//! the previous frame's and is pulled toward it, which keeps the motion smooth without a solve
//! over all frames at once.

use mannequin_data::Image;

use crate::body_fit::{Anchor, BodyFit, Fitter};
use crate::crop::RotatedRect;
use crate::error::FitError;
use crate::person_models::{PersonModels, pick_person};
use crate::pose_landmarker::PoseLandmarks;

/// Frames fitted independently to find the clip's one shape.
const SHAPE_FRAMES: usize = 8;
/// How hard each frame's pose is pulled toward the previous frame's, per radian (the landmark
/// term counts 1 per 1 % of the person's crop).
const SMOOTHNESS: f64 = 2.0;

/// Follows one person from frame to frame.
pub struct Tracker<'a> {
    models: &'a PersonModels,
    /// Where the last frame's landmarks put the person next.
    next_roi: Option<RotatedRect>,
}

impl<'a> Tracker<'a> {
    pub fn new(models: &'a PersonModels) -> Self {
        Self { models, next_roi: None }
    }

    /// The person's landmarks in the next frame; None when nobody is there.
    pub fn next(&mut self, image: &Image) -> Result<Option<PoseLandmarks>, FitError> {
        let followed = match self.next_roi {
            Some(roi) => self.models.follow(image, roi)?,
            None => None,
        };
        let found = match followed {
            Some(l) => Some(l),
            None => {
                let everyone = self.models.people(image)?;
                match everyone.is_empty() {
                    true => None,
                    false => {
                        Some(self.models.refine(image, pick_person(&everyone, None)?.landmarks.clone())?)
                    }
                }
            }
        };
        self.next_roi = found.as_ref().map(|l| l.next_roi);
        Ok(found)
    }
}

/// The body in every frame of a clip, with one shape; `step` is called after each fit.
pub fn fit_clip(
    fitter: &Fitter,
    people: &[PoseLandmarks],
    step: &mut dyn FnMut(),
) -> Result<Vec<BodyFit>, FitError> {
    let n = people.len();
    if n == 0 {
        return Err(FitError::input("clip", "no frames to fit"));
    }
    let count = SHAPE_FRAMES.min(n);
    let mut shapes = Vec::with_capacity(count);
    let mut first = None;
    for i in (0..count).map(|k| k * n / count) {
        let fit = fitter.fit(&people[i])?;
        shapes.push(fit.betas.clone());
        first.get_or_insert(fit);
        step();
    }
    let betas: Vec<f32> = (0..shapes[0].len())
        .map(|k| {
            let mut v: Vec<f32> = shapes.iter().map(|b| b[k]).collect();
            v.sort_by(f32::total_cmp);
            v[v.len() / 2]
        })
        .collect();
    let mut previous = first.expect("frame 0 is fitted first");
    let mut fits = Vec::with_capacity(n);
    for (i, person) in people.iter().enumerate() {
        let weight = if i == 0 { 0.0 } else { SMOOTHNESS };
        let anchor = Anchor { pose: &previous.pose, transl: previous.transl, weight };
        let fit = fitter.follow(person, &betas, &anchor)?;
        previous = fit.clone();
        fits.push(fit);
        step();
    }
    Ok(fits)
}

/// How many progress steps [`fit_clip`] takes for `frames` frames.
pub fn fit_clip_steps(frames: usize) -> usize {
    SHAPE_FRAMES.min(frames) + frames
}
