//! A few named SMPL poses (24 joints × axis-angle) for previews, tests and synthetic captures.
//! Axes are SMPL's: Y up, the body faces +Z, the subject's left is +X. So a positive turn about
//! +Z lifts the left arm, and a negative turn about +X swings a thigh forward.

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4};

use crate::error::BodyError;

/// Names accepted by [`named_pose`].
pub const POSE_NAMES: [&str; 6] = ["t-pose", "a-pose", "arms-raised", "squat", "walk", "arms-crossed"];

fn set(pose: &mut [f32; 72], j: usize, r: [f32; 3]) {
    pose[3 * j..3 * j + 3].copy_from_slice(&r);
}

/// The 72-value SMPL pose called `name` (see [`POSE_NAMES`]).
pub fn named_pose(name: &str) -> Result<[f32; 72], BodyError> {
    use crate::smpl_joint::*;
    let mut p = [0.0f32; 72];
    match name {
        "t-pose" => {}
        "a-pose" => {
            set(&mut p, L_SHOULDER, [0.0, 0.0, -FRAC_PI_4]);
            set(&mut p, R_SHOULDER, [0.0, 0.0, FRAC_PI_4]);
        }
        "arms-raised" => {
            set(&mut p, L_COLLAR, [0.0, 0.0, 0.3]);
            set(&mut p, R_COLLAR, [0.0, 0.0, -0.3]);
            set(&mut p, L_SHOULDER, [0.0, 0.0, FRAC_PI_2 - 0.3]);
            set(&mut p, R_SHOULDER, [0.0, 0.0, -(FRAC_PI_2 - 0.3)]);
        }
        "squat" => {
            // Thighs flexed and turned out (a negative turn about +Y swings the flexed left
            // thigh to +X), knees bent to 80°: as deep as the body's skinning allows. Feet
            // together and knees past 90°, as before, the thighs sank into the belly and the
            // calves (123–156 crossing triangle pairs on the synthetic subjects); here only the
            // creases behind the knees and in the groin fold into themselves (17–27, the
            // arms' reach included).
            set(&mut p, L_HIP, [-1.2, 0.5, 0.0]);
            set(&mut p, R_HIP, [-1.2, -0.5, 0.0]);
            set(&mut p, L_KNEE, [1.4, 0.0, 0.0]);
            set(&mut p, R_KNEE, [1.4, 0.0, 0.0]);
            set(&mut p, L_ANKLE, [-0.25, 0.0, 0.0]);
            set(&mut p, R_ANKLE, [-0.25, 0.0, 0.0]);
            // Arms reach forward for balance: a negative turn about +Y swings the left arm to +Z.
            set(&mut p, L_SHOULDER, [0.0, -1.2, -0.3]);
            set(&mut p, R_SHOULDER, [0.0, 1.2, 0.3]);
        }
        "walk" => {
            // Left leg forward, right leg back; arms swing opposite.
            set(&mut p, L_HIP, [-0.5, 0.0, 0.0]);
            set(&mut p, L_KNEE, [0.25, 0.0, 0.0]);
            set(&mut p, R_HIP, [0.35, 0.0, 0.0]);
            set(&mut p, R_KNEE, [0.5, 0.0, 0.0]);
            set(&mut p, L_SHOULDER, [0.0, 0.0, -1.25]);
            set(&mut p, R_SHOULDER, [0.0, 0.0, 1.25]);
            set(&mut p, L_ELBOW, [0.0, 0.0, 0.0]);
        }
        "arms-crossed" => {
            // The left forearm crosses above and in front of the right one. Mirrored, the two
            // forearms met at one height and passed through each other (99–155 crossing pairs).
            set(&mut p, L_SHOULDER, [0.0, -1.45, -0.45]);
            set(&mut p, R_SHOULDER, [0.0, 0.85, 0.55]);
            set(&mut p, L_ELBOW, [0.0, -1.5, 0.0]);
            set(&mut p, R_ELBOW, [0.0, 1.5, 0.0]);
        }
        other => {
            return Err(BodyError::input(
                "pose name",
                format!("unknown '{other}'; expected one of {}", POSE_NAMES.join(", ")),
            ));
        }
    }
    Ok(p)
}
