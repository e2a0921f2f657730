//! A mesh with named blend shapes (a face's expressions) as glTF morph targets, at default
//! weights, optionally played over time: the weights keyed per frame and the mesh's node moved
//! rigidly (a tracked head). Blender imports the targets as named shape keys and three.js exposes
//! them in `morphTargetDictionary`, both from `extras.targetNames`.

use std::path::Path;

use serde_json::json;

use super::buffer::Buffer;
use super::document::{Track, continuous_rotations, finish};
use super::morph::{morph_mesh_json, weights_sampler};
use crate::{MeshFileError, TriMesh};

/// A base mesh and its blend shapes.
#[derive(Debug, Clone, PartialEq)]
pub struct BlendShapeMesh {
    pub name: String,
    /// The base, shown at zero weights; its UVs and colours are exported when present.
    pub mesh: TriMesh,
    pub shape_names: Vec<String>,
    /// Per shape, each vertex's offset at weight 1.
    pub shapes: Vec<Vec<[f32; 3]>>,
    /// The weights the mesh shows when nothing plays (one per shape).
    pub weights: Vec<f32>,
}

/// The blend shapes' weights over time, and optionally the mesh's rigid motion.
#[derive(Debug, Clone, PartialEq)]
pub struct BlendShapeAnimation {
    pub fps: f32,
    /// Per frame, one weight per shape.
    pub weights: Vec<Vec<f32>>,
    /// Per frame, the mesh node's rotation (unit quaternion x, y, z, w) and translation; `None`
    /// keeps the node still.
    pub node_pose: Option<Vec<([f32; 4], [f32; 3])>>,
}

fn invalid(path: &Path, at: impl Into<String>, expected: impl Into<String>) -> MeshFileError {
    MeshFileError::format(path, at, expected)
}

impl BlendShapeMesh {
    fn validate(&self, path: &Path) -> Result<(), MeshFileError> {
        self.mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
        let (n, v) = (self.shapes.len(), self.mesh.vertex_count());
        for (field, len) in [("shape_names", self.shape_names.len()), ("weights", self.weights.len())] {
            if len != n {
                return Err(invalid(
                    path,
                    format!("{}.{field}", self.name),
                    format!("{n} (one per shape), found {len}"),
                ));
            }
        }
        for (k, shape) in self.shapes.iter().enumerate() {
            let at = format!("{}.shapes[{k}] ({})", self.name, self.shape_names[k]);
            if shape.len() != v {
                return Err(invalid(
                    path,
                    at,
                    format!("{v} offsets (the mesh's vertices), found {}", shape.len()),
                ));
            }
            if shape.iter().flatten().any(|c| !c.is_finite()) {
                return Err(invalid(path, at, "finite offsets"));
            }
        }
        if let Some(k) = self.weights.iter().position(|w| !w.is_finite()) {
            return Err(invalid(path, format!("{}.weights[{k}]", self.name), "a finite weight"));
        }
        Ok(())
    }
}

impl BlendShapeAnimation {
    fn validate(&self, path: &Path, shapes: usize) -> Result<(), MeshFileError> {
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(invalid(path, "animation.fps", format!("a positive frame rate, found {}", self.fps)));
        }
        let frames = self.weights.len();
        if frames == 0 {
            return Err(invalid(path, "animation.weights", "at least one frame"));
        }
        for (f, w) in self.weights.iter().enumerate() {
            if w.len() != shapes || w.iter().any(|x| !x.is_finite()) {
                return Err(invalid(
                    path,
                    format!("animation.weights[{f}]"),
                    format!("{shapes} finite weights (one per shape), found {}", w.len()),
                ));
            }
        }
        if let Some(pose) = &self.node_pose {
            if pose.len() != frames {
                let expected = format!("{frames} frames (as weights), found {}", pose.len());
                return Err(invalid(path, "animation.node_pose", expected));
            }
            for (f, (q, t)) in pose.iter().enumerate() {
                let norm = q.iter().map(|c| c * c).sum::<f32>().sqrt();
                if !(norm.is_finite() && (norm - 1.0).abs() < 1e-3 && t.iter().all(|c| c.is_finite())) {
                    let expected = "a unit quaternion (x, y, z, w) and a finite translation";
                    return Err(invalid(path, format!("animation.node_pose[{f}]"), expected));
                }
            }
        }
        Ok(())
    }
}

/// Writes `shapes` (and `animation`, as the file's one animation) to a `.glb` file atomically.
pub fn write_blend_shape_glb(
    path: impl AsRef<Path>,
    shapes: &BlendShapeMesh,
    animation: Option<&BlendShapeAnimation>,
) -> Result<(), MeshFileError> {
    let path = path.as_ref();
    shapes.validate(path)?;
    if let Some(a) = animation {
        a.validate(path, shapes.shapes.len())?;
    }
    let mut buffer = Buffer::default();
    let targets: Vec<Vec<[f32; 3]>> = shapes
        .shapes
        .iter()
        .map(|s| {
            shapes.mesh.positions.iter().zip(s).map(|(p, d)| std::array::from_fn(|c| p[c] + d[c])).collect()
        })
        .collect();
    let mesh = morph_mesh_json(
        &mut buffer,
        &shapes.name,
        &shapes.mesh,
        &targets,
        &shapes.weights,
        Some(&shapes.shape_names),
    );
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": "Mannequin" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "name": shapes.name, "mesh": 0 }],
        "meshes": [mesh],
    });
    if let Some(a) = animation {
        let mut track = Track::default();
        track.add(weights_sampler(&mut buffer, a.fps, &a.weights), 0, "weights");
        if let Some(pose) = &a.node_pose {
            let times: Vec<[f32; 1]> = (0..pose.len()).map(|k| [(k as f64 / a.fps as f64) as f32]).collect();
            let input = buffer.floats(&times, true, None);
            let rotations = continuous_rotations(pose.iter().map(|(q, _)| *q));
            let translations: Vec<[f32; 3]> = pose.iter().map(|(_, t)| *t).collect();
            for (output, property) in [
                (buffer.floats(&rotations, false, None), "rotation"),
                (buffer.floats(&translations, false, None), "translation"),
            ] {
                track.add(
                    json!({ "input": input, "output": output, "interpolation": "LINEAR" }),
                    0,
                    property,
                );
            }
        }
        doc["animations"] =
            json!([{ "name": "expression", "samplers": track.samplers, "channels": track.channels }]);
    }
    let bytes = finish(path, doc, buffer)?;
    mannequin_io::write_atomic(path, &bytes).map_err(|e| MeshFileError::io(path, e))
}
