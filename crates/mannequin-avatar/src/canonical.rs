//! The subject's body at rest: the model's template shaped by the dataset's β, pose-free, with
//! its rig, optionally midpoint-subdivided for more Gaussians. A model directory stores it, so a
//! trained avatar needs neither the body-model file nor the dataset again.

use mannequin_body::{BodyModel, lbs::shape_body};
use mannequin_io::limits::FLOAT32;
use mannequin_io::limits::MAX_DISTANCE;
use mannequin_io::{NpyArray, Npz, NpzWriter};
use mannequin_mesh::subdivide::Subdivision;

use crate::error::AvatarError;

/// The name of layer 0, the body; garment layers ([`crate::garment_layer`]) follow it.
pub const BODY: &str = "body";

/// Most midpoint subdivisions of a subject's mesh: each quadruples the faces (each a Gaussian or
/// two), and three already make 64 times the template's.
pub const MAX_SUBDIVISIONS: usize = 3;

/// Refuses more than [`MAX_SUBDIVISIONS`].
pub(crate) fn check_subdivisions(subdivisions: usize) -> Result<(), AvatarError> {
    if subdivisions > MAX_SUBDIVISIONS {
        let reason = format!("{subdivisions} subdivisions (expected at most {MAX_SUBDIVISIONS})");
        return Err(AvatarError::Invalid(reason));
    }
    Ok(())
}

#[derive(Debug, Clone, PartialEq)]
pub struct Canonical {
    /// Shaped template, [V] xyz.
    pub vertices: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    /// Skinning weights, V × J row-major.
    pub weights: Vec<f32>,
    /// Rest joints of the shaped body.
    pub joints: Vec<[f32; 3]>,
    pub parents: Vec<Option<usize>>,
    /// Pose correctives, 9(J−1) × 3V, or empty.
    pub posedirs: Vec<f32>,
    /// Per vertex, how much of the offset field applies: 0 where a garment layer hides the body
    /// ([`crate::skirt_layer`]), 1 elsewhere.
    pub offset_gate: Vec<f32>,
    /// Per vertex, the index of its layer in `layer_names`: 0, the body, or a garment
    /// ([`crate::garment_layer`]).
    pub layer: Vec<u8>,
    pub layer_names: Vec<String>,
}

impl Canonical {
    /// Shapes `model` by `betas` (zero-padded) and subdivides `subdivisions` times.
    pub fn from_body(model: &BodyModel, betas: &[f32], subdivisions: usize) -> Result<Self, AvatarError> {
        check_subdivisions(subdivisions)?;
        let shaped = shape_body(model, betas)?;
        let mut c = Self {
            vertices: shaped.vertices.chunks_exact(3).map(|v| [v[0], v[1], v[2]]).collect(),
            faces: model.faces.clone(),
            weights: model.weights().to_vec(),
            joints: shaped.joints.iter().map(|j| j.to_array()).collect(),
            parents: model.parents().to_vec(),
            posedirs: model.posedirs().to_vec(),
            offset_gate: vec![1.0; model.num_vertices()],
            layer: vec![0; model.num_vertices()],
            layer_names: vec![BODY.to_string()],
        };
        for _ in 0..subdivisions {
            c = c.subdivided();
        }
        Ok(c)
    }

    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    pub fn num_joints(&self) -> usize {
        self.parents.len()
    }

    /// One level of midpoint subdivision; weights and pose correctives interpolate linearly.
    pub fn subdivided(&self) -> Self {
        let v = self.num_vertices();
        let s = Subdivision::new(v, &self.faces);
        let flat: Vec<f32> = self.vertices.iter().flatten().copied().collect();
        let vertices = s.interpolate(&flat, 3).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let posedirs = if self.posedirs.is_empty() {
            Vec::new()
        } else {
            // Rows are pose features, columns 3V: interpolate each row as V triples.
            self.posedirs.chunks_exact(3 * v).flat_map(|row| s.interpolate(row, 3)).collect()
        };
        let weights = s.interpolate(&self.weights, self.num_joints());
        // An edge never joins two layers, so its midpoint's layer is its ends' layer exactly.
        let layer = s.interpolate(&self.layer.iter().map(|&l| f32::from(l)).collect::<Vec<_>>(), 1);
        Self {
            layer: layer.into_iter().map(|l| l.round() as u8).collect(),
            layer_names: self.layer_names.clone(),
            vertices,
            offset_gate: s.interpolate(&self.offset_gate, 1),
            faces: s.faces,
            weights,
            joints: self.joints.clone(),
            parents: self.parents.clone(),
            posedirs,
        }
    }

    pub fn write(&self, w: &mut NpzWriter) {
        let (v, j) = (self.num_vertices(), self.num_joints());
        w.add("vertices", NpyArray::f32(vec![v, 3], self.vertices.iter().flatten().copied().collect()));
        w.add(
            "faces",
            NpyArray::i64(
                vec![self.faces.len(), 3],
                self.faces.iter().flatten().map(|&i| i as i64).collect(),
            ),
        );
        w.add("weights", NpyArray::f32(vec![v, j], self.weights.clone()));
        w.add("joints", NpyArray::f32(vec![j, 3], self.joints.iter().flatten().copied().collect()));
        w.add(
            "parents",
            NpyArray::i64(vec![j], self.parents.iter().map(|p| p.map_or(-1, |p| p as i64)).collect()),
        );
        let rows = if self.posedirs.is_empty() { 0 } else { self.posedirs.len() / (3 * v) };
        w.add("posedirs", NpyArray::f32(vec![rows, 3 * v], self.posedirs.clone()));
        w.add("offset_gate", NpyArray::f32(vec![v], self.offset_gate.clone()));
        w.add("layer", NpyArray::i64(vec![v], self.layer.iter().map(|&l| i64::from(l)).collect()));
        w.add("layer_names", NpyArray::text(&self.layer_names.join("\n")));
    }

    /// Reads what [`Canonical::write`] wrote, checking every shape against the vertex and joint
    /// counts and every value against its meaning: float32 numbers, coordinates within
    /// `MAX_DISTANCE` metres, offset gates in [0, 1], faces and parents that index what is there.
    pub fn read(npz: &Npz) -> Result<Self, AvatarError> {
        let f32s = |key: &str, shape: &[Option<usize>], allowed| -> Result<Vec<f32>, AvatarError> {
            let (_, d) = npz.f64_in_range(key, shape, allowed)?;
            Ok(d.into_iter().map(|x| x as f32).collect())
        };
        // The body at rest, in metres.
        let vertices = f32s("vertices", &[None, Some(3)], -MAX_DISTANCE..=MAX_DISTANCE)?;
        let v = vertices.len() / 3;
        let joints = f32s("joints", &[None, Some(3)], -MAX_DISTANCE..=MAX_DISTANCE)?;
        let j = joints.len() / 3;
        if j == 0 {
            return Err(npz.field_error("joints", "expected at least one joint, found none").into());
        }
        let weights = f32s("weights", &[Some(v), Some(j)], FLOAT32)?;
        // Pose correctives: none, or a row per rotation-matrix entry of every joint but the root.
        let none = npz.get("posedirs").is_some_and(|a| a.shape.first() == Some(&0));
        let rows = if none { 0 } else { 9 * (j - 1) };
        let posedirs = f32s("posedirs", &[Some(rows), Some(3 * v)], FLOAT32)?;
        let (_, faces) = npz.f64_with_shape("faces", &[None, Some(3)])?;
        let (_, parents) = npz.f64_with_shape("parents", &[Some(j)])?;
        // Models saved before garment layers existed let the field move every vertex.
        let offset_gate = if npz.contains("offset_gate") {
            f32s("offset_gate", &[Some(v)], 0.0..=1.0)?
        } else {
            vec![1.0; v]
        };
        let bad = |field: &str, reason: String| AvatarError::from(npz.field_error(field, reason));
        if v == 0 || faces.is_empty() {
            return Err(bad(
                "faces",
                format!("expected a mesh, found {} faces on {v} vertices", faces.len() / 3),
            ));
        }
        // Models saved before garment layers are all body.
        let (layer, layer_names) = if npz.contains("layer") {
            let names: Vec<String> = npz.text("layer_names")?.split('\n').map(String::from).collect();
            let (_, layer) = npz.f64_with_shape("layer", &[Some(v)])?;
            if let Some(l) = layer.iter().find(|&&l| !(l >= 0.0 && (l as usize) < names.len())) {
                return Err(bad("layer", format!("layer {l} of {} named in layer_names", names.len())));
            }
            (layer.into_iter().map(|l| l as u8).collect(), names)
        } else {
            (vec![0; v], vec![BODY.to_string()])
        };
        let faces: Vec<[u32; 3]> = faces
            .chunks_exact(3)
            .enumerate()
            .map(|(i, f)| {
                if f.iter().all(|&x| x >= 0.0 && (x as usize) < v) {
                    Ok([f[0] as u32, f[1] as u32, f[2] as u32])
                } else {
                    Err(bad("faces", format!("face {i} indexes past the {v} vertices")))
                }
            })
            .collect::<Result<_, _>>()?;
        let parents = parents
            .iter()
            .enumerate()
            .map(|(k, &p)| match p {
                p if p < 0.0 => Ok(None),
                p if p >= 0.0 && (p as usize) < k => Ok(Some(p as usize)),
                _ => Err(bad("parents", format!("joint {k} has parent {p}, expected an earlier joint"))),
            })
            .collect::<Result<_, _>>()?;
        let triples = |x: Vec<f32>| x.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        Ok(Self {
            vertices: triples(vertices),
            faces,
            weights,
            joints: triples(joints),
            parents,
            posedirs,
            offset_gate,
            layer,
            layer_names,
        })
    }
}
