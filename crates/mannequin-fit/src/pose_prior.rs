//! The pose prior that stands in for the thesis's discriminator (§2.2.2, Eqs. 2.16–2.17). The
//! discriminator learns from a corpus of real poses, which this project cannot download; what
//! it checks — "constraints of the joint rotation matrix" — is written down here instead, from
//! anatomy: each joint's axis-angle components stay inside a range of motion (knees and elbows
//! are hinges that bend one way; shoulders swing far, spines and necks little), and every joint
//! is pulled gently toward a relaxed stance (arms down, elbows a little bent), so that what the
//! image does not show — an arm out of the picture — stays plausible. A learned prior would
//! plug in as another residual block beside these.

use mannequin_body::smpl_joint::*;

/// Range of motion per SMPL joint: (min, max) radians for the x, y and z components of its
/// parent-relative axis-angle, in SMPL's axes (Y up, facing +Z, subject's left at +X). Knee
/// flexion is +x; left-elbow flexion −y and right-elbow +y (the forearm swings forward).
pub fn range_of_motion(joint: usize) -> [(f32, f32); 3] {
    const SPINE_ROM: [(f32, f32); 3] = [(-0.4, 0.6), (-0.35, 0.35), (-0.35, 0.35)];
    const NECK_ROM: [(f32, f32); 3] = [(-0.6, 0.8), (-0.8, 0.8), (-0.5, 0.5)];
    const COLLAR_ROM: [(f32, f32); 3] = [(-0.3, 0.3), (-0.4, 0.4), (-0.4, 0.4)];
    const SHOULDER_ROM: [(f32, f32); 3] = [(-1.6, 1.6), (-1.8, 1.8), (-1.7, 1.7)];
    const WRIST_ROM: [(f32, f32); 3] = [(-1.2, 1.2), (-1.0, 1.0), (-0.6, 0.6)];
    const ANKLE_ROM: [(f32, f32); 3] = [(-0.8, 0.6), (-0.4, 0.4), (-0.4, 0.4)];
    const TOES_ROM: [(f32, f32); 3] = [(-0.5, 0.5), (-0.2, 0.2), (-0.2, 0.2)];
    const HAND_ROM: [(f32, f32); 3] = [(-0.4, 0.4), (-0.4, 0.4), (-0.4, 0.4)];
    const KNEE_ROM: [(f32, f32); 3] = [(-0.05, 2.6), (-0.15, 0.15), (-0.15, 0.15)];
    match joint {
        L_HIP => [(-2.3, 0.5), (-0.7, 0.7), (-0.4, 1.0)],
        R_HIP => [(-2.3, 0.5), (-0.7, 0.7), (-1.0, 0.4)],
        L_KNEE | R_KNEE => KNEE_ROM,
        L_ELBOW => [(-0.3, 0.3), (-2.6, 0.05), (-0.15, 0.15)],
        R_ELBOW => [(-0.3, 0.3), (-0.05, 2.6), (-0.15, 0.15)],
        SPINE1 | SPINE2 | SPINE3 => SPINE_ROM,
        NECK | HEAD => NECK_ROM,
        L_COLLAR | R_COLLAR => COLLAR_ROM,
        L_SHOULDER | R_SHOULDER => SHOULDER_ROM,
        L_WRIST | R_WRIST => WRIST_ROM,
        L_ANKLE | R_ANKLE => ANKLE_ROM,
        L_FOOT | R_FOOT => TOES_ROM,
        L_HAND | R_HAND => HAND_ROM,
        _ => [(-std::f32::consts::PI, std::f32::consts::PI); 3],
    }
}

/// Shoulders turned down by this much (radians) about z in the relaxed stance.
const ARMS_DOWN: f64 = 1.2;
const ELBOWS_BENT: f64 = 0.25;

/// The relaxed stance the prior pulls toward, as a body pose (joints 1..24 × 3): arms hanging
/// about 20° out from the body, elbows slightly bent. Fits start from it too.
pub fn relaxed_pose() -> Vec<f64> {
    let mut p = vec![0.0; 69];
    let mut set = |joint: usize, axis: usize, v: f64| p[3 * (joint - 1) + axis] = v;
    set(L_SHOULDER, 2, -ARMS_DOWN);
    set(R_SHOULDER, 2, ARMS_DOWN);
    set(L_ELBOW, 1, -ELBOWS_BENT);
    set(R_ELBOW, 1, ELBOWS_BENT);
    p
}

/// How strongly joint `j` is pulled toward rest, relative to the others: joints the landmarks
/// see poorly (spine segments, toes, hands) more, the limbs' big joints less.
pub fn rest_weight(joint: usize) -> f32 {
    match joint {
        SPINE1 | SPINE2 | SPINE3 | L_COLLAR | R_COLLAR => 2.0,
        L_FOOT | R_FOOT | L_HAND | R_HAND => 4.0,
        NECK => 1.5,
        _ => 1.0,
    }
}

/// Residuals of the prior for a body pose (joints 1..24 × 3): how far each component leaves its
/// range, times `limit`, then each component's distance from `relaxed` (see [`relaxed_pose`])
/// times `rest` · [`rest_weight`].
pub fn residuals(body_pose: &[f64], relaxed: &[f64], limit: f64, rest: f64, out: &mut Vec<f64>) {
    for (k, (r, q)) in body_pose.chunks_exact(3).zip(relaxed.chunks_exact(3)).enumerate() {
        let joint = k + 1;
        let rom = range_of_motion(joint);
        for c in 0..3 {
            let (lo, hi, v) = (rom[c].0 as f64, rom[c].1 as f64, r[c]);
            out.push(limit * ((lo - v).max(0.0) + (v - hi).max(0.0)));
            out.push(rest * rest_weight(joint) as f64 * (v - q[c]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_named_poses_keep_inside_the_ranges() {
        // The project's own poses are plausible by construction; the prior must not fight them.
        for name in ["a-pose", "walk", "squat", "arms-crossed"] {
            let pose = mannequin_body::named_pose(name).unwrap();
            let body: Vec<f64> = pose[3..].iter().map(|&v| v as f64).collect();
            let mut r = Vec::new();
            residuals(&body, &relaxed_pose(), 1.0, 0.0, &mut r);
            let worst = r.iter().step_by(2).fold(0.0f64, |a, &b| a.max(b));
            assert!(worst < 1e-6, "{name} leaves a range by {worst}");
        }
    }

    #[test]
    fn the_relaxed_stance_is_inside_the_ranges_and_costs_nothing() {
        let mut r = Vec::new();
        residuals(&relaxed_pose(), &relaxed_pose(), 1.0, 1.0, &mut r);
        assert!(r.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn a_knee_bent_backwards_is_penalised() {
        let mut body = vec![0.0; 69];
        body[3 * (L_KNEE - 1)] = -0.5;
        let mut r = Vec::new();
        residuals(&body, &relaxed_pose(), 1.0, 0.0, &mut r);
        let knee = 2 * 3 * (L_KNEE - 1);
        assert!((r[knee] - 0.45).abs() < 1e-6, "{}", r[knee]);
    }
}
