//! A procedural walk cycle in SMPL layout, so the README's demo and the tests have motion
//! without a licensed AMASS download. Sinusoidal hip, knee, shoulder and elbow swings at a
//! typical cadence (about 1 stride per second) with forward travel.

use std::f32::consts::TAU;

use crate::motion::Motion;

const STRIDE_HZ: f32 = 0.9;
const SPEED_M_PER_S: f32 = 1.2;

impl Motion {
    /// `seconds` of walking at `fps`, moving along +Z (the way the body faces).
    pub fn walk_cycle(seconds: f32, fps: f32) -> Motion {
        let frames = ((seconds * fps).round() as usize).max(1);
        let mut poses = vec![0.0f32; frames * 72];
        let mut trans = vec![0.0f32; frames * 3];
        for f in 0..frames {
            let t = f as f32 / fps;
            let phase = TAU * STRIDE_HZ * t;
            let (s, c) = phase.sin_cos();
            let p = &mut poses[f * 72..(f + 1) * 72];
            let mut set = |j: usize, r: [f32; 3]| p[3 * j..3 * j + 3].copy_from_slice(&r);
            // Thighs swing opposite each other; knees bend while the leg swings forward.
            set(1, [-0.45 * s, 0.0, 0.0]);
            set(2, [0.45 * s, 0.0, 0.0]);
            set(4, [0.35 * (1.0 + c).max(0.0) * s.max(0.0) + 0.1, 0.0, 0.0]);
            set(5, [0.35 * (1.0 + c).max(0.0) * (-s).max(0.0) + 0.1, 0.0, 0.0]);
            // Arms hang down and swing against the legs.
            set(16, [0.0, 0.35 * s, -1.2]);
            set(17, [0.0, 0.35 * s, 1.2]);
            set(18, [0.0, -0.3, 0.0]);
            set(19, [0.0, 0.3, 0.0]);
            set(3, [0.05, 0.08 * s, 0.0]);
            trans[3 * f + 1] = 0.02 * (2.0 * phase).cos();
            trans[3 * f + 2] = SPEED_M_PER_S * t;
        }
        Motion {
            source: "procedural walk".into(),
            poses,
            joints: 24,
            trans,
            betas: Vec::new(),
            fps,
            gender: None,
        }
    }
}
