//! A mesh whose vertices move frame by frame (a cloth cache) as glTF morph targets: target k holds
//! frame k's displacement from the base, and the weights are keyed one-hot, target k fully on at
//! t = k / fps. LINEAR interpolation between two one-hot keys blends two frames' positions
//! linearly, which is what a vertex cache plays between frames. Blender imports the targets as
//! shape keys and three.js plays them.

use std::path::Path;

use serde_json::{Value, json};

use super::buffer::{ARRAY_BUFFER, Buffer, ELEMENT_ARRAY_BUFFER, Int};
use super::split::split_uv_seams;
use crate::normals::vertex_normals;
use crate::{MeshFileError, TriMesh};

/// Most frames a vertex cache may have in a `.glb`: the one-hot weight keys grow with the square
/// of the frames (4096 frames, 2 min 16 s at 30 fps, take 16.8 million keys, 67 MB).
pub const MAX_MORPH_FRAMES: usize = 4096;

/// `frames` of `mesh`'s vertices at `fps`; the mesh's own positions are the base the targets
/// displace (shown when no animation plays).
#[derive(Debug, Clone, PartialEq)]
pub struct MorphSequence {
    pub name: String,
    pub mesh: TriMesh,
    pub frames: Vec<Vec<[f32; 3]>>,
    pub fps: f32,
}

impl MorphSequence {
    pub(crate) fn validate(&self, path: &Path) -> Result<(), MeshFileError> {
        let at = |field: &str| format!("{}.{field}", self.name);
        self.mesh.validate().map_err(|e| MeshFileError::invalid(path, e))?;
        if !(self.fps.is_finite() && self.fps > 0.0) {
            let expected = format!("a positive frame rate, found {}", self.fps);
            return Err(MeshFileError::format(path, at("fps"), expected));
        }
        if !(1..=MAX_MORPH_FRAMES).contains(&self.frames.len()) {
            let expected = format!("1 to {MAX_MORPH_FRAMES} frames, found {}", self.frames.len());
            return Err(MeshFileError::format(path, at("frames"), expected));
        }
        let v = self.mesh.vertex_count();
        for (f, frame) in self.frames.iter().enumerate() {
            if frame.len() != v {
                let expected = format!("{v} vertices (the mesh's), found {}", frame.len());
                return Err(MeshFileError::format(path, at(&format!("frames[{f}]")), expected));
            }
            if let Some(i) = frame.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(MeshFileError::format(
                    path,
                    at(&format!("frames[{f}][{i}]")),
                    "finite coordinates",
                ));
            }
        }
        Ok(())
    }

    /// The glTF mesh (base attributes, one POSITION + NORMAL target per frame) and its default
    /// weights.
    pub(crate) fn mesh_json(&self, buffer: &mut Buffer) -> Value {
        morph_mesh_json(buffer, &self.name, &self.mesh, &self.frames, &vec![0.0; self.frames.len()], None)
    }

    /// The sampler (LINEAR, one-hot keys) that plays the frames on the mesh's weights.
    pub(crate) fn weights_sampler(&self, buffer: &mut Buffer) -> Value {
        let frames = self.frames.len();
        let keys: Vec<Vec<f32>> =
            (0..frames).map(|k| (0..frames).map(|t| if t == k { 1.0 } else { 0.0 }).collect()).collect();
        weights_sampler(buffer, self.fps, &keys)
    }
}

/// A glTF mesh of `mesh` (POSITION, NORMAL, and TEXCOORD_0 and COLOR_0 when it has them) with one
/// POSITION + NORMAL target per entry of `targets`, each the mesh's vertices in full (stored as
/// their displacement from the base), at default `weights`; `names` go to `extras.targetNames`,
/// where Blender and three.js read the targets' names.
pub(crate) fn morph_mesh_json(
    buffer: &mut Buffer,
    name: &str,
    mesh: &TriMesh,
    targets: &[Vec<[f32; 3]>],
    weights: &[f32],
    names: Option<&[String]>,
) -> Value {
    let split = split_uv_seams(mesh);
    let source: Vec<usize> = split.source.iter().map(|&v| v as usize).collect();
    let unit = |n: [f32; 3]| if n == [0.0; 3] { [0.0, 1.0, 0.0] } else { n };
    let base_normals: Vec<[f32; 3]> =
        vertex_normals(&mesh.positions, &mesh.faces).into_iter().map(unit).collect();
    let pick = |values: &[[f32; 3]]| -> Vec<[f32; 3]> { source.iter().map(|&v| values[v]).collect() };
    let mut attributes = json!({
        "POSITION": buffer.floats(&pick(&mesh.positions), true, Some(ARRAY_BUFFER)),
        "NORMAL": buffer.floats(&pick(&base_normals), false, Some(ARRAY_BUFFER)),
    });
    if let Some(uv) = &split.uv {
        // glTF's texture origin is the top-left corner: v_gltf = 1 − v_obj.
        let flipped: Vec<[f32; 2]> = uv.iter().map(|t| [t[0], 1.0 - t[1]]).collect();
        attributes["TEXCOORD_0"] = json!(buffer.floats(&flipped, false, Some(ARRAY_BUFFER)));
    }
    if let Some(colors) = &mesh.colors {
        attributes["COLOR_0"] = json!(buffer.floats(&pick(colors), false, Some(ARRAY_BUFFER)));
    }
    let delta = |a: &[[f32; 3]], b: &[[f32; 3]]| -> Vec<[f32; 3]> {
        source.iter().map(|&v| std::array::from_fn(|d| a[v][d] - b[v][d])).collect()
    };
    let targets: Vec<Value> = targets
        .iter()
        .map(|target| {
            let normals: Vec<[f32; 3]> = vertex_normals(target, &mesh.faces).into_iter().map(unit).collect();
            json!({
                "POSITION": buffer.floats(&delta(target, &mesh.positions), true, None),
                "NORMAL": buffer.floats(&delta(&normals, &base_normals), false, None),
            })
        })
        .collect();
    let indices: Vec<[u32; 1]> = split.faces.iter().flatten().map(|&i| [i]).collect();
    let indices = buffer.ints(&indices, Int::U32, Some(ELEMENT_ARRAY_BUFFER));
    let mut out = json!({
        "name": name,
        "primitives": [{ "attributes": attributes, "indices": indices, "mode": 4, "targets": targets }],
        "weights": weights,
    });
    if let Some(names) = names {
        out["extras"] = json!({ "targetNames": names });
    }
    out
}

/// A LINEAR sampler keying the morph weights `keys[k]` (one per target) at t = k / fps.
pub(crate) fn weights_sampler(buffer: &mut Buffer, fps: f32, keys: &[Vec<f32>]) -> Value {
    let times: Vec<[f32; 1]> = (0..keys.len()).map(|k| [(k as f64 / fps as f64) as f32]).collect();
    let input = buffer.floats(&times, true, None);
    let values: Vec<[f32; 1]> = keys.iter().flatten().map(|&w| [w]).collect();
    let output = buffer.floats(&values, false, None);
    json!({ "input": input, "output": output, "interpolation": "LINEAR" })
}
