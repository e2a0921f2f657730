//! What a layer collides with: the part of the body it can reach, and the layers under it. The
//! simulator moves and hashes every collider triangle every substep, and a T-shirt never meets
//! the feet, so only the body triangles that come near the layer's skinned shape (Eq. 3.3) at
//! some frame are kept.

use std::collections::HashSet;

use mannequin_cloth::{Body, ClothError, Layers};
use mannequin_mesh::TriMesh;

/// A layer under the one being simulated: its triangles, and its positions at every frame of
/// the schedule.
pub(crate) type Layer<'a> = (&'a [[u32; 3]], &'a [Vec<[f32; 3]>]);

/// A body triangle is kept when a corner comes within this far (m) of the skinned layer, give or
/// take half again (the test is by cells of half this side): cloth hangs and swings a few
/// centimetres off its skinned place, and hands swing past the hips.
const REACH: f32 = 0.1;

/// The collider's vertices: the kept body vertices followed by the inner layers'. The inner
/// layers' positions are passed in at each frame, so a layer can be simulated while those under
/// it are still going on ahead of it.
pub(crate) struct Collider<'a> {
    kept: Vec<u32>,
    /// Triangles over the kept body vertices.
    pub faces: Vec<[u32; 3]>,
    /// The inner layers' triangles, over their own vertices.
    layer_faces: Vec<[u32; 3]>,
    body_frames: &'a [Vec<[f32; 3]>],
}

impl<'a> Collider<'a> {
    /// `skinned`: the layer's skinned positions at some frames, with the frame each is of.
    pub fn new(
        body_frames: &'a [Vec<[f32; 3]>],
        body_faces: &[[u32; 3]],
        inner: &[Layer],
        skinned: &[(usize, Vec<[f32; 3]>)],
    ) -> Self {
        let cell = |p: &[f32; 3]| p.map(|x| (2.0 * x / REACH).floor() as i32);
        let mut near = vec![false; body_frames[0].len()];
        for (k, positions) in skinned {
            let cells: HashSet<[i32; 3]> = positions.iter().map(cell).collect();
            for (v, p) in body_frames[*k].iter().enumerate() {
                if near[v] {
                    continue;
                }
                let c = cell(p);
                near[v] = (-2..=2).any(|x| {
                    (-2..=2).any(|y| (-2..=2).any(|z| cells.contains(&[c[0] + x, c[1] + y, c[2] + z])))
                });
            }
        }
        let kept_faces: Vec<usize> =
            (0..body_faces.len()).filter(|&f| body_faces[f].iter().any(|&v| near[v as usize])).collect();
        let body = TriMesh::new(body_frames[0].clone(), body_faces.to_vec());
        let (part, kept) = body.submesh(&kept_faces);
        let mut layer_faces = Vec::new();
        let mut offset = 0;
        for (f, frames) in inner {
            layer_faces.extend(f.iter().map(|t| t.map(|i| i + offset)));
            offset += frames[0].len() as u32;
        }
        Self { kept, faces: part.faces, layer_faces, body_frames }
    }

    /// The body part as a collider, wearing the `inner` layers (the same as [`Collider::new`]'s).
    pub fn body(&self, inner: &[Layer]) -> Result<Body, ClothError> {
        let body = Body::new(self.faces.clone());
        if inner.is_empty() {
            return Ok(body);
        }
        let rest = self.at(0, inner).split_off(self.kept.len());
        body.with_layers(Layers { first_vertex: self.kept.len(), faces: self.layer_faces.clone(), rest })
    }

    /// The collider's vertices at schedule frame `k`, which each of the `inner` layers has reached.
    pub fn at(&self, k: usize, inner: &[Layer]) -> Vec<[f32; 3]> {
        let body = &self.body_frames[k];
        let mut all: Vec<[f32; 3]> = self.kept.iter().map(|&v| body[v as usize]).collect();
        for (_, frames) in inner {
            all.extend_from_slice(&frames[k]);
        }
        all
    }
}
