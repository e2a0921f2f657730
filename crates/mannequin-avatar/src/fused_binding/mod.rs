//! Tavatar's binding (Eqs. 5–11) as one differentiable op with a hand-written backward, on Flex
//! (CPU) and CubeCL. Composed from tensor ops ([`crate::mesh_gaussians`]) the binding costs ~100
//! small allocating ops forward and as many backward, a fifth of a CPU training step; here it is
//! one pass over faces and one over vertices each way (a third, gathering onto vertices,
//! backward on CubeCL).

mod autodiff;
mod cube;
mod flex;
mod host;
mod kernels;
mod planes;

use std::sync::Arc;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

use crate::mesh_gaussians::GaussianGeometry;
use crate::one_ring_mesh::OneRingMesh;

/// The op's output is four planes, one after the other, each `[G, width]` row-major: means (3),
/// frames (9, row-major with columns t1, t2, n), scales (3) and normals (3, the frame's third
/// column again, for normal rendering). Planes rather than one `[G, 18]` row per Gaussian so
/// that each is a contiguous view: narrowing rows would make the renderer copy every column
/// block forward and Burn copy it again backward.
pub const PLANES: [usize; 4] = [3, 9, 3, 3];

/// Values per Gaussian in the op's output: the [`PLANES`]' widths summed.
pub const PACKED: usize = PLANES[0] + PLANES[1] + PLANES[2] + PLANES[3];

/// Where each of the [`PLANES`] starts in the output for `g` Gaussians.
pub(crate) fn plane_starts(g: usize) -> [usize; 4] {
    let mut start = 0;
    PLANES.map(|width| {
        let plane = start;
        start += width * g;
        plane
    })
}

/// Which Gaussians the op makes, on which mesh.
#[derive(Clone, Debug)]
pub struct BindConfig {
    pub mesh: Arc<OneRingMesh>,
    pub face_gaussians: bool,
    pub vertex_gaussians: bool,
}

impl BindConfig {
    pub fn num_gaussians(&self) -> usize {
        usize::from(self.face_gaussians) * self.mesh.faces.len()
            + usize::from(self.vertex_gaussians) * self.mesh.num_vertices
    }
}

/// Backends that run the fused binding.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait BindingBackend: Backend {
    /// `[G · PACKED]` Gaussians of posed vertices `[V, 3]` as [`PLANES`], face Gaussians first in
    /// each.
    fn tavatar_bind_forward(vertices: FloatTensor<Self>, config: BindConfig) -> FloatTensor<Self>;

    /// The `[V, 3]` gradient of the vertices given the gradient `grad` of the forward output.
    fn tavatar_bind_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: BindConfig,
    ) -> FloatTensor<Self>;
}

/// Tavatar's face and vertex Gaussians of posed `f32` vertices `[V, 3]` on Flex or a CubeCL
/// device, differentiable with respect to the vertices.
pub fn bind(vertices: Tensor<2>, config: &BindConfig) -> GaussianGeometry {
    let g = config.num_gaussians();
    let planes = Tensor::<1>::from_dispatch(<Dispatch as BindingBackend>::tavatar_bind_forward(
        vertices.into_dispatch(),
        config.clone(),
    ));
    let starts = plane_starts(g);
    let spans = std::array::from_fn(|p| (starts[p], PLANES[p] * g));
    let [means, frames, scales, normals] = if crate::host_ops::on_cube(&planes.device()) {
        planes::planes(planes, spans)
    } else {
        spans.map(|(start, len)| planes.clone().narrow(0, start, len))
    };
    GaussianGeometry {
        means: means.reshape([g, 3]),
        frames: frames.reshape([g, 3, 3]),
        scales: scales.reshape([g, 3]),
        normals: normals.reshape([g, 3]),
    }
}
