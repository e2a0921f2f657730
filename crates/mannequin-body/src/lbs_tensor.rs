//! The differentiable forward pass in Burn tensors, batched over frames, so fitting and training
//! get gradients with respect to shape, pose, translation and the template itself. It computes the
//! same function as [`crate::lbs`] (thesis §SMPL), in tensor form.

use burn::tensor::{DType, Device, Tensor, TensorData};

use crate::model::BodyModel;

/// Keeps θ = ‖r‖ differentiable at the zero rotation, as smplx does.
const ANGLE_EPS: f64 = 1e-8;

/// A model's constant arrays on one device, in one float type.
#[derive(Debug, Clone)]
pub struct BodyTensors {
    /// [V, 3]
    pub v_template: Tensor<2>,
    /// [K, 3V]
    pub shapedirs: Tensor<2>,
    /// [P, 3V], absent when the model has no pose correctives.
    pub posedirs: Option<Tensor<2>>,
    /// [J, V]
    pub j_regressor: Tensor<2>,
    /// [V, J]
    pub weights: Tensor<2>,
    pub parents: Vec<Option<usize>>,
}

/// Outputs of [`forward_tensors`]; N frames, V vertices, J joints.
#[derive(Debug, Clone)]
pub struct PosedTensors {
    /// [N, V, 3]
    pub vertices: Tensor<3>,
    /// [N, J, 3], world positions (translation included).
    pub joints: Tensor<3>,
    /// [N, J, 3, 3] world rotations of the joints.
    pub rotations: Tensor<4>,
}

fn tensor2(values: Vec<f32>, rows: usize, cols: usize, device: &Device, dtype: DType) -> Tensor<2> {
    Tensor::from_data(TensorData::new(values, [rows, cols]), (device, dtype))
}

impl BodyTensors {
    /// Uploads the model's arrays to `device` as `dtype` (F32, or F64 for gradient checks).
    pub fn new(model: &BodyModel, device: &Device, dtype: DType) -> Self {
        let v = model.num_vertices();
        let j = model.num_joints();
        let k = model.num_shape_coeffs();
        let p = model.num_pose_features();
        Self {
            v_template: tensor2(model.v_template.iter().flatten().copied().collect(), v, 3, device, dtype),
            shapedirs: tensor2(model.shapedirs().to_vec(), k, 3 * v, device, dtype),
            posedirs: (p > 0).then(|| tensor2(model.posedirs().to_vec(), p, 3 * v, device, dtype)),
            j_regressor: tensor2(model.j_regressor().to_dense(v), j, v, device, dtype),
            weights: tensor2(model.weights().to_vec(), v, j, device, dtype),
            parents: model.parents().to_vec(),
        }
    }
}

/// Rotation matrices [M, 3, 3] of axis-angle vectors [M, 3]:
/// R = cos θ I + sin θ [k]× + (1 − cos θ) k kᵀ.
pub fn rodrigues_tensor(r: Tensor<2>) -> Tensor<3> {
    let m = r.dims()[0];
    let theta = (r.clone().square().sum_dim(1) + ANGLE_EPS * ANGLE_EPS).sqrt();
    let k = r / theta.clone();
    let (c, s) = (theta.clone().cos(), theta.sin());
    let one_c = c.clone().neg() + 1.0;
    let kx = k.clone().narrow(1, 0, 1);
    let ky = k.clone().narrow(1, 1, 1);
    let kz = k.narrow(1, 2, 1);
    let outer = |a: &Tensor<2>, b: &Tensor<2>| one_c.clone() * a.clone() * b.clone();
    let entries = vec![
        c.clone() + outer(&kx, &kx),
        outer(&kx, &ky) - s.clone() * kz.clone(),
        outer(&kx, &kz) + s.clone() * ky.clone(),
        outer(&ky, &kx) + s.clone() * kz.clone(),
        c.clone() + outer(&ky, &ky),
        outer(&ky, &kz) - s.clone() * kx.clone(),
        outer(&kz, &kx) - s.clone() * ky.clone(),
        outer(&kz, &ky) + s * kx,
        c + outer(&kz, &kz),
    ];
    Tensor::cat(entries, 1).reshape([m, 3, 3])
}

/// Poses N frames: `template` [V, 3] (the model's, or one with learned offsets), `shape` [N, K],
/// `pose` [N, 3J] axis-angle, `transl` [N, 3].
pub fn forward_tensors(
    bt: &BodyTensors,
    template: Tensor<2>,
    shape: Tensor<2>,
    pose: Tensor<2>,
    transl: Tensor<2>,
) -> PosedTensors {
    let [n, _] = shape.dims();
    let [v, j] = bt.weights.dims();

    // T(β) = T̄ + S β, and J(β) = 𝒥 T(β).
    let v_shaped: Tensor<3> =
        (template.reshape([1, 3 * v]) + shape.matmul(bt.shapedirs.clone())).reshape([n, v, 3]);
    let joints_rest = bt.j_regressor.clone().unsqueeze_dim::<3>(0).expand([n, j, v]).matmul(v_shaped.clone());
    let rig = Rig { weights: &bt.weights, posedirs: bt.posedirs.as_ref(), parents: &bt.parents };
    skin_tensors(&rig, v_shaped, joints_rest, pose, transl)
}

/// What skinning needs besides the shaped mesh: weights [V, J], optional pose correctives
/// [9(J−1), 3V], and the joint tree.
#[derive(Debug, Clone, Copy)]
pub struct Rig<'a> {
    pub weights: &'a Tensor<2>,
    pub posedirs: Option<&'a Tensor<2>>,
    pub parents: &'a [Option<usize>],
}

/// Poses shaped vertices [N, V, 3] about rest joints [N, J, 3] (Eq. 1 with pose correctives):
/// the second half of [`forward_tensors`], for callers whose joints do not come from the
/// regressor (an avatar keeps the body's joints under its clothing offsets, iHuman learns them).
pub fn skin_tensors(
    rig: &Rig,
    v_shaped: Tensor<3>,
    joints_rest: Tensor<3>,
    pose: Tensor<2>,
    transl: Tensor<2>,
) -> PosedTensors {
    let [n, v, _] = v_shaped.dims();
    let j = rig.parents.len();
    let device = v_shaped.device();
    let dtype = v_shaped.dtype();
    let v_shaped = v_shaped.reshape([n, 3 * v]);

    let rot = rodrigues_tensor(pose.reshape([n * j, 3])).reshape([n, j, 3, 3]);

    // T_P = T(β) + P (R(θ) − I), over joints 1..J.
    let v_posed = match rig.posedirs {
        Some(pd) => {
            let eye: Tensor<2> = Tensor::<2>::eye(3, &device).cast(dtype);
            let feat = rot.clone().narrow(1, 1, j - 1) - eye.reshape([1, 1, 3, 3]);
            v_shaped + feat.reshape([n, 9 * (j - 1)]).matmul(pd.clone())
        }
        None => v_shaped,
    };

    // Forward kinematics along the tree: G_k = G_parent · [R_k | J_k − J_parent].
    let joint = |k: usize| joints_rest.clone().narrow(1, k, 1).reshape([n, 3, 1]);
    let local_rot = |k: usize| rot.clone().narrow(1, k, 1).reshape([n, 3, 3]);
    let mut g_rot: Vec<Tensor<3>> = Vec::with_capacity(j);
    let mut g_t: Vec<Tensor<3>> = Vec::with_capacity(j);
    for (k, parent) in rig.parents.iter().enumerate() {
        match parent {
            None => {
                g_rot.push(local_rot(k));
                g_t.push(joint(k));
            }
            Some(p) => {
                let offset = joint(k) - joint(*p);
                g_t.push(g_rot[*p].clone().matmul(offset) + g_t[*p].clone());
                g_rot.push(g_rot[*p].clone().matmul(local_rot(k)));
            }
        }
    }
    let world_rot: Tensor<4> = Tensor::stack(g_rot, 1); // [N, J, 3, 3]
    let world_t: Tensor<4> = Tensor::stack(g_t, 1); // [N, J, 3, 1]

    // Skinning transforms A_k = [G_rot | G_t − G_rot J_k], blended per vertex by the weights.
    let rest = joints_rest.clone().reshape([n, j, 3, 1]);
    let a_t = world_t.clone() - world_rot.clone().matmul(rest);
    let a = Tensor::cat(vec![world_rot.clone().reshape([n, j, 9]), a_t.reshape([n, j, 3])], 2); // [N, J, 12]
    let blended = rig.weights.clone().unsqueeze_dim::<3>(0).expand([n, v, j]).matmul(a); // [N, V, 12]
    let b_rot: Tensor<4> = blended.clone().narrow(2, 0, 9).reshape([n, v, 3, 3]);
    let b_t: Tensor<3> = blended.narrow(2, 9, 3);
    let vp: Tensor<4> = v_posed.reshape([n, v, 3, 1]);
    let offset = transl.reshape([n, 1, 3]);
    let vertices = b_rot.matmul(vp).reshape([n, v, 3]) + b_t + offset.clone();
    let joints = world_t.reshape([n, j, 3]) + offset;
    PosedTensors { vertices, joints, rotations: world_rot }
}
