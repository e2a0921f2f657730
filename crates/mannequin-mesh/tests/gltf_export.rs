//! The `.glb` writer, checked from the outside: the file is parsed back with a small reader written
//! here from the glTF 2.0 specification (GLB chunks, accessors, node TRS, LINEAR samplers,
//! inverse bind matrices), the skin is applied from the file's own data, and the result is
//! compared with analytic poses of a 3-joint arm and with linear blend skinning computed directly
//! from the inputs. Two more tests run the Khronos glTF-Validator and three.js's loader on it
//! (tools/node_checks.rs says when they are required).

use std::path::{Path, PathBuf};

use glam::{Mat4, Quat, Vec3};
use mannequin_mesh::gltf::MAX_MORPH_FRAMES;
use mannequin_mesh::{
    BlendShapeAnimation, BlendShapeMesh, MorphSequence, SkeletalAnimation, Skeleton, SkinnedLayer,
    SkinnedMesh, TriMesh, UvLayout, write_blend_shape_glb, write_glb, write_layered_glb, write_scene_glb,
};
use serde_json::Value;

#[path = "../../../tools/node_checks.rs"]
mod node_checks;
use node_checks::{KHRONOS_VALIDATOR, THREE_JS};

const RING: [[f32; 2]; 4] = [[0.1, 0.1], [-0.1, 0.1], [-0.1, -0.1], [0.1, -0.1]];
const RING_X: [f32; 5] = [0.0, 0.5, 1.0, 1.5, 2.0];
const FPS: f32 = 10.0;

/// A square tube along +x from the shoulder (0,0,0) through the elbow (1,0,0) to the wrist
/// (2,0,0), with a UV seam along one side. Rings at x = 0, 0.5 follow the shoulder, x = 1 is split
/// half and half between shoulder and elbow, x = 1.5 follows the elbow and x = 2 the wrist.
fn arm() -> SkinnedMesh {
    let positions: Vec<[f32; 3]> =
        RING_X.iter().flat_map(|&x| RING.iter().map(move |&[y, z]| [x, y, z])).collect();
    let mut faces = Vec::new();
    let mut uv_faces = Vec::new();
    for r in 0..4u32 {
        for k in 0..4u32 {
            let v = |r: u32, k: u32| 4 * r + k % 4;
            let t = |r: u32, k: u32| 5 * r + k; // k = 4 is the seam's second UV.
            faces.extend([[v(r, k), v(r + 1, k), v(r + 1, k + 1)], [v(r, k), v(r + 1, k + 1), v(r, k + 1)]]);
            uv_faces
                .extend([[t(r, k), t(r + 1, k), t(r + 1, k + 1)], [t(r, k), t(r + 1, k + 1), t(r, k + 1)]]);
        }
    }
    let coords = (0..5).flat_map(|r| (0..5).map(move |k| [k as f32 / 4.0, r as f32 / 4.0])).collect();
    let mut mesh = TriMesh::new(positions, faces);
    mesh.uv = Some(UvLayout { coords, faces: uv_faces });
    mesh.colors = Some((0..20).map(|i| [i as f32 / 20.0, 0.5, 1.0 - i as f32 / 20.0]).collect());
    let ring_weights = [[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let weights = (0..20).flat_map(|v| ring_weights[v / 4]).collect();
    let skeleton = Skeleton {
        names: vec!["shoulder".into(), "elbow".into(), "wrist".into()],
        parents: vec![None, Some(0), Some(1)],
        bind_joints: vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
    };
    SkinnedMesh { mesh, skeleton, weights }
}

fn rz(degrees: f32) -> [f32; 4] {
    Quat::from_rotation_z(degrees.to_radians()).to_array()
}

/// Frame 0: bind pose. 1: elbow +90° about z. 2: shoulder −90° and elbow +90° about z, moved by
/// (0, 0, 0.3). 3: wrist +90° about x.
fn motion() -> SkeletalAnimation {
    let id = [0.0, 0.0, 0.0, 1.0];
    let rx90 = Quat::from_rotation_x(90f32.to_radians()).to_array();
    SkeletalAnimation {
        fps: FPS,
        local_rotations: vec![
            vec![id; 3],
            vec![id, rz(90.0), id],
            vec![rz(-90.0), rz(90.0), id],
            vec![id, id, rx90],
        ],
        root_translation: vec![[0.0; 3], [0.0; 3], [0.0, 0.0, 0.3], [0.0; 3]],
    }
}

/// Where a bind-pose arm vertex goes in each frame, worked out by hand.
fn analytic(frame: usize, [x, y, z]: [f32; 3]) -> [f32; 3] {
    let ring = RING_X.iter().position(|&r| r == x).unwrap();
    match (frame, ring) {
        (0, _) | (1, 0 | 1) | (3, 0..=3) => [x, y, z],
        // The elbow turns the forearm's +x into +y: (1 + a, y) ↦ (1 − y, a).
        (1, 2) => [1.0 - y / 2.0, y / 2.0, z],
        (1, 3) => [1.0 - y, 0.5, z],
        (1, 4) => [1.0 - y, 1.0, z],
        // The shoulder's −90° maps (x, y) ↦ (y, −x); the elbow's +90° undoes it for the forearm.
        (2, 0 | 1) => [y, -x, z + 0.3],
        (2, 2) => [y / 2.0, (y - 2.0) / 2.0, z + 0.3],
        (2, 3) => [0.5, y - 1.0, z + 0.3],
        (2, 4) => [1.0, y - 1.0, z + 0.3],
        // The wrist's +90° about x maps (y, z) ↦ (−z, y).
        (3, 4) => [x, -z, y],
        _ => unreachable!(),
    }
}

/// Linear blend skinning straight from the inputs: forward kinematics with bind offsets, then
/// `Σ w_j G_j (v − J_j)`.
fn direct_lbs(skinned: &SkinnedMesh, animation: &SkeletalAnimation, frame: usize) -> Vec<Vec3> {
    let s = &skinned.skeleton;
    let j_count = s.names.len();
    let mut world: Vec<Mat4> = Vec::with_capacity(j_count);
    for j in 0..j_count {
        let q = Quat::from_array(animation.local_rotations[frame][j]);
        let bind = Vec3::from(s.bind_joints[j]);
        world.push(match s.parents[j] {
            None => Mat4::from_rotation_translation(q, bind + Vec3::from(animation.root_translation[frame])),
            Some(p) => world[p] * Mat4::from_rotation_translation(q, bind - Vec3::from(s.bind_joints[p])),
        });
    }
    (0..skinned.mesh.vertex_count())
        .map(|v| {
            let p = Vec3::from(skinned.mesh.positions[v]);
            (0..j_count)
                .map(|j| {
                    skinned.weights[v * j_count + j]
                        * world[j].transform_point3(p - Vec3::from(s.bind_joints[j]))
                })
                .sum()
        })
        .collect()
}

/// A parsed `.glb`: its JSON document and binary chunk.
struct Glb {
    doc: Value,
    bin: Vec<u8>,
}

impl Glb {
    fn read(path: &Path) -> Glb {
        let bytes = std::fs::read(path).unwrap();
        let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[0..4], b"glTF");
        assert_eq!(u32_at(4), 2, "GLB version");
        assert_eq!(u32_at(8), bytes.len(), "GLB header length");
        let json_len = u32_at(12);
        assert_eq!(&bytes[16..20], b"JSON");
        let bin_at = 20 + json_len;
        let bin_len = u32_at(bin_at);
        assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
        assert!(json_len % 4 == 0 && bin_len % 4 == 0, "chunks are 4-byte aligned");
        assert_eq!(bin_at + 8 + bin_len, bytes.len(), "nothing after the BIN chunk");
        let doc: Value = serde_json::from_slice(&bytes[20..bin_at]).unwrap();
        let bin = bytes[bin_at + 8..bin_at + 8 + bin_len].to_vec();
        assert!(doc["buffers"][0]["byteLength"].as_u64().unwrap() as usize <= bin.len());
        Glb { doc, bin }
    }

    /// An accessor's elements as f32 rows (integers converted), honouring offsets.
    fn accessor(&self, index: &Value) -> Vec<Vec<f32>> {
        let a = &self.doc["accessors"][index.as_u64().unwrap() as usize];
        let view = &self.doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        assert!(view.get("byteStride").is_none());
        let n = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            t => panic!("type {t}"),
        };
        let (size, read): (usize, fn(&[u8]) -> f32) = match a["componentType"].as_u64().unwrap() {
            5126 => (4, |b| f32::from_le_bytes(b.try_into().unwrap())),
            5125 => (4, |b| u32::from_le_bytes(b.try_into().unwrap()) as f32),
            5123 => (2, |b| u16::from_le_bytes(b.try_into().unwrap()) as f32),
            5121 => (1, |b| b[0] as f32),
            c => panic!("componentType {c}"),
        };
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        assert_eq!(start % size, 0, "accessor data is aligned to its component size");
        let count = a["count"].as_u64().unwrap() as usize;
        assert!(count * n * size <= view["byteLength"].as_u64().unwrap() as usize);
        (0..count)
            .map(|i| (0..n).map(|c| read(&self.bin[start + (i * n + c) * size..][..size])).collect())
            .collect()
    }

    /// The posed vertices at time `t`: nodes' TRS with animated channels sampled (LINEAR: lerp for
    /// translation, slerp for rotation), world matrices down the node tree, then
    /// `Σ w_k (world(joint_k) · IBM_k) v` over JOINTS_0/WEIGHTS_0.
    fn skin_at(&self, t: f32) -> (Vec<[f32; 3]>, Vec<Vec3>) {
        let nodes = self.doc["nodes"].as_array().unwrap();
        let vec = |v: &Value, default: &[f32]| -> Vec<f32> {
            v.as_array().map_or(default.to_vec(), |a| a.iter().map(|x| x.as_f64().unwrap() as f32).collect())
        };
        let mut translation: Vec<Vec3> =
            nodes.iter().map(|n| Vec3::from_slice(&vec(&n["translation"], &[0.0; 3]))).collect();
        let mut rotation: Vec<Quat> =
            nodes.iter().map(|n| Quat::from_slice(&vec(&n["rotation"], &[0.0, 0.0, 0.0, 1.0]))).collect();
        for n in nodes {
            assert!(n.get("scale").is_none() && n.get("matrix").is_none());
        }
        let animation = &self.doc["animations"][0];
        for channel in animation["channels"].as_array().unwrap() {
            let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
            assert_eq!(sampler["interpolation"], "LINEAR");
            let times: Vec<f32> = self.accessor(&sampler["input"]).into_iter().map(|r| r[0]).collect();
            let values = self.accessor(&sampler["output"]);
            let k = times.iter().rposition(|&x| x <= t).unwrap().min(times.len() - 2);
            let s = ((t - times[k]) / (times[k + 1] - times[k])).clamp(0.0, 1.0);
            let node = channel["target"]["node"].as_u64().unwrap() as usize;
            match channel["target"]["path"].as_str().unwrap() {
                "rotation" => {
                    rotation[node] = Quat::from_slice(&values[k]).slerp(Quat::from_slice(&values[k + 1]), s);
                }
                "translation" => {
                    translation[node] =
                        Vec3::from_slice(&values[k]).lerp(Vec3::from_slice(&values[k + 1]), s);
                }
                "weights" => {} // morph meshes: see morph_at
                p => panic!("path {p}"),
            }
        }
        let mut parent = vec![None; nodes.len()];
        for (i, n) in nodes.iter().enumerate() {
            for c in n["children"].as_array().into_iter().flatten() {
                parent[c.as_u64().unwrap() as usize] = Some(i);
            }
        }
        let world = |mut i: usize| {
            let mut m = Mat4::from_rotation_translation(rotation[i], translation[i]);
            while let Some(p) = parent[i] {
                m = Mat4::from_rotation_translation(rotation[p], translation[p]) * m;
                i = p;
            }
            m
        };
        let skin = &self.doc["skins"][0];
        let ibm = self.accessor(&skin["inverseBindMatrices"]);
        let joint_matrix: Vec<Mat4> = skin["joints"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
            .map(|(j, node)| world(node.as_u64().unwrap() as usize) * Mat4::from_cols_slice(&ibm[j]))
            .collect();
        let attributes = &self.doc["meshes"][0]["primitives"][0]["attributes"];
        let bind: Vec<[f32; 3]> =
            self.accessor(&attributes["POSITION"]).iter().map(|p| [p[0], p[1], p[2]]).collect();
        let joints = self.accessor(&attributes["JOINTS_0"]);
        let weights = self.accessor(&attributes["WEIGHTS_0"]);
        let posed = (0..bind.len())
            .map(|v| {
                (0..4)
                    .map(|k| {
                        weights[v][k]
                            * joint_matrix[joints[v][k] as usize].transform_point3(Vec3::from(bind[v]))
                    })
                    .sum()
            })
            .collect();
        (bind, posed)
    }
}

impl Glb {
    /// The vertices of the unskinned mesh node named `name` at time `t`: its POSITION plus each
    /// morph target's POSITION times its weight, the weights sampled LINEAR from the channel on
    /// that node (`k` keys of `targets` values each).
    fn morph_at(&self, name: &str, t: f32) -> Vec<Vec3> {
        let nodes = self.doc["nodes"].as_array().unwrap();
        let node = nodes.iter().position(|n| n["name"] == name && n.get("skin").is_none()).unwrap();
        let primitive = &self.doc["meshes"][nodes[node]["mesh"].as_u64().unwrap() as usize]["primitives"][0];
        let targets = primitive["targets"].as_array().unwrap();
        let animation = &self.doc["animations"][0];
        let channel = animation["channels"]
            .as_array()
            .into_iter()
            .flatten()
            .find(|c| c["target"]["node"] == node && c["target"]["path"] == "weights");
        // Without a channel the mesh shows its default weights.
        let (times, values): (Vec<f32>, Vec<f32>) = match channel {
            Some(channel) => {
                let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
                let times = self.accessor(&sampler["input"]).into_iter().map(|r| r[0]).collect();
                (times, self.accessor(&sampler["output"]).into_iter().map(|r| r[0]).collect())
            }
            None => {
                let mesh = &self.doc["meshes"][nodes[node]["mesh"].as_u64().unwrap() as usize];
                (
                    vec![0.0],
                    mesh["weights"].as_array().unwrap().iter().map(|w| w.as_f64().unwrap() as f32).collect(),
                )
            }
        };
        let k = times.iter().rposition(|&x| x <= t).unwrap().min(times.len().saturating_sub(2));
        let s =
            if times.len() < 2 { 0.0 } else { ((t - times[k]) / (times[k + 1] - times[k])).clamp(0.0, 1.0) };
        let n = targets.len();
        let weight = |i: usize| {
            let next = if times.len() < 2 { 0.0 } else { values[(k + 1) * n + i] };
            values[k * n + i] * (1.0 - s) + next * s
        };
        let mut out: Vec<Vec3> =
            self.accessor(&primitive["attributes"]["POSITION"]).iter().map(|p| Vec3::from_slice(p)).collect();
        for (i, target) in targets.iter().enumerate() {
            let w = weight(i);
            for (o, d) in out.iter_mut().zip(self.accessor(&target["POSITION"])) {
                *o += w * Vec3::from_slice(&d);
            }
        }
        out
    }
}

fn temp_file(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("mq-gltf-{}-{name}", std::process::id()))
}

fn assert_close(got: Vec3, want: Vec3, what: &str) {
    assert!((got - want).abs().max_element() < 1e-5, "{what}: got {got}, want {want}");
}

#[test]
fn skinning_from_the_file_matches_analytic_poses_and_direct_lbs() {
    let (arm, motion) = (arm(), motion());
    let path = temp_file("arm.glb");
    write_glb(&path, &arm, Some(&motion)).unwrap();
    let glb = Glb::read(&path);
    std::fs::remove_file(&path).unwrap();
    assert_eq!(glb.doc["asset"]["version"], "2.0");
    assert_eq!(glb.doc["asset"]["generator"], "Mannequin");
    for view in glb.doc["bufferViews"].as_array().unwrap() {
        assert_eq!(view["byteOffset"].as_u64().unwrap() % 4, 0, "buffer views are 4-byte aligned");
    }

    // Time keys are i / fps.
    let sampler = &glb.doc["animations"][0]["samplers"][0];
    let times = glb.accessor(&sampler["input"]);
    assert_eq!(times, (0..4).map(|i| vec![i as f32 / FPS]).collect::<Vec<_>>());
    let input = &glb.doc["accessors"][sampler["input"].as_u64().unwrap() as usize];
    assert_eq!(
        (input["min"][0].as_f64(), input["max"][0].as_f64()),
        (Some(0.0), Some((3.0f32 / FPS) as f64))
    );

    // Each of the 20 vertices appears once per distinct UV: the 5 seam vertices twice.
    let attributes = &glb.doc["meshes"][0]["primitives"][0]["attributes"];
    let uvs = glb.accessor(&attributes["TEXCOORD_0"]);
    let (bind, _) = glb.skin_at(0.0);
    assert_eq!(bind.len(), 25);
    let source: Vec<usize> =
        bind.iter().map(|p| arm.mesh.positions.iter().position(|q| q == p).unwrap()).collect();
    let layout = arm.mesh.uv.as_ref().unwrap();
    let mut corners: Vec<(usize, [u32; 2])> = Vec::new();
    for (f, tri) in arm.mesh.faces.iter().enumerate() {
        for (&vertex, &t) in tri.iter().zip(&layout.faces[f]) {
            let [u, v] = layout.coords[t as usize];
            corners.push((vertex as usize, [u.to_bits(), (1.0 - v).to_bits()]));
        }
    }
    corners.sort_unstable();
    corners.dedup();
    let mut written: Vec<(usize, [u32; 2])> =
        (0..25).map(|i| (source[i], [uvs[i][0].to_bits(), uvs[i][1].to_bits()])).collect();
    written.sort_unstable();
    assert_eq!(written, corners, "TEXCOORD_0 holds each (vertex, flipped UV) corner once");
    let colors = glb.accessor(&attributes["COLOR_0"]);
    for (i, &s) in source.iter().enumerate() {
        assert_eq!(colors[i], arm.mesh.colors.as_ref().unwrap()[s].to_vec());
    }
    let position = &glb.doc["accessors"][attributes["POSITION"].as_u64().unwrap() as usize];
    assert_eq!(position["min"], serde_json::json!([0.0, -0.1f32, -0.1f32]));
    assert_eq!(position["max"], serde_json::json!([2.0, 0.1f32, 0.1f32]));

    for frame in 0..4 {
        let (_, posed) = glb.skin_at(frame as f32 / FPS);
        let direct = direct_lbs(&arm, &motion, frame);
        for (i, &s) in source.iter().enumerate() {
            let what = format!("frame {frame}, vertex {s}");
            assert_close(posed[i], Vec3::from(analytic(frame, arm.mesh.positions[s])), &what);
            assert_close(direct[s], posed[i], &what);
        }
    }

    // Halfway between frames 0 and 1 the LINEAR sampler slerps the elbow to 45°.
    let (_, posed) = glb.skin_at(0.5 / FPS);
    let (c, s) = (45f32.to_radians().cos(), 45f32.to_radians().sin());
    for (i, &v) in source.iter().enumerate() {
        let [x, y, z] = arm.mesh.positions[v];
        if x == 1.5 {
            assert_close(posed[i], Vec3::new(1.0 + 0.5 * c - y * s, 0.5 * s + y * c, z), "halfway");
        }
    }
}

#[test]
fn bad_inputs_are_errors_naming_the_field() {
    let path = temp_file("bad.glb");
    let mut arm = arm();
    arm.weights.pop();
    let e = write_glb(&path, &arm, None).unwrap_err().to_string();
    assert!(e.contains("weights") && e.contains("60 values"), "{e}");

    let arm_ok = self::arm();
    let mut m = motion();
    m.local_rotations[2][1] = [0.0, 0.0, 0.0, 2.0];
    let e = write_glb(&path, &arm_ok, Some(&m)).unwrap_err().to_string();
    assert!(e.contains("animation frame 2, joint 1") && e.contains("unit quaternion"), "{e}");

    let mut m = motion();
    m.root_translation.pop();
    assert!(write_glb(&path, &arm_ok, Some(&m)).unwrap_err().to_string().contains("root_translation"));

    let mut arm = self::arm();
    arm.skeleton.parents[1] = Some(2);
    let e = write_glb(&path, &arm, None).unwrap_err().to_string();
    assert!(e.contains("skeleton.parents[1]"), "{e}");

    let mut arm = self::arm();
    arm.weights[..12].fill(0.0);
    let e = write_glb(&path, &arm, None).unwrap_err().to_string();
    assert!(e.contains("weights[vertex 0]") && e.contains("positive"), "{e}");
    assert!(!path.exists(), "nothing is written on error");
}

/// A layer (a sleeve over the arm) is a skinned node of its own on the body's skeleton, with its
/// own vertices and the body's joints; a layer whose weights do not fit is refused by name.
#[test]
fn layers_are_skinned_nodes_of_their_own() {
    let path = temp_file("layered.glb");
    let arm = arm();
    let mut sleeve = TriMesh::new(
        arm.mesh.positions.iter().map(|&[x, y, z]| [x, 1.5 * y, 1.5 * z]).collect(),
        arm.mesh.faces.clone(),
    );
    sleeve.colors = None;
    let layer = SkinnedLayer { name: "sleeve".into(), mesh: sleeve, weights: arm.weights.clone() };
    write_layered_glb(&path, &arm, std::slice::from_ref(&layer), Some(&motion())).unwrap();
    let glb = Glb::read(&path);
    let skinned: Vec<(&str, u64)> = glb.doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n.get("skin").is_some())
        .map(|n| (n["name"].as_str().unwrap(), n["mesh"].as_u64().unwrap()))
        .collect();
    assert_eq!(skinned, [("body", 0), ("sleeve", 1)]);
    let attributes = &glb.doc["meshes"][1]["primitives"][0]["attributes"];
    let positions = glb.accessor(&attributes["POSITION"]);
    // No UV seam to split: the sleeve's own 20 vertices, 1.5 times the arm's radius.
    assert_eq!(positions.len(), 20);
    assert!(positions.iter().all(|p| (p[1].abs() - 0.15).abs() < 1e-6 && (p[2].abs() - 0.15).abs() < 1e-6));
    let joints = glb.accessor(&attributes["JOINTS_0"]);
    assert_eq!(joints[19][0], 2.0, "the wrist ring follows the wrist");
    let report = KHRONOS_VALIDATOR.run(&path);
    std::fs::remove_file(&path).unwrap();
    if let Some(report) = report {
        assert!(report.contains(" 0 errors, 0 warnings"), "{report}");
    }
    let bad = SkinnedLayer { weights: arm.weights[..59].to_vec(), ..layer.clone() };
    let e = write_layered_glb(&path, &arm, &[bad], None).unwrap_err().to_string();
    assert!(e.contains("layer sleeve weights") && e.contains("60 values"), "{e}");
    let mut bad = layer.clone();
    bad.mesh.positions[3][1] = f32::NAN;
    let e = write_layered_glb(&path, &arm, &[bad], None).unwrap_err().to_string();
    assert!(e.ends_with("layered.glb: layer sleeve: vertex 3 is not finite"), "{e}");
    let mut bad = layer;
    bad.weights[7] = f32::INFINITY;
    let e = write_layered_glb(&path, &arm, &[bad], None).unwrap_err().to_string();
    assert!(
        e.contains("layer sleeve weights[vertex 2, joint 1]: a finite non-negative weight, found inf"),
        "{e}"
    );
    assert!(!path.exists(), "nothing is written on error");
}

/// Inputs that pass every check can still compute to a non-finite number (a root translation
/// added to its bind position, key times of a vanishing frame rate): the file is refused naming the value's
/// place rather than written with it.
#[test]
fn computed_values_that_overflow_are_not_written() {
    let path = temp_file("overflow.glb");
    let mut arm = arm();
    arm.mesh.colors.as_mut().unwrap()[5][2] = f32::NAN;
    let e = write_glb(&path, &arm, None).unwrap_err().to_string();
    assert!(e.ends_with("overflow.glb: the colour of vertex 5 is not finite"), "{e}");
    let mut far = motion();
    far.root_translation[1][0] = 3e38;
    let mut arm = self::arm();
    arm.skeleton.bind_joints.iter_mut().for_each(|j| j[0] += 3e38);
    let e = write_glb(&path, &arm, Some(&far)).unwrap_err().to_string();
    assert!(e.contains("overflow.glb: animation sampler 3 output, element 1: finite numbers"), "{e}");
    let mut slow = motion();
    slow.fps = 1e-44;
    let e = write_glb(&path, &self::arm(), Some(&slow)).unwrap_err().to_string();
    assert!(e.contains("overflow.glb: animation sampler 0 input, element 1: finite numbers"), "{e}");
    assert!(!path.exists(), "nothing is written on error");
}

/// A deterministic generator for test weights (splitmix64), so the test needs no seed crate.
fn splitmix(state: &mut u64) -> f32 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
}

/// A 300-joint chain (so JOINTS_0 needs u16) over a 12×12 grid whose vertices each have about a
/// dozen non-zero weights (so the top-4 reduction matters), with a 2-frame motion.
fn many_joints() -> (SkinnedMesh, SkeletalAnimation) {
    let (n, joints) = (12usize, 300usize);
    let positions: Vec<[f32; 3]> =
        (0..n * n).map(|i| [(i % n) as f32 * 0.1, (i / n) as f32 * 0.1, 0.0]).collect();
    let faces = (0..n - 1)
        .flat_map(|r| (0..n - 1).map(move |c| (r * n + c) as u32))
        .flat_map(|a| [[a, a + 1, a + n as u32 + 1], [a, a + n as u32 + 1, a + n as u32]])
        .collect();
    let mut seed = 7;
    let weights = (0..n * n * joints).map(|_| (splitmix(&mut seed) - 0.96).max(0.0)).collect();
    let skeleton = Skeleton {
        names: (0..joints).map(|j| format!("j{j}")).collect(),
        parents: (0..joints).map(|j| j.checked_sub(1)).collect(),
        bind_joints: (0..joints).map(|j| [j as f32 * 0.01, 0.0, 0.0]).collect(),
    };
    let animation = SkeletalAnimation {
        fps: 30.0,
        local_rotations: vec![vec![[0.0, 0.0, 0.0, 1.0]; joints], vec![rz(1.0); joints]],
        // The second frame's rotations are negated quaternions: the same rotation, which the
        // writer must keep in the first frame's hemisphere.
        root_translation: vec![[0.0; 3], [0.1, 0.0, 0.0]],
    };
    let mut animation = animation;
    for q in &mut animation.local_rotations[1] {
        *q = q.map(|c| -c);
    }
    (SkinnedMesh { mesh: TriMesh::new(positions, faces), skeleton, weights }, animation)
}

#[test]
fn many_joints_use_u16_indices_and_stay_normalised() {
    let (skinned, animation) = many_joints();
    let path = temp_file("many.glb");
    write_glb(&path, &skinned, Some(&animation)).unwrap();
    let glb = Glb::read(&path);
    std::fs::remove_file(&path).unwrap();
    let attributes = &glb.doc["meshes"][0]["primitives"][0]["attributes"];
    let joints_accessor = &glb.doc["accessors"][attributes["JOINTS_0"].as_u64().unwrap() as usize];
    assert_eq!(joints_accessor["componentType"], 5123);
    let joints = glb.accessor(&attributes["JOINTS_0"]);
    let weights = glb.accessor(&attributes["WEIGHTS_0"]);
    let (bind, _) = glb.skin_at(0.0);
    let j = skinned.skeleton.names.len();
    for v in 0..bind.len() {
        let src = skinned.mesh.positions.iter().position(|p| *p == bind[v]).unwrap();
        let row = &skinned.weights[src * j..(src + 1) * j];
        let mut sorted: Vec<f32> = row.to_vec();
        sorted.sort_by(|a, b| b.total_cmp(a));
        let kept: f32 = sorted[..4].iter().sum();
        assert!((weights[v].iter().sum::<f32>() - 1.0).abs() < 1e-6);
        for k in 0..4 {
            if weights[v][k] > 0.0 {
                assert!((weights[v][k] - row[joints[v][k] as usize] / kept).abs() < 1e-6);
            }
            assert!(
                weights[v][k] == 0.0 || row[joints[v][k] as usize] >= sorted[3],
                "vertex {v} keeps a top-4 joint"
            );
        }
    }
    for sampler in glb.doc["animations"][0]["samplers"].as_array().unwrap() {
        let out = glb.accessor(&sampler["output"]);
        if out[0].len() == 4 {
            let dot: f32 = (0..4).map(|c| out[0][c] * out[1][c]).sum();
            assert!(dot > 0.0, "consecutive rotation keys share a hemisphere");
        }
    }
}

/// The Khronos validator (tools/gltf_validate.mjs) on the arm and the 300-joint export.
#[test]
fn khronos_validator_reports_no_errors() {
    let (many, many_motion) = many_joints();
    for (name, skinned, animation) in [("arm.glb", arm(), motion()), ("many.glb", many, many_motion)] {
        let path = temp_file(&format!("validate-{name}"));
        write_glb(&path, &skinned, Some(&animation)).unwrap();
        let report = KHRONOS_VALIDATOR.run(&path);
        std::fs::remove_file(&path).unwrap();
        let Some(report) = report else { return };
        assert!(report.contains(" 0 errors, 0 warnings"), "{name}: {report}");
    }
}

/// three.js's loader (tools/gltf_three_check.mjs), as a web viewer plays the arm: one skinned
/// mesh with the 3 bones, one clip, and the posed bounding boxes of the analytic poses at the
/// first key, the second (t = d/3) and the last.
#[test]
fn three_js_plays_the_arm_as_posed_by_hand() {
    let (arm, motion) = (arm(), motion());
    let path = temp_file("three-arm.glb");
    write_glb(&path, &arm, Some(&motion)).unwrap();
    let report = THREE_JS.run(&path);
    std::fs::remove_file(&path).unwrap();
    let Some(report) = report else { return };
    assert!(report.contains(": 1 skinned mesh(es), 1 animation(s)"), "{report}");
    assert!(report.contains(" 3 bones,"), "{report}");
    let boxes: Vec<[f32; 6]> = report
        .lines()
        .filter_map(|line| line.trim().strip_prefix("posed box at t="))
        .map(|line| {
            let numbers: Vec<f32> = line
                .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
                .filter_map(|w| w.parse().ok())
                .collect();
            numbers[1..].try_into().unwrap_or_else(|_| panic!("a box in '{line}'"))
        })
        .collect();
    assert_eq!(boxes.len(), 3, "{report}");
    for (frame, got) in [0, 1, 3].into_iter().zip(boxes) {
        let posed: Vec<Vec3> = arm.mesh.positions.iter().map(|&p| Vec3::from(analytic(frame, p))).collect();
        let min = posed.iter().fold(Vec3::INFINITY, |m, &p| m.min(p));
        let max = posed.iter().fold(Vec3::NEG_INFINITY, |m, &p| m.max(p));
        let want = [min.x, min.y, min.z, max.x, max.y, max.z];
        // The script prints four decimals.
        assert!(
            got.iter().zip(want).all(|(g, w)| (g - w).abs() < 2e-4),
            "frame {frame}: {got:?} vs {want:?}"
        );
    }
}

/// A 3×3 sheet with a UV seam down its middle column, over 4 frames at 10 fps: frame k is the
/// sheet moved by (0, −0.1k, 0) and stretched by 1 + 0.2k along x.
fn sheet_cache() -> MorphSequence {
    let positions: Vec<[f32; 3]> =
        (0..9).map(|i| [(i % 3) as f32 * 0.5, 1.0, (i / 3) as f32 * 0.5]).collect();
    let faces = vec![[0, 3, 1], [1, 3, 4], [1, 4, 2], [2, 4, 5], [3, 6, 4], [4, 6, 7], [4, 7, 5], [5, 7, 8]];
    let mut mesh = TriMesh::new(positions.clone(), faces.clone());
    // Per-corner UVs: the left half's corners of column 1 take u = 0.5, the right half's u = 0.51.
    let mut coords = Vec::new();
    let uv_faces = faces
        .iter()
        .enumerate()
        .map(|(f, face)| {
            face.map(|v| {
                let u = (v % 3) as f32 * 0.5 + if v % 3 == 1 && f % 4 >= 2 { 0.01 } else { 0.0 };
                coords.push([u, (v / 3) as f32 * 0.5]);
                coords.len() as u32 - 1
            })
        })
        .collect();
    mesh.uv = Some(UvLayout { coords, faces: uv_faces });
    let frames = (0..4)
        .map(|k| {
            positions.iter().map(|p| [p[0] * (1.0 + 0.2 * k as f32), p[1] - 0.1 * k as f32, p[2]]).collect()
        })
        .collect();
    MorphSequence { name: "sheet".into(), mesh, frames, fps: 10.0 }
}

/// Read back from the file, the cache plays its frames at their keys and blends neighbours
/// linearly between them; the body's skinning is unchanged by the cache beside it.
#[test]
fn vertex_cache_plays_back_from_the_file() {
    let (arm, motion, sheet) = (arm(), motion(), sheet_cache());
    let path = temp_file("cache.glb");
    write_scene_glb(&path, &arm, Some(&motion), std::slice::from_ref(&sheet)).unwrap();
    let glb = Glb::read(&path);
    std::fs::remove_file(&path).unwrap();
    let frame = |k: f32| -> Vec<Vec3> {
        sheet.mesh.positions.iter().map(|p| Vec3::new(p[0] * (1.0 + 0.2 * k), p[1] - 0.1 * k, p[2])).collect()
    };
    for (t, k) in [(0.0, 0.0), (0.1, 1.0), (0.25, 2.5), (0.3, 3.0)] {
        let got = glb.morph_at("sheet", t);
        assert_eq!(got.len(), 12, "9 vertices, the seam column's 3 written twice");
        let want = frame(k);
        for g in got {
            // Each written vertex is one of the frame's vertices (seam copies included).
            let nearest = want.iter().map(|w| (g - *w).length()).fold(f32::INFINITY, f32::min);
            assert!(nearest < 1e-5, "t = {t}: {g} is no vertex of frame {k}");
        }
    }
    let (bind, posed) = glb.skin_at(0.1);
    let want = direct_lbs(&arm, &motion, 1);
    for (b, got) in bind.iter().zip(&posed) {
        let source = arm.mesh.positions.iter().position(|q| q == b).unwrap();
        assert_close(*got, want[source], "arm at frame 1 beside the cache");
    }
    let mut bad = sheet.clone();
    bad.frames[2].pop();
    let e = write_scene_glb(&path, &arm, None, &[bad]).unwrap_err().to_string();
    assert!(e.contains("sheet.frames[2]") && e.contains("9 vertices"), "{e}");
    // Its weight keys grow with the square of the frames: a long cache is refused, not allocated.
    let mut long = sheet.clone();
    long.frames = vec![sheet.frames[0].clone(); MAX_MORPH_FRAMES + 1];
    let e = write_scene_glb(&path, &arm, None, &[long]).unwrap_err().to_string();
    assert!(e.ends_with("cache.glb: sheet.frames: 1 to 4096 frames, found 4097"), "{e}");
}

/// The validator and three.js on the arm with the cache beside it: three.js finds the morph mesh
/// and its bounding box at the last key is frame 3's.
#[test]
fn vertex_cache_passes_the_validator_and_three_js() {
    let (arm, motion, sheet) = (arm(), motion(), sheet_cache());
    let path = temp_file("cache-check.glb");
    write_scene_glb(&path, &arm, Some(&motion), std::slice::from_ref(&sheet)).unwrap();
    let (report, three) = (KHRONOS_VALIDATOR.run(&path), THREE_JS.run(&path));
    std::fs::remove_file(&path).unwrap();
    if let Some(report) = report {
        assert!(report.contains(" 0 errors, 0 warnings"), "{report}");
    }
    let Some(three) = three else { return };
    assert!(three.contains("morph mesh 'sheet': 12 vertices, 4 targets"), "{three}");
    let line = three.lines().find_map(|l| l.trim().strip_prefix("sheet box at t=0.3000: ")).expect(&three);
    // Frame 3: x in [0, 1.6], y = 0.7, z in [0, 1].
    assert_eq!(line, "min (0.0000, 0.7000, 0.0000) max (1.6000, 0.7000, 1.0000)", "{three}");
}

/// The sheet with colours and two named shapes: `lift` raises the middle vertex by 0.2, `spread`
/// moves every vertex by 0.1 per unit of x along x; shown at weights (0.5, 0).
fn sheet_shapes() -> BlendShapeMesh {
    let mut mesh = sheet_cache().mesh;
    mesh.colors = Some((0..9).map(|i| [i as f32 / 8.0, 0.5, 1.0 - i as f32 / 8.0]).collect());
    let lift = (0..9).map(|i| if i == 4 { [0.0, 0.2, 0.0] } else { [0.0; 3] }).collect();
    let spread = mesh.positions.iter().map(|p| [0.1 * p[0], 0.0, 0.0]).collect();
    BlendShapeMesh {
        name: "sheet".into(),
        mesh,
        shape_names: vec!["lift".into(), "spread".into()],
        shapes: vec![lift, spread],
        weights: vec![0.5, 0.0],
    }
}

/// The sheet's vertices at shape weights `w`, computed from the definition above.
fn sheet_at(w: [f32; 2]) -> Vec<Vec3> {
    sheet_cache()
        .mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let lift = if i == 4 { 0.2 * w[0] } else { 0.0 };
            Vec3::new(p[0] * (1.0 + 0.1 * w[1]), p[1] + lift, p[2])
        })
        .collect()
}

fn assert_is_sheet_at(got: &[Vec3], w: [f32; 2], what: &str) {
    let want = sheet_at(w);
    assert_eq!(got.len(), 12, "{what}: 9 vertices, the seam column's 3 written twice");
    for g in got {
        let nearest = want.iter().map(|v| (*g - *v).length()).fold(f32::INFINITY, f32::min);
        assert!(nearest < 1e-5, "{what}: {g} is no vertex of the sheet at weights {w:?}");
    }
}

/// Read back: the shapes' names, the colours, the default weights, and an animation that keys
/// the weights and turns the node.
#[test]
fn blend_shapes_keep_their_names_weights_and_keys() {
    let shapes = sheet_shapes();
    let path = temp_file("shapes.glb");
    write_blend_shape_glb(&path, &shapes, None).unwrap();
    let glb = Glb::read(&path);
    let mesh = &glb.doc["meshes"][0];
    assert_eq!(mesh["extras"]["targetNames"], serde_json::json!(["lift", "spread"]));
    let colors = glb.accessor(&mesh["primitives"][0]["attributes"]["COLOR_0"]);
    let positions = glb.accessor(&mesh["primitives"][0]["attributes"]["POSITION"]);
    for (c, p) in colors.iter().zip(&positions) {
        let i = sheet_cache().mesh.positions.iter().position(|q| q == &[p[0], p[1], p[2]]).unwrap();
        assert_eq!(c, &[i as f32 / 8.0, 0.5, 1.0 - i as f32 / 8.0], "the colour of vertex {i}");
    }
    assert!(glb.doc.get("animations").is_none());
    assert_is_sheet_at(&glb.morph_at("sheet", 0.0), [0.5, 0.0], "default weights");

    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let animation = BlendShapeAnimation {
        fps: 10.0,
        weights: vec![vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 1.0]],
        node_pose: Some(vec![
            ([0.0, 0.0, 0.0, 1.0], [0.0; 3]),
            ([0.0, 0.0, 0.0, 1.0], [0.0; 3]),
            (turn.to_array(), [0.0, 0.0, 1.0]),
        ]),
    };
    write_blend_shape_glb(&path, &shapes, Some(&animation)).unwrap();
    let glb = Glb::read(&path);
    for (t, w) in
        [(0.0, [0.0, 0.0]), (0.05, [0.5, 0.0]), (0.1, [1.0, 0.0]), (0.15, [0.5, 0.5]), (0.2, [0.0, 1.0])]
    {
        assert_is_sheet_at(&glb.morph_at("sheet", t), w, &format!("t = {t}"));
    }
    let animation_json = &glb.doc["animations"][0];
    let keyed = |property: &str| -> Vec<Vec<f32>> {
        let channel = animation_json["channels"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["target"]["path"] == property)
            .unwrap();
        glb.accessor(&animation_json["samplers"][channel["sampler"].as_u64().unwrap() as usize]["output"])
    };
    assert_eq!(keyed("translation")[2], vec![0.0, 0.0, 1.0]);
    let last = Quat::from_slice(&keyed("rotation")[2]);
    assert!(last.angle_between(turn) < 1e-5, "{last} vs {turn}");

    let mut bad = shapes.clone();
    bad.shapes[1].pop();
    let e = write_blend_shape_glb(&path, &bad, None).unwrap_err().to_string();
    assert!(e.contains("sheet.shapes[1] (spread)") && e.contains("9 offsets"), "{e}");
    let mut short = animation.clone();
    short.weights[1].pop();
    let e = write_blend_shape_glb(&path, &shapes, Some(&short)).unwrap_err().to_string();
    assert!(e.contains("animation.weights[1]") && e.contains("2 finite weights"), "{e}");
    std::fs::remove_file(&path).unwrap();
}

/// The validator and three.js on the blend shapes: three.js names the targets and plays the
/// weights to the last key (the spread sheet turned a quarter about y, moved 1 along z).
#[test]
fn blend_shapes_pass_the_validator_and_three_js() {
    let shapes = sheet_shapes();
    let animation = BlendShapeAnimation {
        fps: 10.0,
        weights: vec![vec![0.0, 0.0], vec![0.0, 1.0]],
        node_pose: Some(vec![
            ([0.0, 0.0, 0.0, 1.0], [0.0; 3]),
            (Quat::from_rotation_y(std::f32::consts::FRAC_PI_2).to_array(), [0.0, 0.0, 1.0]),
        ]),
    };
    let path = temp_file("shapes-check.glb");
    write_blend_shape_glb(&path, &shapes, Some(&animation)).unwrap();
    let (report, three) = (KHRONOS_VALIDATOR.run(&path), THREE_JS.run(&path));
    std::fs::remove_file(&path).unwrap();
    if let Some(report) = report {
        assert!(report.contains(" 0 errors, 0 warnings"), "{report}");
    }
    let Some(three) = three else { return };
    assert!(three.contains("morph mesh 'sheet': 12 vertices, 2 targets (lift, spread)"), "{three}");
    let line = three.lines().find_map(|l| l.trim().strip_prefix("sheet box at t=0.1000: ")).expect(&three);
    // Spread: x in [0, 1.1], y = 1, z in [0, 1]; turned by +90° about y (x → −z, z → x), then z + 1.
    let got: Vec<f32> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let want = [0.0, 1.0, -0.1, 1.0, 1.0, 1.0];
    assert!(got.len() == 6 && got.iter().zip(want).all(|(g, w)| (g - w).abs() < 2e-4), "{three}");
}
