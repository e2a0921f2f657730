//! The plain fast forward pass (no autodiff) for animation and export: shape blend shapes,
//! joint regression, pose correctives as one matrix product over all frames, forward kinematics
//! and linear blend skinning (thesis §SMPL, Eqs. for T_P(β, θ) and W(·)).

use faer::{Accum, MatMut, MatRef, Par};
use glam::{Affine3A, Mat3, Mat3A, Vec3, Vec3A};
use mannequin_io::limits::MAX_BETA;
use rayon::prelude::*;

use crate::error::BodyError;
use crate::kinematics::{skinning_transforms, world_transforms};
use crate::model::BodyModel;
use crate::rodrigues::rodrigues;

/// The rest body for one shape: T̄ + B_S(β) and its regressed joints J(β).
#[derive(Debug, Clone)]
pub struct ShapedBody {
    /// 3V values, xyz per vertex.
    pub vertices: Vec<f32>,
    pub joints: Vec<Vec3>,
}

/// A posed clip: per frame, vertices, joints and world transforms.
#[derive(Debug, Clone)]
pub struct PosedFrames {
    pub num_frames: usize,
    /// F × V × 3.
    pub vertices: Vec<f32>,
    /// F × J × 3, translated like the vertices.
    pub joints: Vec<f32>,
    /// F × J world transforms of the joints, translation included.
    pub transforms: Vec<Affine3A>,
}

impl PosedFrames {
    pub fn frame_vertices(&self, f: usize) -> &[f32] {
        let n = self.vertices.len() / self.num_frames;
        &self.vertices[f * n..(f + 1) * n]
    }

    pub fn frame_joints(&self, f: usize) -> &[f32] {
        let n = self.joints.len() / self.num_frames;
        &self.joints[f * n..(f + 1) * n]
    }
}

/// T̄ + Σ β_k S_k, then J = 𝒥 T. A shape vector shorter than the model's is zero-padded.
pub fn shape_body(model: &BodyModel, shape: &[f32]) -> Result<ShapedBody, BodyError> {
    let n = model.num_shape_coeffs();
    if shape.len() > n {
        return Err(BodyError::input(
            "shape",
            format!("{} coefficients given, the model has {n}", shape.len()),
        ));
    }
    if let Some(i) = shape.iter().position(|x| !x.is_finite() || f64::from(x.abs()) > MAX_BETA) {
        return Err(BodyError::input(
            "shape",
            format!("coefficient {i} is {}: expected a finite value within ±{MAX_BETA}", shape[i]),
        ));
    }
    let mut vertices: Vec<f32> = model.v_template.iter().flatten().copied().collect();
    let len = vertices.len();
    for (k, &b) in shape.iter().enumerate() {
        if b != 0.0 {
            let dir = &model.shapedirs()[k * len..(k + 1) * len];
            vertices.iter_mut().zip(dir).for_each(|(v, d)| *v += b * d);
        }
    }
    let joints = regress_joints(model, &vertices);
    Ok(ShapedBody { vertices, joints })
}

/// J = 𝒥 · vertices, with the sparse regressor.
pub fn regress_joints(model: &BodyModel, vertices: &[f32]) -> Vec<Vec3> {
    let reg = model.j_regressor();
    (0..reg.rows())
        .map(|j| {
            reg.row(j).fold(Vec3::ZERO, |acc, (v, w)| acc + w * Vec3::from_slice(&vertices[3 * v..3 * v + 3]))
        })
        .collect()
}

/// Checks a pose/translation batch and returns its frame count.
fn frame_count(model: &BodyModel, poses: &[f32], transl: &[f32]) -> Result<usize, BodyError> {
    let pl = model.pose_len();
    if poses.is_empty() || !poses.len().is_multiple_of(pl) {
        return Err(BodyError::input(
            "pose",
            format!(
                "expected a multiple of {pl} values ({} joints × 3), found {}",
                model.num_joints(),
                poses.len()
            ),
        ));
    }
    let f = poses.len() / pl;
    if transl.len() != 3 * f {
        return Err(BodyError::input(
            "translation",
            format!("expected {} values (3 per frame), found {}", 3 * f, transl.len()),
        ));
    }
    if let Some(i) = poses.iter().position(|x| !x.is_finite()) {
        return Err(BodyError::input(
            "pose",
            format!("frame {}, joint {} is not finite", i / pl, (i % pl) / 3),
        ));
    }
    if let Some(i) = transl.iter().position(|x| !x.is_finite()) {
        return Err(BodyError::input("translation", format!("frame {} is not finite", i / 3)));
    }
    Ok(f)
}

/// Per-frame local rotation matrices, F × J.
pub fn frame_rotations(poses: &[f32]) -> Vec<Mat3> {
    poses.chunks_exact(3).map(|r| rodrigues([r[0], r[1], r[2]])).collect()
}

/// Pose-corrective features (R_k − I for k ≥ 1, row-major), F × 9(J − 1).
fn pose_features(rotations: &[Mat3], joints: usize) -> Vec<f32> {
    let mut out = Vec::with_capacity(rotations.len() / joints * 9 * (joints - 1));
    for frame in rotations.chunks_exact(joints) {
        for r in &frame[1..] {
            let m = *r - Mat3::IDENTITY;
            // glam is column-major; SMPL flattens row-major.
            for row in 0..3 {
                out.extend_from_slice(&m.row(row).to_array());
            }
        }
    }
    out
}

/// Poses `shaped` with F frames of axis-angle `poses` (F × 3J) and `transl` (F × 3).
pub fn pose_frames(
    model: &BodyModel,
    shaped: &ShapedBody,
    poses: &[f32],
    transl: &[f32],
) -> Result<PosedFrames, BodyError> {
    let f = frame_count(model, poses, transl)?;
    let j = model.num_joints();
    let len = shaped.vertices.len();
    let rotations = frame_rotations(poses);

    let p = model.num_pose_features();
    let feats = if p > 0 { pose_features(&rotations, j) } else { Vec::new() };
    let mut vertices = vec![0.0f32; f * len];
    let mut joints = vec![0.0f32; f * j * 3];
    let mut transforms = vec![Affine3A::IDENTITY; f * j];
    let skin = model.skin();
    // One group of frames per thread: the pose-corrective GEMM streams the large posedirs matrix
    // once per group, so few big groups beat many small ones (memory-bound otherwise).
    let group_frames = f.div_ceil(rayon::current_num_threads()).max(1);
    vertices
        .par_chunks_mut(group_frames * len)
        .zip(joints.par_chunks_mut(group_frames * 3 * j))
        .zip(transforms.par_chunks_mut(group_frames * j))
        .enumerate()
        .for_each(|(g, ((group, joints_out), world_out))| {
            let first = g * group_frames;
            let n = group.len() / len;
            group.chunks_exact_mut(len).for_each(|v| v.copy_from_slice(&shaped.vertices));
            // v_posed = v_shaped + P · features, one small GEMM per group.
            if p > 0 {
                faer::linalg::matmul::matmul(
                    MatMut::from_row_major_slice_mut(group, n, len),
                    Accum::Add,
                    MatRef::from_row_major_slice(&feats[first * p..(first + n) * p], n, p),
                    MatRef::from_row_major_slice(model.posedirs(), p, len),
                    1.0f32,
                    Par::Seq,
                );
            }
            for (i, verts) in group.chunks_exact_mut(len).enumerate() {
                let fi = first + i;
                let t = Vec3A::from_slice(&transl[3 * fi..3 * fi + 3]);
                let world =
                    world_transforms(model.parents(), &rotations[fi * j..(fi + 1) * j], &shaped.joints);
                let skinning = skinning_transforms(&world, &shaped.joints);
                for (v, xyz) in verts.chunks_exact_mut(3).enumerate() {
                    // Blend the 3×4 matrices of the joints that influence this vertex.
                    let mut m = Mat3A::ZERO;
                    let mut tr = Vec3A::ZERO;
                    for (k, w) in skin.row(v) {
                        m += skinning[k].matrix3 * w;
                        tr += skinning[k].translation * w;
                    }
                    let out = m * Vec3A::from_slice(xyz) + tr + t;
                    xyz.copy_from_slice(&out.to_array());
                }
                for (k, g) in world.iter().enumerate() {
                    let mut g = *g;
                    g.translation += t;
                    joints_out[3 * (i * j + k)..3 * (i * j + k) + 3]
                        .copy_from_slice(&g.translation.to_array());
                    world_out[i * j + k] = g;
                }
            }
        });
    Ok(PosedFrames { num_frames: f, vertices, joints, transforms })
}

/// T(β, θ) of the thesis for one frame: the shaped rest body plus the pose correctives B_P(θ),
/// before skinning. A garment bound to the body takes its rest shape from it (Eq. 3.2).
pub fn pose_corrected(model: &BodyModel, shaped: &ShapedBody, pose: &[f32]) -> Result<Vec<f32>, BodyError> {
    frame_count(model, pose, &[0.0; 3])?;
    let mut vertices = shaped.vertices.clone();
    let p = model.num_pose_features();
    if p > 0 {
        let feats = pose_features(&frame_rotations(pose), model.num_joints());
        let len = vertices.len();
        faer::linalg::matmul::matmul(
            MatMut::from_row_major_slice_mut(&mut vertices, 1, len),
            Accum::Add,
            MatRef::from_row_major_slice(&feats, 1, p),
            MatRef::from_row_major_slice(model.posedirs(), p, len),
            1.0f32,
            Par::Seq,
        );
    }
    Ok(vertices)
}

/// One frame's skinning transforms A_k with the translation added: what LBS blends for any point
/// skinned to this body with its own weights (a garment, Eq. 3.3).
pub fn frame_skinning(
    model: &BodyModel,
    shaped: &ShapedBody,
    pose: &[f32],
    transl: &[f32],
) -> Result<Vec<Affine3A>, BodyError> {
    frame_count(model, pose, transl)?;
    let world = world_transforms(model.parents(), &frame_rotations(pose), &shaped.joints);
    let t = Vec3A::from_slice(transl);
    Ok(skinning_transforms(&world, &shaped.joints)
        .into_iter()
        .map(|mut a| {
            a.translation += t;
            a
        })
        .collect())
}

/// One-call forward for a batch that shares one shape.
pub fn forward(
    model: &BodyModel,
    shape: &[f32],
    poses: &[f32],
    transl: &[f32],
) -> Result<PosedFrames, BodyError> {
    pose_frames(model, &shape_body(model, shape)?, poses, transl)
}
