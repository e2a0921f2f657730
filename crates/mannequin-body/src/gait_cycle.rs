//! Procedural gaits in SMPL layout, so the README's demo and the tests have motion without a
//! licensed AMASS download: sinusoidal hip, knee, shoulder and elbow swings with forward travel.
//! A walk (about 1 stride per second) and a jog (faster, with higher knees and bent elbows),
//! which the cloth must follow at twice the walk's speed.

use std::f32::consts::TAU;

use crate::motion::Motion;

/// One gait's amplitudes (radians, metres) and pace.
#[derive(Debug, Clone, Copy)]
pub struct Gait {
    /// Strides (two steps) per second.
    pub stride_hz: f32,
    /// Forward speed, m/s.
    pub speed: f32,
    /// Thigh swing about the hip's X axis, each way.
    pub thigh_swing: f32,
    /// Knee bend while the leg swings forward, on top of `knee_rest`.
    pub knee_lift: f32,
    pub knee_rest: f32,
    /// Arm swing about the shoulder's Y axis, each way (the arms hang 1.2 rad below the T-pose).
    pub arm_swing: f32,
    /// Elbow bend, forward.
    pub elbow_bend: f32,
    /// Forward lean of the lower spine, and its twist with the stride.
    pub lean: f32,
    pub twist: f32,
    /// The pelvis's rise and fall, twice a stride.
    pub bounce: f32,
}

impl Gait {
    pub const WALK: Gait = Gait {
        stride_hz: 0.9,
        speed: 1.2,
        thigh_swing: 0.45,
        knee_lift: 0.35,
        knee_rest: 0.1,
        arm_swing: 0.35,
        elbow_bend: 0.3,
        lean: 0.05,
        twist: 0.08,
        bounce: 0.02,
    };

    /// About 165 steps a minute at 9 km/h, elbows bent to about 70°.
    pub const JOG: Gait = Gait {
        stride_hz: 1.4,
        speed: 2.5,
        thigh_swing: 0.55,
        knee_lift: 0.6,
        knee_rest: 0.2,
        // A wider swing folds the armpits into themselves (50 % more crossing pairs of the
        // body's own triangles than the walk's at 0.55); the bent elbows swing the hands wider.
        arm_swing: 0.35,
        elbow_bend: 1.2,
        lean: 0.12,
        twist: 0.12,
        bounce: 0.04,
    };
}

impl Motion {
    /// `seconds` of walking at `fps`, moving along +Z (the way the body faces).
    pub fn walk_cycle(seconds: f32, fps: f32) -> Motion {
        Motion::gait_cycle(&Gait::WALK, "procedural walk", seconds, fps)
    }

    /// `seconds` of jogging at `fps`, moving along +Z.
    pub fn jog_cycle(seconds: f32, fps: f32) -> Motion {
        Motion::gait_cycle(&Gait::JOG, "procedural jog", seconds, fps)
    }

    /// `seconds` of `gait` at `fps`, moving along +Z; `source` names it in the file.
    pub fn gait_cycle(gait: &Gait, source: &str, seconds: f32, fps: f32) -> Motion {
        let frames = ((seconds * fps).round() as usize).max(1);
        let mut poses = vec![0.0f32; frames * 72];
        let mut trans = vec![0.0f32; frames * 3];
        for f in 0..frames {
            let t = f as f32 / fps;
            let phase = TAU * gait.stride_hz * t;
            let (s, c) = phase.sin_cos();
            let p = &mut poses[f * 72..(f + 1) * 72];
            let mut set = |j: usize, r: [f32; 3]| p[3 * j..3 * j + 3].copy_from_slice(&r);
            // Thighs swing opposite each other; knees bend while the leg swings forward.
            set(1, [-gait.thigh_swing * s, 0.0, 0.0]);
            set(2, [gait.thigh_swing * s, 0.0, 0.0]);
            set(4, [gait.knee_lift * (1.0 + c).max(0.0) * s.max(0.0) + gait.knee_rest, 0.0, 0.0]);
            set(5, [gait.knee_lift * (1.0 + c).max(0.0) * (-s).max(0.0) + gait.knee_rest, 0.0, 0.0]);
            // Arms hang down and swing against the legs.
            set(16, [0.0, gait.arm_swing * s, -1.2]);
            set(17, [0.0, gait.arm_swing * s, 1.2]);
            set(18, [0.0, -gait.elbow_bend, 0.0]);
            set(19, [0.0, gait.elbow_bend, 0.0]);
            set(3, [gait.lean, gait.twist * s, 0.0]);
            trans[3 * f + 1] = gait.bounce * (2.0 * phase).cos();
            trans[3 * f + 2] = gait.speed * t;
        }
        Motion { source: source.into(), poses, joints: 24, trans, betas: Vec::new(), fps, gender: None }
    }
}
