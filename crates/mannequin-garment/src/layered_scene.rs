//! A body wearing layers, written for other tools: a `.glb` of the skinned body playing its
//! motion with each layer's frames as morph targets in sync, and each layer's frames as a
//! Blender point cache beside it.

use std::path::Path;

use mannequin_body::{BodyModel, skeletal_animation, skinned_body};
use mannequin_mesh::{MorphSequence, PointCache, write_scene_glb};

use crate::dress_error::DressError;

/// `glb`: the skinned body of shape `betas` playing `(poses, trans, fps)` (SMPL's layout), with
/// each layer's frames as morph targets in sync; and beside it each layer's frames as a Blender
/// point cache, `<name>.pc2`.
pub fn write_layered_scene(
    glb: &Path,
    model: &BodyModel,
    betas: &[f32],
    (poses, trans, fps): (&[f32], &[f32], f32),
    layers: &[MorphSequence],
) -> Result<(), DressError> {
    let dir = glb.parent().unwrap_or(Path::new("."));
    for layer in layers {
        PointCache { start: 0.0, sampling: 1.0, frames: layer.frames.clone() }
            .write(&dir.join(format!("{}.pc2", layer.name)))?;
    }
    let animation = skeletal_animation(model.num_joints(), poses, trans, fps)?;
    write_scene_glb(glb, &skinned_body(model, betas)?, Some(&animation), layers)?;
    Ok(())
}
