//! Assembles the glTF document: one node per joint (translation = bind offset from the parent),
//! a skinned mesh node, inverse bind matrices `translate(−bind_joint)`, and one LINEAR sampler per
//! joint rotation plus one for the root translation, keyed at `t = i / fps`.
//!
//! With identity bind rotations a joint's world matrix at frame t is `G_j(t)`, and glTF skins a
//! vertex as `Σ_j w_j G_j(t) translate(−J_j) v`, which is SMPL's linear blend skinning
//! (the thesis' LBS equation) without pose correctives.
//!
//! Vertex caches (cloth) follow as unskinned meshes at the scene root, played by morph targets
//! in the same animation, so they stay in sync with the body.

use std::path::Path;

use glam::Vec4;
use serde_json::{Value, json};

use super::buffer::{ARRAY_BUFFER, Buffer, ELEMENT_ARRAY_BUFFER, Int};
use super::glb::glb;
use super::influences::top_four;
use super::model::{SkeletalAnimation, SkinnedLayer, SkinnedMesh};
use super::morph::MorphSequence;
use super::split::split_uv_seams;
use crate::normals::vertex_normals;
use crate::{MeshFileError, TriMesh};

/// Writes `skinned` (and `animation`, when given, as the file's single animation) to a `.glb`
/// file atomically. The mesh node sits at the scene root with no transform of its own, as glTF
/// requires of skinned meshes.
pub fn write_glb(
    path: impl AsRef<Path>,
    skinned: &SkinnedMesh,
    animation: Option<&SkeletalAnimation>,
) -> Result<(), MeshFileError> {
    write_scene_glb(path, skinned, animation, &[])
}

/// [`write_glb`] with vertex caches (`morphs`, e.g. simulated garments) beside the body, all
/// played by the file's one animation.
pub fn write_scene_glb(
    path: impl AsRef<Path>,
    skinned: &SkinnedMesh,
    animation: Option<&SkeletalAnimation>,
    morphs: &[MorphSequence],
) -> Result<(), MeshFileError> {
    let path = path.as_ref();
    let bytes = scene_glb_bytes(path, skinned, &[], animation, morphs)?;
    mannequin_io::write_atomic(path, &bytes).map_err(|e| MeshFileError::io(path, e))
}

/// [`write_glb`] with `layers` (garments, say) as skinned meshes of their own, each its own node
/// driven by the body's skeleton.
pub fn write_layered_glb(
    path: impl AsRef<Path>,
    skinned: &SkinnedMesh,
    layers: &[SkinnedLayer],
    animation: Option<&SkeletalAnimation>,
) -> Result<(), MeshFileError> {
    let path = path.as_ref();
    let bytes = scene_glb_bytes(path, skinned, layers, animation, &[])?;
    mannequin_io::write_atomic(path, &bytes).map_err(|e| MeshFileError::io(path, e))
}

/// The bytes [`write_scene_glb`] and [`write_layered_glb`] write, every part checked, for a
/// server that sends them instead; `name` names the file in errors.
pub fn scene_glb_bytes(
    name: &Path,
    skinned: &SkinnedMesh,
    layers: &[SkinnedLayer],
    animation: Option<&SkeletalAnimation>,
    morphs: &[MorphSequence],
) -> Result<Vec<u8>, MeshFileError> {
    skinned.validate(name)?;
    let joints = skinned.skeleton.joint_count();
    if let Some(a) = animation {
        a.validate(name, joints)?;
    }
    for l in layers {
        l.validate(name, joints)?;
    }
    for m in morphs {
        m.validate(name)?;
    }
    encode(name, skinned, layers, animation, morphs)
}

fn encode(
    path: &Path,
    skinned: &SkinnedMesh,
    layers: &[SkinnedLayer],
    animation: Option<&SkeletalAnimation>,
    morphs: &[MorphSequence],
) -> Result<Vec<u8>, MeshFileError> {
    let skeleton = &skinned.skeleton;
    let joints = skeleton.joint_count();
    let mut buffer = Buffer::default();

    let body = primitive(path, &skinned.mesh, &skinned.weights, joints, &mut buffer)?;
    let ibm: Vec<[f32; 16]> = skeleton
        .bind_joints
        .iter()
        .map(|b| {
            let mut m = [0.0; 16];
            (m[0], m[5], m[10], m[15]) = (1.0, 1.0, 1.0, 1.0);
            (m[12], m[13], m[14]) = (-b[0], -b[1], -b[2]);
            m
        })
        .collect();
    let ibm = buffer.floats(&ibm, false, None);

    let mut nodes: Vec<Value> = (0..joints)
        .map(|j| {
            let offset = match skeleton.parents[j] {
                Some(p) => std::array::from_fn::<f32, 3, _>(|d| {
                    skeleton.bind_joints[j][d] - skeleton.bind_joints[p][d]
                }),
                None => skeleton.bind_joints[j],
            };
            let mut node = json!({ "name": skeleton.names[j], "translation": offset });
            let children: Vec<usize> = (0..joints).filter(|&c| skeleton.parents[c] == Some(j)).collect();
            if !children.is_empty() {
                node["children"] = json!(children);
            }
            node
        })
        .collect();
    nodes.push(json!({ "name": "body", "mesh": 0, "skin": 0 }));
    let mut meshes = vec![json!({ "name": "body", "primitives": [body] })];
    let mut roots = vec![0, joints];
    for l in layers {
        let layer = primitive(path, &l.mesh, &l.weights, joints, &mut buffer)?;
        roots.push(nodes.len());
        nodes.push(json!({ "name": l.name, "mesh": meshes.len(), "skin": 0 }));
        meshes.push(json!({ "name": l.name, "primitives": [layer] }));
    }
    let first_morph = nodes.len();
    for m in morphs {
        roots.push(nodes.len());
        nodes.push(json!({ "name": m.name, "mesh": meshes.len() }));
        meshes.push(m.mesh_json(&mut buffer));
    }

    let mut doc = json!({
        "asset": { "version": "2.0", "generator": "Mannequin" },
        "scene": 0,
        "scenes": [{ "nodes": roots }],
        "nodes": nodes,
        "meshes": meshes,
        "skins": [{ "inverseBindMatrices": ibm, "joints": (0..joints).collect::<Vec<_>>(), "skeleton": 0 }],
    });
    let mut track = Track::default();
    if let Some(a) = animation {
        skeletal_tracks(a, skeleton.bind_joints[0], &mut buffer, &mut track);
    }
    for (i, m) in morphs.iter().enumerate() {
        track.add(m.weights_sampler(&mut buffer), first_morph + i, "weights");
    }
    if !track.channels.is_empty() {
        doc["animations"] =
            json!([{ "name": "motion", "samplers": track.samplers, "channels": track.channels }]);
    }
    finish(path, doc, buffer)
}

/// What refers to accessor `a` in `doc`: a mesh attribute or an animation sampler.
fn accessor_role(doc: &Value, a: usize) -> String {
    let meshes = doc["meshes"].as_array().into_iter().flatten();
    for mesh in meshes {
        let primitives = mesh["primitives"].as_array().into_iter().flatten();
        let targets = primitives.clone().flat_map(|p| p["targets"].as_array().into_iter().flatten());
        let attributes = primitives.map(|p| &p["attributes"]).chain(targets);
        for map in attributes.filter_map(Value::as_object) {
            if let Some((name, _)) = map.iter().find(|(_, v)| v.as_u64() == Some(a as u64)) {
                return format!("mesh {} {name}", mesh["name"].as_str().unwrap_or("(unnamed)"));
            }
        }
    }
    let samplers = doc["animations"][0]["samplers"].as_array().into_iter().flatten();
    for (i, sampler) in samplers.enumerate() {
        for side in ["input", "output"] {
            if sampler[side].as_u64() == Some(a as u64) {
                return format!("animation sampler {i} {side}");
            }
        }
    }
    format!("accessor {a}")
}

/// The GLB bytes of `doc` with `buffer` as its one buffer.
pub(crate) fn finish(path: &Path, mut doc: Value, buffer: Buffer) -> Result<Vec<u8>, MeshFileError> {
    if let Some((a, element)) = buffer.non_finite {
        let at = format!("{}, element {element}", accessor_role(&doc, a));
        return Err(MeshFileError::format(path, at, "finite numbers"));
    }
    doc["buffers"] = json!([{ "byteLength": buffer.bytes.len() }]);
    doc["bufferViews"] = json!(buffer.views);
    doc["accessors"] = json!(buffer.accessors);
    let json = serde_json::to_vec(&doc).expect("a serde_json::Value always serialises");
    let bytes = glb(&json, &buffer.bytes);
    if u32::try_from(bytes.len()).is_err() {
        return Err(MeshFileError::format(
            path,
            "file size",
            format!("at most 4 GiB (GLB limit), found {} bytes", bytes.len()),
        ));
    }
    Ok(bytes)
}

/// The mesh primitive: seam-split vertices with POSITION, NORMAL, optional TEXCOORD_0 and
/// COLOR_0, and the four strongest skinning influences.
fn primitive(
    path: &Path,
    mesh: &TriMesh,
    weights: &[f32],
    joints: usize,
    buffer: &mut Buffer,
) -> Result<Value, MeshFileError> {
    let split = split_uv_seams(mesh);
    let source: Vec<usize> = split.source.iter().map(|&v| v as usize).collect();

    let normals = vertex_normals(&mesh.positions, &mesh.faces);
    // A vertex used only by degenerate faces has no normal; glTF requires unit length, so give it
    // the body's up axis rather than emit an invalid file.
    let normal = |v: usize| if normals[v] == [0.0; 3] { [0.0, 1.0, 0.0] } else { normals[v] };
    let mut influences = Vec::with_capacity(source.len());
    for &v in &source {
        influences.push(top_four(&weights[v * joints..(v + 1) * joints]).ok_or_else(|| {
            MeshFileError::format(
                path,
                format!("weights[vertex {v}]"),
                "at least one positive skinning weight",
            )
        })?);
    }
    let joint_kind = if joints <= 256 { Int::U8 } else { Int::U16 };

    let positions: Vec<[f32; 3]> = source.iter().map(|&v| mesh.positions[v]).collect();
    let mut attributes = json!({
        "POSITION": buffer.floats(&positions, true, Some(ARRAY_BUFFER)),
        "NORMAL": buffer.floats(&source.iter().map(|&v| normal(v)).collect::<Vec<_>>(), false, Some(ARRAY_BUFFER)),
    });
    if let Some(uv) = &split.uv {
        // glTF's texture origin is the top-left corner: v_gltf = 1 − v_obj.
        let flipped: Vec<[f32; 2]> = uv.iter().map(|t| [t[0], 1.0 - t[1]]).collect();
        attributes["TEXCOORD_0"] = json!(buffer.floats(&flipped, false, Some(ARRAY_BUFFER)));
    }
    if let Some(colors) = &mesh.colors {
        let colors: Vec<[f32; 3]> = source.iter().map(|&v| colors[v]).collect();
        attributes["COLOR_0"] = json!(buffer.floats(&colors, false, Some(ARRAY_BUFFER)));
    }
    let joint_ids: Vec<[u32; 4]> = influences.iter().map(|(j, _)| j.map(u32::from)).collect();
    attributes["JOINTS_0"] = json!(buffer.ints(&joint_ids, joint_kind, Some(ARRAY_BUFFER)));
    let strongest: Vec<[f32; 4]> = influences.iter().map(|(_, w)| *w).collect();
    attributes["WEIGHTS_0"] = json!(buffer.floats(&strongest, false, Some(ARRAY_BUFFER)));

    let indices: Vec<[u32; 1]> = split.faces.iter().flatten().map(|&i| [i]).collect();
    let indices = buffer.ints(&indices, Int::U32, Some(ELEMENT_ARRAY_BUFFER));
    Ok(json!({ "attributes": attributes, "indices": indices, "mode": 4 }))
}

/// The samplers and channels of the file's one animation.
#[derive(Default)]
pub(crate) struct Track {
    pub samplers: Vec<Value>,
    pub channels: Vec<Value>,
}

impl Track {
    pub(crate) fn add(&mut self, sampler: Value, node: usize, property: &str) {
        self.channels
            .push(json!({ "sampler": self.samplers.len(), "target": { "node": node, "path": property } }));
        self.samplers.push(sampler);
    }
}

/// One rotation channel per joint and a translation channel for the root, all sharing one
/// time accessor.
fn skeletal_tracks(
    animation: &SkeletalAnimation,
    root_bind: [f32; 3],
    buffer: &mut Buffer,
    track: &mut Track,
) {
    let frames = animation.frame_count();
    let fps = animation.fps as f64;
    let times: Vec<[f32; 1]> = (0..frames).map(|i| [(i as f64 / fps) as f32]).collect();
    let input = buffer.floats(&times, true, None);
    let linear = |output: usize| json!({ "input": input, "output": output, "interpolation": "LINEAR" });
    let joints = animation.local_rotations[0].len();
    for j in 0..joints {
        let rotations = continuous_rotations(animation.local_rotations.iter().map(|pose| pose[j]));
        track.add(linear(buffer.floats(&rotations, false, None)), j, "rotation");
    }
    let root: Vec<[f32; 3]> =
        animation.root_translation.iter().map(|t| std::array::from_fn(|d| root_bind[d] + t[d])).collect();
    track.add(linear(buffer.floats(&root, false, None)), 0, "translation");
}

/// Normalises each quaternion and flips its sign where needed so consecutive keys lie in the same
/// hemisphere: q and −q are the same rotation, but interpolating between them takes the long way.
pub(crate) fn continuous_rotations(track: impl Iterator<Item = [f32; 4]>) -> Vec<[f32; 4]> {
    let mut out: Vec<[f32; 4]> = Vec::new();
    for q in track {
        let mut q = Vec4::from(q).normalize();
        if out.last().is_some_and(|&p| Vec4::from(p).dot(q) < 0.0) {
            q = -q;
        }
        out.push(q.to_array());
    }
    out
}
