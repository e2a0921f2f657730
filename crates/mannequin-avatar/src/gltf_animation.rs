//! The avatar on its glTF skeleton ([`crate::export::skinned_mesh`]): the bind pose, and a motion
//! as the skeleton's animation.

use mannequin_body::{Motion, skeletal_animation};
use mannequin_mesh::gltf::SkeletalAnimation;

use crate::avatar::{Avatar, Posed};
use crate::error::AvatarError;

impl Avatar {
    /// The avatar at its canonical pose (zero rotations, no translation): the glTF bind pose.
    pub fn canonical_pose(&self) -> Result<Posed, AvatarError> {
        self.pose(&vec![0.0; 3 * self.canonical.num_joints()], [0.0; 3])
    }

    /// `motion` as an animation of the avatar's glTF skeleton.
    pub fn animation(&self, motion: &Motion) -> Result<SkeletalAnimation, AvatarError> {
        let j = self.canonical.num_joints();
        let poses = motion.poses_for_joints(j)?;
        Ok(skeletal_animation(j, &poses, &motion.trans, motion.fps)?)
    }
}
