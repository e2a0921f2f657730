//! Forward kinematics on a joint tree (thesis §SMPL, Eq. for G_k): each joint's world transform
//! is its parent's times its own rotation about its rest position.

use glam::{Affine3A, Mat3, Vec3, Vec3A};

/// World transforms of every joint, given local rotations and rest joint positions.
/// Parents must come before children.
pub fn world_transforms(
    parents: &[Option<usize>],
    rotations: &[Mat3],
    rest_joints: &[Vec3],
) -> Vec<Affine3A> {
    let mut world: Vec<Affine3A> = Vec::with_capacity(parents.len());
    for (k, parent) in parents.iter().enumerate() {
        let local_offset = match parent {
            Some(p) => rest_joints[k] - rest_joints[*p],
            None => rest_joints[k],
        };
        let local = Affine3A::from_mat3_translation(rotations[k], local_offset);
        world.push(match parent {
            Some(p) => world[*p] * local,
            None => local,
        });
    }
    world
}

/// Skinning transforms: world transforms with the rest position removed, so that
/// `A_k · x_rest` moves a rest-pose point rigidly with joint k.
pub fn skinning_transforms(world: &[Affine3A], rest_joints: &[Vec3]) -> Vec<Affine3A> {
    world
        .iter()
        .zip(rest_joints)
        .map(|(g, &j)| {
            let mut a = *g;
            a.translation -= g.matrix3 * Vec3A::from(j);
            a
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bent_elbow_moves_the_wrist_around_the_elbow() {
        // shoulder at origin, elbow at x=1, wrist at x=2; bend the elbow 90° about z.
        let parents = [None, Some(0), Some(1)];
        let rest = [Vec3::ZERO, Vec3::X, Vec3::new(2.0, 0.0, 0.0)];
        let rots = [Mat3::IDENTITY, Mat3::from_rotation_z(std::f32::consts::FRAC_PI_2), Mat3::IDENTITY];
        let world = world_transforms(&parents, &rots, &rest);
        let wrist = world[2].translation;
        assert!((Vec3::from(wrist) - Vec3::new(1.0, 1.0, 0.0)).length() < 1e-6);
        let skin = skinning_transforms(&world, &rest);
        // A point on the forearm rest position (1.5, 0, 0) follows the elbow.
        let p = skin[1].transform_point3(Vec3::new(1.5, 0.0, 0.0));
        assert!((p - Vec3::new(1.0, 0.5, 0.0)).length() < 1e-6);
    }
}
