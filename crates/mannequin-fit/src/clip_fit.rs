//! A clip to one person's landmarks and body per frame. The person is found in the first frame
//! and followed as MediaPipe follows them (the next crop from this frame's auxiliary points),
//! found again where the landmarker loses them (the one overlapping where they last were).
//!
//! Seen from the side or behind, the landmarker sometimes reads the person as their mirror (left
//! and right swapped, depth turned over); the clip's turn decides which frames those are
//! ([`resolve_mirrors`]). Then the body is fitted to the whole clip, with one shape:
//! 1. a starting shape, the median of independent fits on a few frames spread over the clip;
//! 2. a forward pass: each frame's pose starts from the previous frame's and is pulled toward
//!    it, and its orientation toward where the clip's landmarks say it faces;
//! 3. the shape refitted to many frames' residuals at once, their poses held;
//! 4. a backward pass with that shape, each frame pulled toward both its neighbours.

use glam::{DQuat, DVec3};
use mannequin_body::rodrigues::{axis_angle_quat, quat_axis_angle};
use mannequin_data::Image;

use crate::body_fit::{Anchor, BodyFit, Fitter, FramePose, rotation_gap};
use crate::crop::RotatedRect;
use crate::error::FitError;
use crate::person_models::{Person, PersonModels, body_box, pick_person};
use crate::pose_landmarker::PoseLandmarks;
use crate::ssd_detector::box_iou;

/// Frames fitted independently to find the clip's one shape.
const SHAPE_FRAMES: usize = 8;
/// How hard each frame's pose is pulled toward the previous frame's, per radian (the landmark
/// term counts 1 per 1 % of the person's crop).
const SMOOTHNESS: f64 = 2.0;
/// Frames, spread over the clip, whose residuals the clip's one shape is fitted to.
const SHAPE_REFIT_FRAMES: usize = 24;
/// Passes of the joint refinement after the first, forward one, alternately backward and
/// forward: each frame is refitted pulled toward the mean of its two neighbours (Gauss–Seidel
/// on the clip's smoothness), so later frames inform earlier ones too.
const SWEEPS: usize = 1;
/// How hard each frame's orientation is pulled toward where the clip's landmarks say it faces,
/// per radian.
const FACING: f64 = 3.0;
/// Frames either side whose facings vote on each frame's.
const FACING_WINDOW: usize = 5;

/// What reading a frame as its landmarker's mirror costs, in radians of turn between frames:
/// a few frames' mirrors are undone, a long run of them is left as read.
const MIRROR_COST: f64 = 0.25;

/// Undoes the landmarker's mirror readings (`PoseLandmarks::mirrored`) where the clip's turn
/// says they are mirrors: each frame is read as given or mirrored, whichever sequence turns the
/// body least from frame to frame, mirrors counted at [`MIRROR_COST`] each (a two-state
/// Viterbi). Returns the frames that were mirrored.
pub fn resolve_mirrors(fitter: &Fitter, people: &mut [PoseLandmarks]) -> Vec<usize> {
    let n = people.len();
    let facings: Vec<[Option<DQuat>; 2]> =
        people.iter().map(|p| [fitter.facing(p), fitter.facing(&p.mirrored())]).collect();
    let turn = |a: Option<DQuat>, b: Option<DQuat>| match (a, b) {
        (Some(a), Some(b)) => rotation_gap(a, b).length(),
        _ => 0.0,
    };
    let mut cost = [0.0, MIRROR_COST];
    let mut back = vec![[0usize; 2]; n];
    for i in 1..n {
        let mut next = [0.0; 2];
        for s in 0..2 {
            let (best, from) = (0..2)
                .map(|t| (cost[t] + turn(facings[i - 1][t], facings[i][s]), t))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .expect("two states");
            next[s] = best + s as f64 * MIRROR_COST;
            back[i][s] = from;
        }
        cost = next;
    }
    let mut state = if cost[1] < cost[0] { 1 } else { 0 };
    let mut mirrored = Vec::new();
    for i in (0..n).rev() {
        if state == 1 {
            people[i] = people[i].mirrored();
            mirrored.push(i);
        }
        state = back[i][state];
    }
    mirrored.reverse();
    mirrored
}

/// Each frame's facing, voted on by its neighbours: the one of the window's facings nearest to
/// all the others (a medoid). A landmarker that turns the person round for a few frames, or a
/// side view it reads the wrong way, is outvoted; a steady turn keeps its own frame's facing.
fn voted_facings(facings: &[Option<DQuat>]) -> Vec<Option<DQuat>> {
    (0..facings.len())
        .map(|i| {
            let window =
                &facings[i.saturating_sub(FACING_WINDOW)..(i + FACING_WINDOW + 1).min(facings.len())];
            let spread =
                |q: DQuat| window.iter().flatten().map(|&o| rotation_gap(q, o).length()).sum::<f64>();
            window.iter().flatten().copied().min_by(|&a, &b| spread(a).total_cmp(&spread(b)))
        })
        .collect()
}

/// Follows one person from frame to frame: in the crop their last landmarks point to while the
/// landmarker still sees them there; where it loses them, the person found again whose body
/// overlaps the box they last had most. The first frame anyone is found in picks the person:
/// the one `--person` names, else the only or clearly largest one.
pub struct Tracker<'a> {
    models: &'a PersonModels,
    /// The person asked for, counting from 0, largest first, in the first frame with anyone.
    wanted: Option<usize>,
    /// Where the last frame's landmarks put the person next.
    next_roi: Option<RotatedRect>,
    /// The box the person's landmarks spanned in the last frame they were found in.
    last_box: Option<[f32; 4]>,
}

/// A person found again overlaps the box they were last seen in by at least this IoU.
const MIN_FOLLOW_IOU: f32 = 0.1;

impl<'a> Tracker<'a> {
    /// A tracker that picks the person unasked.
    pub fn new(models: &'a PersonModels) -> Self {
        Self::resume(models, None, None, false)
    }

    /// A tracker that goes on where one stopped: `last` is the person as last found, and
    /// `in_last_frame` whether that was in the frame just before.
    pub fn resume(
        models: &'a PersonModels,
        wanted: Option<usize>,
        last: Option<&PoseLandmarks>,
        in_last_frame: bool,
    ) -> Self {
        Self {
            models,
            wanted,
            next_roi: last.filter(|_| in_last_frame).map(|l| l.next_roi),
            last_box: last.map(body_box),
        }
    }

    /// The person's landmarks in the next frame; None when they are not there.
    pub fn next(&mut self, image: &Image) -> Result<Option<PoseLandmarks>, FitError> {
        let followed = match self.next_roi {
            Some(roi) => self.models.follow(image, roi)?,
            None => None,
        };
        let found = match followed {
            Some(l) => Some(l),
            None => match self.find_again(&self.models.people(image, self.wanted)?)? {
                Some(person) => Some(self.models.refine(image, person.landmarks.clone())?),
                None => None,
            },
        };
        self.next_roi = found.as_ref().map(|l| l.next_roi);
        if let Some(l) = &found {
            self.last_box = Some(body_box(l));
        }
        Ok(found)
    }

    /// Which of `everyone` is the person: the first time, the one asked for (an error when
    /// there is no such person, or when two are too alike in size to pick between unasked);
    /// after, the one overlapping their last box most, else the one asked for, if any.
    fn find_again<'p>(&self, everyone: &'p [Person]) -> Result<Option<&'p Person>, FitError> {
        if everyone.is_empty() {
            return Ok(None);
        }
        let Some(last) = self.last_box else { return pick_person(everyone, self.wanted).map(Some) };
        let overlap = |p: &Person| box_iou(&body_box(&p.landmarks), &last);
        let nearest = everyone.iter().max_by(|a, b| overlap(a).total_cmp(&overlap(b)));
        Ok(match nearest.filter(|p| overlap(p) >= MIN_FOLLOW_IOU) {
            Some(p) => Some(p),
            None => match self.wanted {
                Some(n) => everyone.get(n),
                None => Some(pick_person(everyone, None)?),
            },
        })
    }
}

/// How far a clip's fit has got: the passes done, the clip's shape and each frame's pose and
/// placement after the last of them. A job stores it between passes to resume.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClipProgress {
    pub passes: usize,
    pub betas: Vec<f32>,
    pub frames: Vec<FramePose>,
}

/// The passes of a clip's fit (see the module's list), one at a time.
pub struct ClipFit<'a> {
    fitter: &'a Fitter,
    people: &'a [PoseLandmarks],
    facings: Vec<Option<(DQuat, f64)>>,
    pub progress: ClipProgress,
}

impl<'a> ClipFit<'a> {
    /// Passes in all: the forward pass (with the starting shape), the shape, the sweeps.
    pub const PASSES: usize = 2 + SWEEPS;

    /// A fit of `people` (one per frame) that starts after `progress` (default: from scratch).
    pub fn new(
        fitter: &'a Fitter,
        people: &'a [PoseLandmarks],
        progress: ClipProgress,
    ) -> Result<Self, FitError> {
        let n = people.len();
        if n == 0 {
            return Err(FitError::input("clip", "no frames to fit"));
        }
        if progress.passes > 0 && progress.frames.len() != n {
            return Err(FitError::input(
                "clip",
                format!("a fit of {} frames cannot go on with {n}", progress.frames.len()),
            ));
        }
        let facings = voted_facings(&people.iter().map(|p| fitter.facing(p)).collect::<Vec<_>>())
            .into_iter()
            .map(|q| q.map(|q| (q, FACING)))
            .collect();
        Ok(Self { fitter, people, facings, progress })
    }

    /// Progress steps per pass: frames fitted (or one for the shape).
    pub fn steps(frames: usize) -> usize {
        SHAPE_FRAMES.min(frames) + (1 + SWEEPS) * frames + 1
    }

    /// Progress steps the passes done so far took.
    pub fn steps_done(&self) -> usize {
        let n = self.people.len();
        let passes = self.progress.passes;
        let forward = if passes > 0 { SHAPE_FRAMES.min(n) + n } else { 0 };
        forward + usize::from(passes > 1) + passes.saturating_sub(2) * n
    }

    /// Runs the next pass, calling `step` after each fit; false when all are done.
    pub fn next_pass(&mut self, step: &mut dyn FnMut()) -> Result<bool, FitError> {
        match self.progress.passes {
            0 => self.forward(step)?,
            1 => self.refit_shape(step)?,
            p if p < Self::PASSES => self.sweep(p - 2, step)?,
            _ => return Ok(false),
        }
        self.progress.passes += 1;
        Ok(true)
    }

    /// Every frame's fit as it stands.
    pub fn fits(&self) -> Result<Vec<BodyFit>, FitError> {
        let ClipProgress { betas, frames, .. } = &self.progress;
        self.people.iter().zip(frames).map(|(person, frame)| self.fitter.at(person, betas, frame)).collect()
    }

    /// A starting shape, the median of independent fits spread over the clip; then each frame
    /// from the previous one.
    fn forward(&mut self, step: &mut dyn FnMut()) -> Result<(), FitError> {
        let (fitter, people) = (self.fitter, self.people);
        let n = people.len();
        let count = SHAPE_FRAMES.min(n);
        let mut shapes = Vec::with_capacity(count);
        let mut previous = None;
        for i in (0..count).map(|k| k * n / count) {
            let fit = fitter.fit(&people[i])?;
            shapes.push(fit.betas.clone());
            previous.get_or_insert(fit.frame_pose());
            step();
        }
        let betas: Vec<f32> = (0..shapes[0].len())
            .map(|k| {
                let mut v: Vec<f32> = shapes.iter().map(|b| b[k]).collect();
                v.sort_by(f32::total_cmp);
                v[v.len() / 2]
            })
            .collect();
        let mut previous = previous.expect("frame 0 is fitted first");
        let mut frames = Vec::with_capacity(n);
        for (i, person) in people.iter().enumerate() {
            let weight = if i == 0 { 0.0 } else { SMOOTHNESS };
            let anchor = Anchor { at: &previous, weight, facing: self.facings[i] };
            previous = fitter.follow(person, &betas, &anchor)?.frame_pose();
            frames.push(previous.clone());
            step();
        }
        self.progress = ClipProgress { passes: self.progress.passes, betas, frames };
        Ok(())
    }

    /// The shape refitted to frames spread over the clip at once, their poses held.
    fn refit_shape(&mut self, step: &mut dyn FnMut()) -> Result<(), FitError> {
        let n = self.people.len();
        let count = SHAPE_REFIT_FRAMES.min(n);
        let held: Vec<_> =
            (0..count).map(|k| k * n / count).map(|i| (&self.people[i], &self.progress.frames[i])).collect();
        self.progress.betas = self.fitter.fit_shape(&held, &self.progress.betas)?;
        step();
        Ok(())
    }

    /// Each frame refitted pulled toward its neighbours; backward on even sweeps.
    fn sweep(&mut self, sweep: usize, step: &mut dyn FnMut()) -> Result<(), FitError> {
        let n = self.people.len();
        let order: Box<dyn Iterator<Item = usize>> =
            if sweep.is_multiple_of(2) { Box::new((0..n).rev()) } else { Box::new(0..n) };
        for i in order {
            let frames = &self.progress.frames;
            let neighbours: Vec<&FramePose> = [i.checked_sub(1), Some(i + 1).filter(|&j| j < n)]
                .into_iter()
                .flatten()
                .map(|j| &frames[j])
                .collect();
            let target = between(&frames[i], &neighbours);
            let weight = SMOOTHNESS * (neighbours.len() as f64).sqrt();
            let anchor = Anchor { at: &target, weight, facing: self.facings[i] };
            self.progress.frames[i] =
                self.fitter.follow(&self.people[i], &self.progress.betas, &anchor)?.frame_pose();
            step();
        }
        Ok(())
    }
}

/// The body in every frame of a clip, with one shape, all passes at once; `step` is called
/// after each fit.
pub fn fit_clip(
    fitter: &Fitter,
    people: &[PoseLandmarks],
    step: &mut dyn FnMut(),
) -> Result<Vec<BodyFit>, FitError> {
    let mut clip = ClipFit::new(fitter, people, ClipProgress::default())?;
    while clip.next_pass(step)? {}
    clip.fits()
}

/// The pose and placement midway between a frame's neighbours: the mean of their joint
/// rotations and translations, and of their orientations taken about the frame's own.
fn between(own: &FramePose, neighbours: &[&FramePose]) -> FramePose {
    let k = neighbours.len() as f32;
    let mut pose: Vec<f32> =
        (0..own.pose.len()).map(|j| neighbours.iter().map(|f| f.pose[j]).sum::<f32>() / k).collect();
    let q = |f: &FramePose| axis_angle_quat([f.pose[0], f.pose[1], f.pose[2]]).as_dquat();
    let gap = neighbours.iter().map(|f| rotation_gap(q(own), q(f))).sum::<DVec3>() / k as f64;
    let turned = axis_angle_quat(gap.as_vec3().to_array()).as_dquat() * q(own);
    pose[..3].copy_from_slice(&quat_axis_angle(turned.as_quat()));
    let transl = std::array::from_fn(|c| neighbours.iter().map(|f| f.transl[c]).sum::<f32>() / k);
    FramePose { pose, transl }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;
    use mannequin_body::BodyModel;
    use mannequin_body::smpl_joint::{L_HIP, L_SHOULDER, R_HIP, R_SHOULDER};

    use super::*;
    use crate::blazepose::{LEFT_HIP, LEFT_SHOULDER, RIGHT_HIP, RIGHT_SHOULDER};
    use crate::crop::RotatedRect;
    use crate::pose_landmarker::NUM_LANDMARKS;

    /// World landmarks of the rest body's hips and shoulders turned `yaw` about the vertical, in
    /// the camera's axes (y down, z away); nothing else.
    fn turned_torso(model: &BodyModel, yaw: f32) -> PoseLandmarks {
        let joints = mannequin_body::forward(model, &[], &[0.0; 72], &[0.0; 3]).unwrap().joints;
        let turn = glam::Quat::from_rotation_y(yaw);
        let at = |j: usize| {
            let p = turn * Vec3::from_slice(&joints[3 * j..3 * j + 3]);
            [p.x, -p.y, -p.z]
        };
        let mut world = vec![[0.0; 3]; NUM_LANDMARKS];
        let mut visibility = vec![0.0; NUM_LANDMARKS];
        for (i, j) in
            [(LEFT_HIP, L_HIP), (RIGHT_HIP, R_HIP), (LEFT_SHOULDER, L_SHOULDER), (RIGHT_SHOULDER, R_SHOULDER)]
        {
            world[i] = at(j);
            visibility[i] = 1.0;
        }
        let square = RotatedRect { cx: 0.0, cy: 0.0, width: 1.0, height: 1.0, rotation: 0.0 };
        PoseLandmarks {
            roi: square,
            flag: 1.0,
            points: vec![[0.0; 3]; NUM_LANDMARKS],
            visibility,
            presence: vec![1.0; NUM_LANDMARKS],
            world,
            next_roi: square,
            mask: Vec::new(),
        }
    }

    #[test]
    fn a_few_mirrored_frames_of_a_turn_are_found_and_undone() {
        let model = BodyModel::default_body();
        let fitter = Fitter::new(&model, 64, 64, 64.0).unwrap();
        // Half a turn in 40 frames. A mirror turns the body from ψ to π − ψ, so it shows most
        // facing the camera or away (frames 3, 4 and 36) and less at three quarters (28–30); in
        // profile (frame 20) it is the same reading.
        let truth: Vec<PoseLandmarks> = (0..40).map(|i| turned_torso(&model, 0.08 * i as f32)).collect();
        let mut people = truth.clone();
        let misread = [3, 4, 28, 29, 30, 36];
        for &i in &misread {
            people[i] = people[i].mirrored();
        }
        assert_eq!(resolve_mirrors(&fitter, &mut people), misread);
        for (got, want) in people.iter().zip(&truth) {
            for (a, b) in got.world.iter().zip(&want.world) {
                assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6));
            }
        }
        // Read as given, a steady turn is left alone.
        assert!(resolve_mirrors(&fitter, &mut truth.clone()).is_empty());
    }

    #[test]
    fn the_rotation_gap_is_the_short_way_round() {
        let from = DQuat::from_rotation_y(3.0);
        let to = DQuat::from_rotation_y(-3.0);
        // 3 rad one way and −3 the other are 2π − 6 ≈ 0.283 rad apart, through half a turn.
        let gap = rotation_gap(from, to);
        assert!((gap - DVec3::new(0.0, std::f64::consts::TAU - 6.0, 0.0)).length() < 1e-9, "{gap}");
        let q = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 2.0).normalize(), 0.7);
        assert!((rotation_gap(DQuat::IDENTITY, q) - DVec3::new(1.0, 2.0, 2.0) / 3.0 * 0.7).length() < 1e-9);
    }
}
