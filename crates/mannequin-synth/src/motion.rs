//! Pose sequences of the synthetic capture: the subject turning in place in an A-pose with small
//! natural motion (as in PeopleSnapshot), and out-of-distribution test motions.

use std::f32::consts::TAU;

use mannequin_body::smpl_joint::*;
use mannequin_body::{BodyError, Motion, named_pose};

use mannequin_io::rng::SplitMix64;

/// SMPL joints that sway a little while the subject holds the A-pose.
const SWAY_JOINTS: [usize; 9] =
    [SPINE1, SPINE2, SPINE3, NECK, HEAD, L_SHOULDER, R_SHOULDER, L_ELBOW, R_ELBOW];

/// `frames` poses (72 each) turning `turns` times about the vertical axis, starting facing
/// the camera (+Z), with per-joint sinusoidal sway of a few degrees.
pub fn turning_a_pose(frames: usize, turns: f32, rng: &mut SplitMix64) -> Result<Vec<f32>, BodyError> {
    let base = named_pose("a-pose")?;
    let sway: Vec<(usize, usize, f32, f32, f32)> = SWAY_JOINTS
        .iter()
        .flat_map(|&j| (0..3).map(move |c| (j, c)))
        .map(|(j, c)| {
            (j, c, rng.range(0.01, 0.05) as f32, rng.range(0.5, 2.0) as f32, rng.range(0.0, 6.3) as f32)
        })
        .collect();
    let mut poses = Vec::with_capacity(frames * 72);
    for f in 0..frames {
        let t = f as f32 / frames as f32;
        let mut p = base;
        p[1] = TAU * turns * t;
        for &(j, c, amp, freq, phase) in &sway {
            p[3 * j + c] += amp * (TAU * freq * t * turns + phase).sin();
        }
        poses.extend_from_slice(&p);
    }
    Ok(poses)
}

/// The frame rate of the out-of-distribution motions: `frames_each` frames of each take
/// about a second, a stride of the walk.
pub fn novel_pose_fps(frames_each: usize) -> f32 {
    frames_each as f32 * 0.9
}

/// Linear blend of two poses in axis-angle, per joint (fine for the moderate angles used).
fn blend(a: &[f32; 72], b: &[f32; 72], t: f32) -> [f32; 72] {
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
}

/// The out-of-distribution motions: walking, raising the arms, squatting, crossing the arms,
/// `frames_each` frames of each, facing the camera with a small random turn. Returns the motion
/// names and the poses.
pub fn novel_poses(
    frames_each: usize,
    rng: &mut SplitMix64,
) -> Result<(Vec<&'static str>, Vec<f32>), BodyError> {
    let a = named_pose("a-pose")?;
    let walk = Motion::walk_cycle(1.0 / 0.9, novel_pose_fps(frames_each));
    let mut names = Vec::new();
    let mut poses = Vec::new();
    for name in ["walk", "arms-raised", "squat", "arms-crossed"] {
        let target = named_pose(name)?;
        let yaw = rng.range(-0.5, 0.5) as f32;
        for f in 0..frames_each {
            let t = (f + 1) as f32 / frames_each as f32;
            let mut p = if name == "walk" {
                std::array::from_fn(|i| walk.poses[f * 72 + i])
            } else {
                blend(&a, &target, t)
            };
            p[1] += yaw;
            poses.extend_from_slice(&p);
            names.push(name);
        }
    }
    Ok((names, poses))
}
