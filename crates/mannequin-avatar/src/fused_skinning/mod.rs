//! Linear blend skinning with pose correctives (Eq. 1) as one differentiable op on the CubeCL
//! backends. Composed from tensor ops (`mannequin_body::skin_tensors`), the kinematic chain is a
//! sequence of 3×3 products per joint, about 290 small kernels forward and as many backward,
//! a quarter of a GPU training step spent launching; here it is two launches forward and five
//! backward. Flex keeps the composition, which is fast on a CPU and is the reference this op is
//! held to.

mod autodiff;
mod cube;
mod kernels;

use burn::backend::tensor::{FloatTensor, IntTensor};
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::{Device, Int, Tensor, TensorData};

use crate::AvatarError;

/// Backends that run the fused skinning. All float inputs are `f32`.
#[backend_extension(Cube, Autodiff)]
pub trait SkinningBackend: Backend {
    /// Posed vertices `[V, 3]` of rest vertices `[V, 3]` about rest joints `[J, 3]`, for the
    /// axis-angle pose `[1, 3J]` and translation `[1, 3]`; `blend` is `[J + 1, V]` (the weights
    /// transposed, then a row of ones), `posedirs` `[P, 3V]` with `features` = P rows used.
    #[allow(clippy::too_many_arguments)]
    fn lbs_forward(
        vertices: FloatTensor<Self>,
        joints: FloatTensor<Self>,
        pose: FloatTensor<Self>,
        transl: FloatTensor<Self>,
        blend: FloatTensor<Self>,
        posedirs: FloatTensor<Self>,
        parents: IntTensor<Self>,
        features: usize,
    ) -> FloatTensor<Self>;

    /// The gradients of (vertices, joints, pose, transl) given the output's gradient `grad`.
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn lbs_backward(
        vertices: FloatTensor<Self>,
        joints: FloatTensor<Self>,
        pose: FloatTensor<Self>,
        blend: FloatTensor<Self>,
        posedirs: FloatTensor<Self>,
        parents: IntTensor<Self>,
        features: usize,
        grad: FloatTensor<Self>,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>);
}

/// A body's skinning rig on one device, in the layout the kernels read, built once.
#[derive(Debug, Clone)]
pub struct SkinRig {
    blend: Tensor<2>,
    posedirs: Tensor<2>,
    features: usize,
    parents: Tensor<1, Int>,
}

impl SkinRig {
    /// The rig of weights `[V, J]` (row-major), optional correctives `[P, 3V]` and the joint
    /// tree, whose parents must come before their children (as in every SMPL-family model).
    pub fn new(
        weights: &[f32],
        num_vertices: usize,
        posedirs: Option<&Tensor<2>>,
        parents: &[Option<usize>],
        device: &Device,
    ) -> Result<Self, AvatarError> {
        let j = parents.len();
        if weights.len() != num_vertices * j {
            return Err(AvatarError::Invalid(format!(
                "skinning weights: {} values for {num_vertices} vertices and {j} joints",
                weights.len()
            )));
        }
        if let Some(k) = parents.iter().enumerate().position(|(k, p)| p.is_some_and(|p| p >= k)) {
            return Err(AvatarError::Invalid(format!(
                "joint {k}'s parent {:?} does not come before it",
                parents[k]
            )));
        }
        let mut blend = vec![1.0f32; (j + 1) * num_vertices];
        for (v, row) in weights.chunks_exact(j).enumerate() {
            for (k, &w) in row.iter().enumerate() {
                blend[k * num_vertices + v] = w;
            }
        }
        let blend = Tensor::from_data(TensorData::new(blend, [j + 1, num_vertices]), device);
        let (posedirs, features) = match posedirs {
            Some(p) => (p.clone(), p.dims()[0]),
            // The kernels read no row of it; one keeps every buffer non-empty.
            None => (Tensor::zeros([1, 1], device), 0),
        };
        let parents: Vec<i32> = parents.iter().map(|p| p.map_or(-1, |p| p as i32)).collect();
        let parents = Tensor::from_data(TensorData::new(parents, [j]), device);
        Ok(Self { blend, posedirs, features, parents })
    }

    /// Posed vertices `[V, 3]`, differentiable with respect to every input: rest vertices
    /// `[V, 3]`, rest joints `[J, 3]`, pose `[1, 3J]` and translation `[1, 3]`.
    pub fn skin(
        &self,
        vertices: Tensor<2>,
        joints: Tensor<2>,
        pose: Tensor<2>,
        transl: Tensor<2>,
    ) -> Tensor<2> {
        Tensor::from_dispatch(<Dispatch as SkinningBackend>::lbs_forward(
            vertices.into_dispatch(),
            joints.into_dispatch(),
            pose.into_dispatch(),
            transl.into_dispatch(),
            self.blend.clone().into_dispatch(),
            self.posedirs.clone().into_dispatch(),
            self.parents.clone().into_dispatch(),
            self.features,
        ))
    }
}
