//! The body cut down to what a landmark fit reads: its joints and a few surface vertices, each
//! linear in β (T̄ + Σ β_k S_k and J = 𝒥 T), posed by forward kinematics and linear blend
//! skinning. Posing it costs microseconds, so the fit can afford finite-difference Jacobians.

use glam::Vec3;
use mannequin_body::BodyModel;
use mannequin_body::kinematics::{skinning_transforms, world_transforms};
use mannequin_body::lbs::regress_joints;
use mannequin_body::rodrigues::rodrigues;

/// One tracked vertex: rest position, shape directions and skinning weights.
#[derive(Debug, Clone)]
struct TrackedVertex {
    rest: Vec3,
    shape_dirs: Vec<Vec3>,
    weights: Vec<(usize, f32)>,
}

/// Joints and tracked vertices of one body model, ready to pose.
#[derive(Debug, Clone)]
pub struct LandmarkBody {
    parents: Vec<Option<usize>>,
    joints: Vec<Vec3>,
    joint_dirs: Vec<Vec<Vec3>>,
    vertices: Vec<TrackedVertex>,
}

/// A posed landmark body: joints and tracked vertices in world space.
#[derive(Debug, Clone)]
pub struct PosedLandmarks {
    pub joints: Vec<Vec3>,
    pub vertices: Vec<Vec3>,
}

impl LandmarkBody {
    /// Tracks `vertices` (indices into the model's mesh) besides every joint.
    pub fn new(model: &BodyModel, vertices: &[usize]) -> Self {
        let n = model.num_shape_coeffs();
        let len = 3 * model.num_vertices();
        let template: Vec<f32> = model.v_template.iter().flatten().copied().collect();
        let dir = |k: usize| &model.shapedirs()[k * len..(k + 1) * len];
        let joint_dirs = (0..n).map(|k| regress_joints(model, dir(k))).collect();
        let tracked = vertices
            .iter()
            .map(|&v| TrackedVertex {
                rest: Vec3::from(model.v_template[v]),
                shape_dirs: (0..n).map(|k| Vec3::from_slice(&dir(k)[3 * v..3 * v + 3])).collect(),
                weights: model.skin().row(v).collect(),
            })
            .collect();
        Self {
            parents: model.parents().to_vec(),
            joints: regress_joints(model, &template),
            joint_dirs,
            vertices: tracked,
        }
    }

    pub fn num_betas(&self) -> usize {
        self.joint_dirs.len()
    }

    /// Rest joints for shape `betas`.
    pub fn rest_joints(&self, betas: &[f32]) -> Vec<Vec3> {
        let mut j = self.joints.clone();
        for (dirs, &b) in self.joint_dirs.iter().zip(betas) {
            j.iter_mut().zip(dirs).for_each(|(j, d)| *j += b * *d);
        }
        j
    }

    /// Joints and tracked vertices for shape `betas`, pose (24 × axis-angle) and translation.
    pub fn pose(&self, betas: &[f32], pose: &[f32], transl: Vec3) -> PosedLandmarks {
        let rest = self.rest_joints(betas);
        let rotations: Vec<_> = pose.chunks_exact(3).map(|r| rodrigues([r[0], r[1], r[2]])).collect();
        let world = world_transforms(&self.parents, &rotations, &rest);
        let skin = skinning_transforms(&world, &rest);
        let joints = world.iter().map(|g| Vec3::from(g.translation) + transl).collect();
        let vertices = self
            .vertices
            .iter()
            .map(|v| {
                let rest = v.shape_dirs.iter().zip(betas).fold(v.rest, |p, (d, &b)| p + b * *d);
                v.weights.iter().fold(transl, |acc, &(k, w)| acc + w * skin[k].transform_point3(rest))
            })
            .collect();
        PosedLandmarks { joints, vertices }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn landmark_body_matches_the_full_forward_pass() {
        let model = BodyModel::default_body_lod1();
        let picked = [0, 17, 400, model.num_vertices() - 1];
        let body = LandmarkBody::new(&model, &picked);
        let betas: Vec<f32> = (0..model.num_shape_coeffs()).map(|k| 0.4 * ((k as f32) * 1.7).sin()).collect();
        let pose = mannequin_body::named_pose("walk").unwrap();
        let transl = [0.1, -0.2, 2.0];
        let full = mannequin_body::forward(&model, &betas, &pose, &transl).unwrap();
        let posed = body.pose(&betas, &pose, Vec3::from(transl));
        for (i, &v) in picked.iter().enumerate() {
            let want = Vec3::from_slice(&full.vertices[3 * v..3 * v + 3]);
            assert!((posed.vertices[i] - want).length() < 1e-5, "vertex {v}");
        }
        for (k, j) in posed.joints.iter().enumerate() {
            assert!((*j - Vec3::from_slice(&full.joints[3 * k..3 * k + 3])).length() < 1e-5, "joint {k}");
        }
    }
}
