//! Limbs kept out of each other and out of the torso (the issue's "no self-interpenetration of
//! limbs"). Each bone that can pass through another part is a capsule around the segment between
//! its two joints; a pair of capsules that are not joined costs how deep they overlap. The radii
//! are thinner than the default body's limbs, so arms resting on the torso or thighs touching
//! cost nothing: only a limb driven through another part does. A depth-ambiguous view (an arm in
//! front of or behind the torso, seen from the side) is where the fit needs this.

use glam::Vec3;
use mannequin_body::smpl_joint::*;

/// A bone's capsule: the segment between two joints, and its radius in metres.
struct Capsule {
    from: usize,
    to: usize,
    radius: f32,
}

const fn capsule(from: usize, to: usize, radius: f32) -> Capsule {
    Capsule { from, to, radius }
}

const TORSO: usize = 0;
const HEAD: usize = 1;
const L_UPPER_ARM: usize = 2;
const R_UPPER_ARM: usize = 3;
const L_FOREARM: usize = 4;
const R_FOREARM: usize = 5;
const L_THIGH: usize = 6;
const R_THIGH: usize = 7;
const L_SHIN: usize = 8;
const R_SHIN: usize = 9;

const CAPSULES: [Capsule; 10] = [
    capsule(PELVIS, NECK, 0.09),
    capsule(NECK, mannequin_body::smpl_joint::HEAD, 0.07),
    capsule(L_SHOULDER, L_ELBOW, 0.035),
    capsule(R_SHOULDER, R_ELBOW, 0.035),
    capsule(L_ELBOW, L_WRIST, 0.03),
    capsule(R_ELBOW, R_WRIST, 0.03),
    capsule(L_HIP, L_KNEE, 0.05),
    capsule(R_HIP, R_KNEE, 0.05),
    capsule(L_KNEE, L_ANKLE, 0.035),
    capsule(R_KNEE, R_ANKLE, 0.035),
];

/// The pairs that must not overlap: none shares a joint, and none is joined through a short
/// chain the radii would make touch at rest (the upper arms and thighs meet the torso there).
const PAIRS: [(usize, usize); 16] = [
    (L_FOREARM, TORSO),
    (R_FOREARM, TORSO),
    (L_FOREARM, HEAD),
    (R_FOREARM, HEAD),
    (L_FOREARM, R_FOREARM),
    (L_FOREARM, L_THIGH),
    (R_FOREARM, R_THIGH),
    (L_FOREARM, R_THIGH),
    (R_FOREARM, L_THIGH),
    (L_UPPER_ARM, R_FOREARM),
    (R_UPPER_ARM, L_FOREARM),
    (L_THIGH, R_THIGH),
    (L_SHIN, R_SHIN),
    (L_THIGH, R_SHIN),
    (R_THIGH, L_SHIN),
    (L_UPPER_ARM, HEAD),
];

/// The closest distance between segments [p0, p1] and [q0, q1].
pub fn segment_distance(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> f32 {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    let eps = 1e-12;
    let (s, t) = if a <= eps && e <= eps {
        (0.0, 0.0)
    } else if a <= eps {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= eps {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > eps { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    ((p0 + d1 * s) - (q0 + d2 * t)).length()
}

/// One residual per pair: `weight` per metre of overlap, zero apart.
pub fn residuals(joints: &[Vec3], weight: f64, out: &mut Vec<f64>) {
    for (a, b) in PAIRS {
        let (a, b) = (&CAPSULES[a], &CAPSULES[b]);
        let d = segment_distance(joints[a.from], joints[a.to], joints[b.from], joints[b.to]);
        out.push(weight * (a.radius + b.radius - d).max(0.0) as f64);
    }
}

#[cfg(test)]
mod tests {
    use mannequin_body::BodyModel;

    use super::*;

    #[test]
    fn segment_distance_matches_dense_sampling() {
        let mut rng = mannequin_io::rng::SplitMix64::new(7);
        let mut point = || {
            Vec3::new(rng.range(-0.5, 0.5) as f32, rng.range(-0.5, 0.5) as f32, rng.range(-0.5, 0.5) as f32)
        };
        for case in 0..200 {
            let (p0, p1, q0) = (point(), point(), point());
            // Every tenth case parallel, to reach the degenerate branch.
            let q1 = if case % 10 == 0 { q0 + (p1 - p0) * 0.7 } else { point() };
            let steps = 400;
            let sampled = (0..=steps)
                .flat_map(|i| (0..=steps).map(move |j| (i as f32 / steps as f32, j as f32 / steps as f32)))
                .map(|(s, t)| (p0.lerp(p1, s) - q0.lerp(q1, t)).length())
                .fold(f32::INFINITY, f32::min);
            let exact = segment_distance(p0, p1, q0, q1);
            assert!(exact <= sampled + 1e-6 && sampled - exact < 4e-3, "case {case}: {exact} vs {sampled}");
        }
    }

    fn joints(model: &BodyModel, pose: &[f32]) -> Vec<Vec3> {
        let posed = mannequin_body::forward(model, &[], pose, &[0.0; 3]).unwrap();
        posed.joints.chunks_exact(3).map(Vec3::from_slice).collect()
    }

    #[test]
    fn named_poses_cost_nothing_and_an_arm_through_the_torso_does() {
        let model = BodyModel::default_body();
        for name in mannequin_body::POSE_NAMES {
            let pose = mannequin_body::named_pose(name).unwrap();
            let mut r = Vec::new();
            residuals(&joints(&model, &pose), 1.0, &mut r);
            assert!(r.iter().all(|&v| v == 0.0), "{name}: {r:?}");
        }
        // The left shoulder turned so the upper arm points across the chest, and the elbow bent
        // a further half turn: the forearm comes back through the torso.
        let mut pose = vec![0.0f32; 72];
        pose[3 * L_SHOULDER + 1] = -2.4;
        pose[3 * L_ELBOW + 1] = -2.6;
        let mut r = Vec::new();
        residuals(&joints(&model, &pose), 1.0, &mut r);
        assert!(r[0] > 0.02, "the left forearm overlaps the torso by {} m", r[0]);
    }
}
