//! Dressing a body (thesis Eqs. 3.2–3.3): the template's offsets D^g on a body of any shape,
//! T^g(β, θ) = I^g T(β, θ) + D^g, posed by linear blend skinning with weights carried from the
//! body to the garment by Gaussian RBFs (NGD §3.5) whose width is each vertex's distance to the
//! body: a vertex on the body takes that body vertex's weights exactly, and one that stands off
//! (a hem, a cuff) blends the joints around it instead of tearing along the nearest one.

use glam::{Mat3A, Vec3A};
use mannequin_body::weight_transfer::{KernelWidth, transfer_weights};
use mannequin_body::{BodyModel, ShapedBody, frame_skinning, pose_corrected, shape_body};
use mannequin_mesh::adjacency::boundary_loops_by_height;
use mannequin_mesh::points;

use crate::error::GarmentError;
use crate::garment::Garment;

/// The kernel's smallest width (m): small against any edge, so on-body vertices copy their weights.
const KERNEL_FLOOR: f32 = 1e-4;

/// A garment transferred to one body shape.
#[derive(Debug, Clone)]
pub struct Dressed<'a> {
    garment: &'a Garment,
    model: &'a BodyModel,
    faces: Vec<[u32; 3]>,
    shaped: ShapedBody,
    betas: Vec<f32>,
    /// N × J skinning weights.
    pub weights: Vec<f32>,
}

impl<'a> Dressed<'a> {
    /// `garment` on `model` with shape `betas`; refused when the template hangs on another model.
    pub fn new(garment: &'a Garment, model: &'a BodyModel, betas: &[f32]) -> Result<Self, GarmentError> {
        garment.check_body(model)?;
        let faces = model.faces.clone();
        let shaped = shape_body(model, betas)?;
        let mut dressed = Self { garment, model, faces, shaped, betas: betas.to_vec(), weights: Vec::new() };
        let rest = dressed.rest();
        dressed.weights = transfer_weights(
            &points(&dressed.shaped.vertices),
            model.weights(),
            model.num_joints(),
            &rest,
            KernelWidth::NearestDistance(KERNEL_FLOOR),
        );
        Ok(dressed)
    }

    pub fn garment(&self) -> &'a Garment {
        self.garment
    }

    pub fn model(&self) -> &'a BodyModel {
        self.model
    }

    /// The body's shape parameters.
    pub fn betas(&self) -> &[f32] {
        &self.betas
    }

    /// Eq. 3.2 at rest (θ = 0): I^g T(β, 0) + D^g.
    pub fn rest(&self) -> Vec<[f32; 3]> {
        self.garment.on_body(&points(&self.shaped.vertices), &self.faces)
    }

    /// The vertices held to the body, as an elastic waistband holds a skirt or trousers: for a
    /// lower-body garment the loop of its boundary that is highest at rest, none otherwise.
    pub fn held(&self) -> Vec<u32> {
        let garment = self.garment;
        match garment.recipe.category.is_lower_body() {
            true => boundary_loops_by_height(&self.rest(), &garment.mesh.faces).pop().unwrap_or_default(),
            false => Vec::new(),
        }
    }

    /// `rest` (positions of the garment's vertices on this body at rest, e.g. a reconstruction's)
    /// posed by linear blend skinning with the garment's weights: each vertex's posed position and
    /// the 3×3 part of its blended transform, whose transpose carries a gradient back to `rest`.
    pub fn skin(
        &self,
        rest: &[[f32; 3]],
        pose: &[f32],
        transl: &[f32],
    ) -> Result<Vec<([f32; 3], Mat3A)>, GarmentError> {
        self.skin_with(rest, &self.weights, pose, transl)
    }

    /// [`Self::skin`] with other weights (N × J): a remeshed garment's, carried from these.
    pub fn skin_with(
        &self,
        rest: &[[f32; 3]],
        weights: &[f32],
        pose: &[f32],
        transl: &[f32],
    ) -> Result<Vec<([f32; 3], Mat3A)>, GarmentError> {
        let skinning = frame_skinning(self.model, &self.shaped, pose, transl)?;
        let joints = self.model.num_joints();
        if rest.len() * joints != weights.len() {
            return Err(GarmentError::invalid(
                "rest",
                format!("{} vertices; the weights are for {}", rest.len(), weights.len() / joints.max(1)),
            ));
        }
        Ok(rest
            .iter()
            .zip(weights.chunks_exact(joints))
            .map(|(p, w)| {
                let (mut m, mut t) = (Mat3A::ZERO, Vec3A::ZERO);
                for (k, &wk) in w.iter().enumerate() {
                    if wk != 0.0 {
                        m += skinning[k].matrix3 * wk;
                        t += skinning[k].translation * wk;
                    }
                }
                ((m * Vec3A::from(*p) + t).to_array(), m)
            })
            .collect())
    }

    /// Eqs. 3.2–3.3: the garment on the body in pose `pose` (3 per joint) moved by `transl`.
    pub fn posed(&self, pose: &[f32], transl: &[f32]) -> Result<Vec<[f32; 3]>, GarmentError> {
        let corrected = pose_corrected(self.model, &self.shaped, pose)?;
        let rest = self.garment.on_body(&points(&corrected), &self.faces);
        Ok(self.skin(&rest, pose, transl)?.into_iter().map(|(p, _)| p).collect())
    }
}
