//! The body's parts as the segmentation sees them: each vertex of the fitted body belongs to the
//! part its skinning weights bind it to most, and a part allows only some classes (a hand shows
//! skin, a shin skin or the lower garment, the torso either garment). The body's projection thus
//! carries a prior into every frame, and the parts' cores seed the colour models.

use mannequin_body::BodyModel;
use mannequin_body::smpl_joint as j;

use super::class::{CLASSES, Class, Scores};

/// A part of the body, by the joints that move it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// Head and the back of the neck.
    Head,
    /// The face: the head's front below the brow, skin unless hair falls over it.
    Face,
    /// The crown, hair unless the person is bald.
    Crown,
    /// Neck and collar bones.
    Neck,
    /// The upper chest, up to the neckline.
    Chest,
    /// From below the chest to the waist.
    Belly,
    Pelvis,
    UpperArm,
    Forearm,
    Hand,
    /// The top of the thighs, where a loose top's hem hangs over the trousers.
    Hip,
    Thigh,
    Shin,
    Foot,
}

impl Part {
    /// Log prior of each class on this part: 0 where the class is expected, [`UNLIKELY`] where it
    /// happens (long hair over the chest, trousers down to the shoes), [`NEVER`] elsewhere.
    pub fn prior(self) -> Scores {
        use Class::*;
        let (expected, unlikely): (&[Class], &[Class]) = match self {
            Part::Head => (&[Skin, Hair], &[]),
            Part::Face => (&[Skin], &[Hair]),
            Part::Crown => (&[Hair], &[Skin]),
            Part::Neck => (&[Skin, Upper], &[Hair]),
            // A neckline, or a top slipping off the shoulder, shows the upper chest's skin.
            Part::Chest => (&[Upper, Skin], &[Hair]),
            Part::Belly => (&[Upper], &[Lower, Skin, Hair]),
            Part::Pelvis => (&[Upper, Lower], &[Skin]),
            Part::UpperArm => (&[Upper, Skin], &[Hair]),
            Part::Forearm => (&[Skin, Upper], &[]),
            Part::Hand => (&[Skin], &[Upper]),
            Part::Hip => (&[Lower, Upper], &[Skin]),
            Part::Thigh => (&[Lower, Skin], &[Upper]),
            Part::Shin => (&[Lower, Skin], &[Shoes]),
            // Trouser hems fall over the shoes.
            Part::Foot => (&[Shoes, Lower], &[Skin]),
        };
        let mut prior = [NEVER; CLASSES];
        expected.iter().for_each(|c| prior[c.index()] = 0.0);
        unlikely.iter().for_each(|c| prior[c.index()] = UNLIKELY);
        prior
    }

    /// The class this part's colours seed, where nearly every person shows it there.
    pub fn seed(self) -> Option<Class> {
        match self {
            Part::Face | Part::Hand => Some(Class::Skin),
            Part::Crown => Some(Class::Hair),
            Part::Belly => Some(Class::Upper),
            Part::Thigh => Some(Class::Lower),
            Part::Foot => Some(Class::Shoes),
            _ => None,
        }
    }
}

/// The share of the thigh, from the hip joint down to the knee, that counts as the hip.
const HIP_SHARE: f32 = 0.3;

/// Log prior of a class a part rarely shows.
pub const UNLIKELY: f32 = -3.0;
/// Log prior of a class a part does not show; finite, so strong colour evidence may still win.
pub const NEVER: f32 = -10.0;

/// Each vertex's part on `model`, from its skinning weights and its place on the rest body (the
/// face and crown are cut out of the head by height and depth about the head joint).
pub fn vertex_parts(model: &BodyModel, rest: &[[f32; 3]], joints: &[[f32; 3]]) -> Vec<Part> {
    let n = model.num_joints();
    let head = joints[j::HEAD];
    let (hip, knee) = (joints[j::L_HIP][1], joints[j::L_KNEE][1]);
    let hip_line = hip - HIP_SHARE * (hip - knee);
    rest.iter()
        .enumerate()
        .map(|(v, p)| {
            let w = &model.weights()[v * n..(v + 1) * n];
            let mut strongest = (0..n).max_by(|&a, &b| w[a].total_cmp(&w[b])).unwrap_or(0);
            // A finger or jaw joint of a richer model (SMPL-X) counts as the SMPL joint it hangs from.
            while strongest > j::R_HAND {
                strongest = model.parents()[strongest].unwrap_or(j::HEAD);
            }
            match strongest {
                j::HEAD if p[1] > head[1] + 0.09 => Part::Crown,
                j::HEAD if p[2] > head[2] + 0.03 && p[1] < head[1] + 0.04 => Part::Face,
                j::HEAD => Part::Head,
                j::NECK | j::L_COLLAR | j::R_COLLAR => Part::Neck,
                j::SPINE3 => Part::Chest,
                j::SPINE2 | j::SPINE1 => Part::Belly,
                j::PELVIS => Part::Pelvis,
                j::L_SHOULDER | j::R_SHOULDER => Part::UpperArm,
                j::L_ELBOW | j::R_ELBOW => Part::Forearm,
                j::L_WRIST | j::R_WRIST | j::L_HAND | j::R_HAND => Part::Hand,
                j::L_HIP | j::R_HIP if p[1] > hip_line => Part::Hip,
                j::L_HIP | j::R_HIP => Part::Thigh,
                j::L_KNEE | j::R_KNEE => Part::Shin,
                j::L_ANKLE | j::R_ANKLE | j::L_FOOT | j::R_FOOT => Part::Foot,
                _ => Part::Head,
            }
        })
        .collect()
}
