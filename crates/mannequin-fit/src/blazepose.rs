//! Where the 33 BlazePose landmarks sit on the default body: a joint of the skeleton for the
//! limbs, a surface vertex for the face, hands and feet. The face, hand and foot vertices were
//! chosen once on the default body's mean shape: the nose as the front-most vertex of the head's
//! midline; the eyes as the upper-lid vertex that MakeHuman's `eyeBlink` unit moves most; the
//! mouth corners as those `mouthSmile` moves most; the ears at the middle of the head's widest
//! band; heel and toe as the back- and front-most points of the foot; the thumb tip as the
//! hand's front-most point (palms face down, thumbs forward); index and pinky knuckles as the
//! back-of-hand vertices 3 cm either side of the finger roots. `tests` check each one.

use mannequin_body::smpl_joint::*;

/// What a landmark is tied to on the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    Joint(usize),
    Vertex(usize),
    /// Not used: the default head has no eyeball and its eyelid corners are not marked, so
    /// the eye's inner and outer points are left to the eye centre.
    Unmapped,
}

/// BlazePose's landmark names and their anchors, in the network's order.
pub const LANDMARKS: [(&str, Anchor); 33] = [
    ("nose", Anchor::Vertex(5054)),
    ("left_eye_inner", Anchor::Unmapped),
    ("left_eye", Anchor::Vertex(6786)),
    ("left_eye_outer", Anchor::Unmapped),
    ("right_eye_inner", Anchor::Unmapped),
    ("right_eye", Anchor::Vertex(2)),
    ("right_eye_outer", Anchor::Unmapped),
    ("left_ear", Anchor::Vertex(12106)),
    ("right_ear", Anchor::Vertex(5507)),
    ("mouth_left", Anchor::Vertex(7301)),
    ("mouth_right", Anchor::Vertex(560)),
    ("left_shoulder", Anchor::Joint(L_SHOULDER)),
    ("right_shoulder", Anchor::Joint(R_SHOULDER)),
    ("left_elbow", Anchor::Joint(L_ELBOW)),
    ("right_elbow", Anchor::Joint(R_ELBOW)),
    ("left_wrist", Anchor::Joint(L_WRIST)),
    ("right_wrist", Anchor::Joint(R_WRIST)),
    ("left_pinky", Anchor::Vertex(8962)),
    ("right_pinky", Anchor::Vertex(2294)),
    ("left_index", Anchor::Vertex(9918)),
    ("right_index", Anchor::Vertex(3250)),
    ("left_thumb", Anchor::Vertex(9445)),
    ("right_thumb", Anchor::Vertex(2777)),
    ("left_hip", Anchor::Joint(L_HIP)),
    ("right_hip", Anchor::Joint(R_HIP)),
    ("left_knee", Anchor::Joint(L_KNEE)),
    ("right_knee", Anchor::Joint(R_KNEE)),
    ("left_ankle", Anchor::Joint(L_ANKLE)),
    ("right_ankle", Anchor::Joint(R_ANKLE)),
    ("left_heel", Anchor::Vertex(12453)),
    ("right_heel", Anchor::Vertex(5856)),
    ("left_foot_index", Anchor::Vertex(11551)),
    ("right_foot_index", Anchor::Vertex(4933)),
];

/// The landmark on the other side of the body: the same name with left and right swapped
/// (itself for the nose).
pub fn mirror(i: usize) -> usize {
    let name = LANDMARKS[i].0;
    let other =
        if name.contains("left") { name.replace("left", "right") } else { name.replace("right", "left") };
    LANDMARKS.iter().position(|(n, _)| *n == other).unwrap_or(i)
}

/// The vertex count of the body the table's vertices index.
pub const DEFAULT_BODY_VERTICES: usize = 13380;

pub const LEFT_HIP: usize = 23;
pub const RIGHT_HIP: usize = 24;
pub const LEFT_SHOULDER: usize = 11;
pub const RIGHT_SHOULDER: usize = 12;

/// The skeleton drawn in overlays: pairs of landmarks.
pub const BONES: [(usize, usize); 18] = [
    (11, 12),
    (11, 13),
    (13, 15),
    (12, 14),
    (14, 16),
    (11, 23),
    (12, 24),
    (23, 24),
    (23, 25),
    (25, 27),
    (24, 26),
    (26, 28),
    (27, 29),
    (29, 31),
    (28, 30),
    (30, 32),
    (0, 2),
    (0, 5),
];

#[cfg(test)]
mod tests {
    use mannequin_body::BodyModel;

    use super::*;

    fn vertex(m: &BodyModel, name: &str) -> [f32; 3] {
        match LANDMARKS.iter().find(|(n, _)| *n == name).unwrap().1 {
            Anchor::Vertex(v) => m.v_template[v],
            other => panic!("{name} is {other:?}"),
        }
    }

    #[test]
    fn mirror_pairs_each_side_with_the_other() {
        for (i, &(a, _)) in LANDMARKS.iter().enumerate() {
            let j = mirror(i);
            assert_eq!(mirror(j), i);
            let b = LANDMARKS[j].0;
            match i {
                0 => assert_eq!(j, 0, "the nose is its own mirror"),
                _ => assert!(
                    a != b && a.replace("left", "right") == b || a.replace("right", "left") == b,
                    "{a} ↔ {b}"
                ),
            }
        }
    }

    #[test]
    fn left_and_right_vertices_mirror_each_other() {
        let m = BodyModel::default_body();
        for (name, anchor) in LANDMARKS {
            let (Some(stem), Anchor::Vertex(v)) = (name.strip_prefix("left_"), anchor) else { continue };
            let [x, y, z] = vertex(&m, &format!("right_{stem}"));
            let l = m.v_template[v];
            assert!(l[0] > 0.0, "{name} is on the subject's left (+X)");
            assert!((l[0] + x).abs() < 1e-4 && (l[1] - y).abs() < 1e-4 && (l[2] - z).abs() < 1e-4, "{name}");
        }
    }

    #[test]
    fn face_hand_and_foot_vertices_lie_where_their_names_say() {
        let m = BodyModel::default_body();
        let v = |n: &str| vertex(&m, n);
        let front_most = m.v_template.iter().filter(|p| p[1] > 0.35).map(|p| p[2]).fold(f32::MIN, f32::max);
        assert_eq!(v("nose")[2], front_most, "the nose is the head's front-most point");
        assert!(
            v("left_eye")[1] > v("nose")[1] && v("nose")[1] > v("mouth_left")[1],
            "eyes above nose above mouth"
        );
        assert!(v("left_ear")[0] > v("left_eye")[0] + 0.03 && v("left_ear")[2] < v("left_eye")[2] - 0.05);
        assert!(v("left_heel")[2] < 0.0 && v("left_foot_index")[2] > 0.15, "heel behind, toe in front");
        assert!(v("left_heel")[1] < -1.05 && v("left_foot_index")[1] < -1.05, "both at the sole");
        let wrist_x = 0.65;
        for n in ["left_thumb", "left_index", "left_pinky"] {
            assert!(v(n)[0] > wrist_x, "{n} is beyond the wrist");
        }
        assert!(v("left_thumb")[2] > v("left_index")[2] && v("left_index")[2] > v("left_pinky")[2]);
    }
}
