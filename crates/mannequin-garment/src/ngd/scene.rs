//! One frame's scene for the garment's losses: the garment posed by linear blend skinning, with
//! the posed body drawn as its occluder, rendered by the differentiable rasteriser with four
//! channels per vertex: the garment's mask (1 on the garment, 0 on the body) and its unit
//! normals in the camera's axes. The backward pass carries an image gradient to the garment's
//! rest positions: through the rasteriser, the vertex normals and each vertex's blended skinning
//! matrix (d rest = Mᵀ d posed).

use glam::{DVec3, Mat3A, Vec3A};
use mannequin_body::forward;
use mannequin_data::{Camera, Split};
use mannequin_mesh::normals::{vertex_normals, vertex_normals_backward};
use mannequin_raster::differentiable::{Rendered, render};

use crate::error::GarmentError;
use crate::transfer::Dressed;

/// How far inside its skin the body is drawn as an occluder, in metres: it hides the garment where
/// a limb passes in front, not where the garment, lying close, dips under the skin.
const INSET: f32 = 0.015;

/// Channels: the garment's mask, then its camera-space normal.
pub const CHANNELS: usize = 4;

/// A frame's pose: the body's 72 axis-angle values and its translation.
#[derive(Debug, Clone)]
pub struct FramePose {
    pub pose: Vec<f32>,
    pub transl: [f32; 3],
}

impl FramePose {
    /// Frame `k` of `split` (its `k`th frame, not the dataset's frame number).
    pub fn of(split: &Split, k: usize) -> Self {
        Self { pose: split.poses.pose72(k), transl: split.poses.transl[k] }
    }
}

pub(crate) struct Scene {
    positions: Vec<[f32; 3]>,
    faces: Vec<[u32; 3]>,
    attributes: Vec<[f64; CHANNELS]>,
    blends: Vec<Mat3A>,
    /// The posed garment before the noise: its normals are the drawn ones.
    garment: Vec<[f32; 3]>,
    garment_faces: usize,
}

impl Scene {
    /// The garment `rest` (vertices on the dressed body at rest, with skinning `weights`) and the
    /// body, posed in `frame`; each posed garment vertex moved by `noise` (NGD Eq. 12) before it
    /// is drawn. The normals are the noiseless surface's.
    pub(crate) fn new(
        dressed: &Dressed,
        rest: &[[f32; 3]],
        faces: &[[u32; 3]],
        weights: &[f32],
        frame: &FramePose,
        camera: &Camera,
        noise: impl FnMut() -> [f32; 3],
    ) -> Result<Self, GarmentError> {
        let model = dressed.model();
        let skinned = dressed.skin_with(rest, weights, &frame.pose, &frame.transl)?;
        let garment: Vec<[f32; 3]> = skinned.iter().map(|(p, _)| *p).collect();
        let rotation = camera.rotation();
        let mut attributes: Vec<[f64; CHANNELS]> = vertex_normals(&garment, faces)
            .iter()
            .map(|n| {
                let n = rotation * DVec3::from(n.map(f64::from));
                [1.0, n.x, n.y, n.z]
            })
            .collect();
        let mut noise = noise;
        let mut positions: Vec<[f32; 3]> = garment
            .iter()
            .map(|p| {
                let d = noise();
                std::array::from_fn(|c| p[c] + d[c])
            })
            .collect();
        let body_faces = model.template_mesh().faces;
        let posed = forward(model, dressed.betas(), &frame.pose, &frame.transl)?;
        let body: Vec<[f32; 3]> =
            posed.frame_vertices(0).chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
        let body_normals = vertex_normals(&body, &body_faces);
        let g = garment.len() as u32;
        positions.extend(
            body.iter()
                .zip(&body_normals)
                .map(|(p, n)| -> [f32; 3] { std::array::from_fn(|c| p[c] - INSET * n[c]) }),
        );
        attributes.extend(std::iter::repeat_n([0.0; CHANNELS], body.len()));
        let mut all_faces = faces.to_vec();
        all_faces.extend(body_faces.iter().map(|f| f.map(|v| v + g)));
        Ok(Self {
            positions,
            faces: all_faces,
            attributes,
            blends: skinned.iter().map(|(_, m)| *m).collect(),
            garment,
            garment_faces: faces.len(),
        })
    }

    pub(crate) fn render(&self, camera: &Camera) -> Rendered<CHANNELS> {
        render(&self.positions, &self.faces, &self.attributes, camera, [0.0; CHANNELS])
    }

    /// The gradient with respect to the garment's rest positions of a loss whose gradient with
    /// respect to `rendered`'s image is `grad`.
    pub(crate) fn backward(
        &self,
        rendered: &Rendered<CHANNELS>,
        grad: &[[f64; CHANNELS]],
        camera: &Camera,
    ) -> Vec<[f64; 3]> {
        let d = rendered.backward(grad, &self.faces, &self.attributes, camera);
        let g = self.blends.len();
        // The normals were rotated into the camera's axes: back to the world's, then to positions.
        let rotation_t = camera.rotation().transpose();
        let d_normals: Vec<[f64; 3]> = d.attributes[..g]
            .iter()
            .map(|a| (rotation_t * DVec3::new(a[1], a[2], a[3])).to_array())
            .collect();
        let through_normals =
            vertex_normals_backward(&self.garment, &self.faces[..self.garment_faces], &d_normals);
        self.blends
            .iter()
            .zip(&d.positions)
            .zip(&through_normals)
            .map(|((m, p), n)| {
                let g = Vec3A::new((p[0] + n[0]) as f32, (p[1] + n[1]) as f32, (p[2] + n[2]) as f32);
                (m.transpose() * g).to_array().map(f64::from)
            })
            .collect()
    }
}
