//! What a skinned, animated export holds, in the terms the body model already uses (SMPL-style:
//! joints in world space at a bind pose with identity rotations, parent-relative rotations per
//! frame), so that a body crate can fill it without knowing glTF.

use std::path::Path;

use crate::{MeshFileError, TriMesh};

/// A joint hierarchy at its bind pose. The bind pose has identity rotations, as in SMPL, so a
/// joint's bind transform is a pure translation to its position.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    pub names: Vec<String>,
    /// Each joint's parent; joint 0 is the single root and every parent comes before its children.
    pub parents: Vec<Option<usize>>,
    /// World-space joint positions in the bind pose, metres.
    pub bind_joints: Vec<[f32; 3]>,
}

/// A bind-pose mesh with its skeleton and dense linear-blend-skinning weights: a body (the glTF
/// node and mesh are named `body`).
#[derive(Debug, Clone, PartialEq)]
pub struct SkinnedMesh {
    /// Bind-pose vertices in metres; its UVs and colours are exported when present.
    pub mesh: TriMesh,
    pub skeleton: Skeleton,
    /// V×J weights, row-major (one row per vertex), as SMPL's `weights` array. glTF keeps the four
    /// largest of each row, renormalised to sum to one.
    pub weights: Vec<f32>,
}

/// A mesh skinned by a [`SkinnedMesh`]'s skeleton, written as a node of its own (a garment).
#[derive(Debug, Clone, PartialEq)]
pub struct SkinnedLayer {
    pub name: String,
    pub mesh: TriMesh,
    /// V×J weights, row-major, in the skeleton's joints.
    pub weights: Vec<f32>,
}

impl SkinnedLayer {
    pub(crate) fn validate(&self, path: &Path, joints: usize) -> Result<(), MeshFileError> {
        let layer = |e| MeshFileError::format(path, format!("layer {}", self.name), format!("{e}"));
        self.mesh.validate().map_err(layer)?;
        check_weights(
            path,
            &format!("layer {} weights", self.name),
            &self.weights,
            self.mesh.vertex_count(),
            joints,
        )
    }
}

/// `weights` as `v` rows of `j` finite non-negative skinning weights; `at` names them.
fn check_weights(path: &Path, at: &str, weights: &[f32], v: usize, j: usize) -> Result<(), MeshFileError> {
    if weights.len() != v * j {
        let expected = format!("{} values ({v} vertices × {j} joints), found {}", v * j, weights.len());
        return Err(invalid(path, at, expected));
    }
    if let Some(k) = weights.iter().position(|w| !(w.is_finite() && *w >= 0.0)) {
        return Err(invalid(
            path,
            format!("{at}[vertex {}, joint {}]", k / j, k % j),
            format!("a finite non-negative weight, found {}", weights[k]),
        ));
    }
    Ok(())
}

/// A motion for a skeleton: one pose per frame at a fixed rate.
#[derive(Debug, Clone, PartialEq)]
pub struct SkeletalAnimation {
    pub fps: f32,
    /// Frame × joint unit quaternions (x, y, z, w), parent-relative and relative to the bind pose.
    pub local_rotations: Vec<Vec<[f32; 4]>>,
    /// Per frame, the world translation added to the root joint's bind position.
    pub root_translation: Vec<[f32; 3]>,
}

fn invalid(path: &Path, at: impl Into<String>, expected: impl Into<String>) -> MeshFileError {
    MeshFileError::format(path, at, expected)
}

impl Skeleton {
    pub fn joint_count(&self) -> usize {
        self.names.len()
    }

    /// `path` names the file being written, for the error message.
    pub(crate) fn validate(&self, path: &Path) -> Result<(), MeshFileError> {
        let j = self.names.len();
        if j == 0 || j > u16::MAX as usize + 1 {
            return Err(invalid(path, "skeleton", format!("1 to 65536 joints, found {j}")));
        }
        for (field, len) in [("parents", self.parents.len()), ("bind_joints", self.bind_joints.len())] {
            if len != j {
                return Err(invalid(
                    path,
                    format!("skeleton.{field}"),
                    format!("{j} entries (one per name), found {len}"),
                ));
            }
        }
        for (i, parent) in self.parents.iter().enumerate() {
            let ok = match parent {
                None => i == 0,
                Some(p) => *p < i,
            };
            if !ok {
                let expected = if i == 0 {
                    "no parent (joint 0 is the root)".into()
                } else {
                    format!("a parent below {i}")
                };
                return Err(invalid(
                    path,
                    format!("skeleton.parents[{i}]"),
                    format!("{expected}, found {parent:?}"),
                ));
            }
        }
        if let Some(i) = self.bind_joints.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(invalid(path, format!("skeleton.bind_joints[{i}]"), "finite coordinates"));
        }
        Ok(())
    }
}

impl SkinnedMesh {
    pub(crate) fn validate(&self, path: &Path) -> Result<(), MeshFileError> {
        self.mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
        self.skeleton.validate(path)?;
        check_weights(path, "weights", &self.weights, self.mesh.vertex_count(), self.skeleton.joint_count())
    }
}

impl SkeletalAnimation {
    pub fn frame_count(&self) -> usize {
        self.local_rotations.len()
    }

    pub(crate) fn validate(&self, path: &Path, joints: usize) -> Result<(), MeshFileError> {
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(invalid(path, "animation.fps", format!("a positive frame rate, found {}", self.fps)));
        }
        let frames = self.local_rotations.len();
        if frames == 0 {
            return Err(invalid(path, "animation.local_rotations", "at least one frame"));
        }
        if self.root_translation.len() != frames {
            return Err(invalid(
                path,
                "animation.root_translation",
                format!("{frames} frames (as local_rotations), found {}", self.root_translation.len()),
            ));
        }
        for (f, pose) in self.local_rotations.iter().enumerate() {
            if pose.len() != joints {
                return Err(invalid(
                    path,
                    format!("animation frame {f}"),
                    format!("{joints} joint rotations (the skeleton's joint count), found {}", pose.len()),
                ));
            }
            for (j, q) in pose.iter().enumerate() {
                let norm = q.iter().map(|c| c * c).sum::<f32>().sqrt();
                if !(norm.is_finite() && (norm - 1.0).abs() < 1e-3) {
                    return Err(invalid(
                        path,
                        format!("animation frame {f}, joint {j}"),
                        format!("a unit quaternion (x, y, z, w), found {q:?}"),
                    ));
                }
            }
        }
        if let Some(f) = self.root_translation.iter().position(|t| t.iter().any(|c| !c.is_finite())) {
            return Err(invalid(path, format!("animation.root_translation[{f}]"), "finite coordinates"));
        }
        Ok(())
    }
}
