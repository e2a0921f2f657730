//! A motion preceded by a settling period: a garment modelled around the body at rest must drape
//! on a still body before the body moves, so half the settling holds the rest pose and the other
//! half eases from rest into the motion's first frame.

use mannequin_mesh::points;

use crate::{BodyError, BodyModel, Motion, ShapedBody, pose_frames};

/// Longest settling period (s): a garment hangs still within a second or two, and every second
/// costs a simulated frame per frame of the motion's rate.
pub const MAX_SETTLE_SECONDS: f32 = 10.0;

/// Most settling frames, whatever the motion's frame rate: ten seconds at 120 fps, the highest
/// rate motion capture records at.
pub const MAX_SETTLE_FRAMES: usize = 1200;

/// The body's pose schedule: `settle` frames (at least one) from rest into the motion's first
/// frame, then the motion. Frame 0 is the rest pose.
#[derive(Debug, Clone)]
pub struct Settling {
    /// Frames before the motion's first.
    pub settle: usize,
    poses: Vec<f32>,
    trans: Vec<f32>,
    joints: usize,
}

impl Settling {
    pub fn new(model: &BodyModel, motion: &Motion, settle_seconds: f32) -> Result<Self, BodyError> {
        let joints = model.num_joints();
        let settle = Self::settle_frames(settle_seconds, motion.fps)?;
        let poses = motion.poses_for(model)?;
        let hold = settle / 2;
        let mut all_poses = Vec::with_capacity((settle + motion.num_frames()) * 3 * joints);
        let mut all_trans = Vec::new();
        for k in 0..settle {
            // Smoothstep, so the body starts and arrives without a jolt.
            let t = if k < hold { 0.0 } else { (k - hold) as f32 / (settle - hold) as f32 };
            let w = t * t * (3.0 - 2.0 * t);
            all_poses.extend(poses[..3 * joints].iter().map(|p| w * p));
            all_trans.extend(motion.trans[..3].iter().map(|t| w * t));
        }
        all_poses.extend_from_slice(&poses);
        all_trans.extend_from_slice(&motion.trans);
        Ok(Self { settle, poses: all_poses, trans: all_trans, joints })
    }

    /// Frames of settling for `settle_seconds` at `fps` (at least one), refused past
    /// [`MAX_SETTLE_SECONDS`] or [`MAX_SETTLE_FRAMES`]: known before anything is allocated.
    pub fn settle_frames(settle_seconds: f32, fps: f32) -> Result<usize, BodyError> {
        if !(0.0..=MAX_SETTLE_SECONDS).contains(&settle_seconds) {
            return Err(BodyError::input(
                "settle",
                format!("{settle_seconds} s; expected 0 to {MAX_SETTLE_SECONDS} seconds"),
            ));
        }
        let frames = (f64::from(settle_seconds) * f64::from(fps)).round();
        if !frames.is_finite() || frames > MAX_SETTLE_FRAMES as f64 {
            return Err(BodyError::input(
                "settle",
                format!(
                    "{settle_seconds} s at {fps} fps is {frames} frames; expected at most {MAX_SETTLE_FRAMES}"
                ),
            ));
        }
        Ok((frames as usize).max(1))
    }

    /// Frames in all, settling included.
    pub fn len(&self) -> usize {
        self.trans.len() / 3
    }

    pub fn is_empty(&self) -> bool {
        self.trans.is_empty()
    }

    /// The `shaped` body's vertices at every frame, posed in one pass.
    pub fn body_frames(
        &self,
        model: &BodyModel,
        shaped: &ShapedBody,
    ) -> Result<Vec<Vec<[f32; 3]>>, BodyError> {
        let posed = pose_frames(model, shaped, &self.poses, &self.trans)?;
        Ok((0..self.len()).map(|k| points(posed.frame_vertices(k))).collect())
    }

    /// Frame `k`'s axis-angle pose (3 per joint) and translation.
    pub fn pose(&self, k: usize) -> (&[f32], &[f32]) {
        (&self.poses[3 * self.joints * k..3 * self.joints * (k + 1)], &self.trans[3 * k..3 * k + 3])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_rest_then_eases_into_the_first_frame() {
        let model = BodyModel::default_body_lod1();
        let motion = Motion::walk_cycle(0.5, 30.0);
        let s = Settling::new(&model, &motion, 0.4).unwrap();
        assert_eq!((s.settle, s.len()), (12, 12 + motion.num_frames()));
        let first = motion.poses_for(&model).unwrap();
        assert!(s.pose(0).0.iter().chain(s.pose(5).0).all(|&p| p == 0.0), "the first half holds rest");
        // Smoothstep at t = 1/6 gives 2/27 of the first frame.
        let w = 2.0 / 27.0;
        for (p, q) in s.pose(7).0.iter().zip(&first) {
            assert!((p - w * q).abs() <= 1e-6 * q.abs().max(1.0), "{p} vs {}", w * q);
        }
        assert_eq!(s.pose(12).0, &first[..3 * model.num_joints()], "the motion follows unchanged");
    }

    /// Issue 42: `--settle inf` grew to 24 GB; a settling period past the limits, or not a
    /// number, is refused before anything is allocated.
    #[test]
    fn settling_past_its_limits_is_refused() {
        let model = BodyModel::default_body_lod1();
        let motion = Motion::walk_cycle(0.2, 30.0);
        for bad in [f32::INFINITY, f32::NAN, -1.0, 1e5, MAX_SETTLE_SECONDS + 0.1] {
            let e = Settling::new(&model, &motion, bad).unwrap_err().to_string();
            assert!(e.starts_with("settle: ") && e.contains("expected 0 to 10 seconds"), "{e}");
        }
        let e = Settling::settle_frames(10.0, 1e6).unwrap_err().to_string();
        assert!(e.contains("expected at most 1200"), "{e}");
        assert_eq!(Settling::settle_frames(0.0, 30.0).unwrap(), 1);
        assert_eq!(Settling::settle_frames(MAX_SETTLE_SECONDS, 120.0).unwrap(), MAX_SETTLE_FRAMES);
    }
}
