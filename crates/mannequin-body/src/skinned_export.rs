//! Fills the mesh crate's skinned-export types from a body model: the shaped rest body as the
//! bind pose, and a motion as per-joint local rotations. glTF skinning is plain LBS, so pose
//! correctives (SMPL's posedirs) are not carried; the default body has none.

use mannequin_mesh::gltf::{SkeletalAnimation, Skeleton, SkinnedMesh};

use crate::error::BodyError;
use crate::lbs::shape_body;
use crate::model::BodyModel;
use crate::rodrigues::axis_angle_quat;

/// The body shaped by `shape`, at rest, with its skeleton and weights.
pub fn skinned_body(model: &BodyModel, shape: &[f32]) -> Result<SkinnedMesh, BodyError> {
    let shaped = shape_body(model, shape)?;
    let mut mesh = model.template_mesh();
    mesh.positions = shaped.vertices.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    Ok(SkinnedMesh {
        mesh,
        skeleton: Skeleton {
            names: model.joint_names.clone(),
            parents: model.parents().to_vec(),
            bind_joints: shaped.joints.iter().map(|j| j.to_array()).collect(),
        },
        weights: model.weights().to_vec(),
    })
}

/// F frames of axis-angle `poses` (F × 3J for a skeleton of `joints` joints, SMPL's layout) and
/// `trans` (F × 3) at `fps`.
pub fn skeletal_animation(
    joints: usize,
    poses: &[f32],
    trans: &[f32],
    fps: f32,
) -> Result<SkeletalAnimation, BodyError> {
    let pl = 3 * joints;
    if pl == 0 || !poses.len().is_multiple_of(pl) || poses.len() / pl != trans.len() / 3 {
        return Err(BodyError::input(
            "motion",
            format!(
                "{} pose values and {} translations do not make whole frames of {joints} joints",
                poses.len(),
                trans.len() / 3,
            ),
        ));
    }
    Ok(SkeletalAnimation {
        fps,
        local_rotations: poses
            .chunks_exact(pl)
            .map(|frame| {
                frame.chunks_exact(3).map(|r| axis_angle_quat([r[0], r[1], r[2]]).to_array()).collect()
            })
            .collect(),
        root_translation: trans.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
    })
}
