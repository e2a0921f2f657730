//! The mesh regularisers as one differentiable op with a hand-written backward (Flex and
//! CubeCL): composed from tensor ops each costs tens of gathers, scatters and row-wise products
//! each way (together a tenth of a CPU training step); here each is one pass over its elements.
//! The host math of each term sits next to its tensor form ([`super::laplacian`],
//! [`super::normal_consistency`], [`super::equilateral`]), its GPU form in `kernels.rs`; this
//! module carries the plumbing.

mod autodiff;
mod cube;
mod flex;
mod kernels;
mod tables;

use std::sync::Arc;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;
use rayon::prelude::*;

use crate::one_ring_mesh::OneRingMesh;

/// The fixed mesh the host terms read.
#[derive(Debug)]
pub struct HostMesh {
    /// Faces and sorted one-rings.
    pub rings: Arc<OneRingMesh>,
    /// `[a, b, c, d]` per pair of faces sharing the edge `(a, b)`, `c` and `d` opposite it.
    pub hinges: Vec<[u32; 4]>,
    /// Vertices with at least one neighbour.
    pub num_connected: usize,
}

/// Which regulariser a [`MeshLoss`] evaluates: each backend runs its own form of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HostTerm {
    Laplacian,
    NormalConsistency,
    Equilateral,
}

/// One regulariser on one mesh.
#[derive(Clone, Debug)]
pub struct MeshLoss {
    pub term: HostTerm,
    pub mesh: Arc<HostMesh>,
}

impl MeshLoss {
    /// The loss at vertices `v` (`[V·3]`, f64), and its gradient when `grad` is given
    /// (overwritten).
    pub fn evaluate(&self, v: &[f64], grad: Option<&mut [f64]>) -> f64 {
        let term = match self.term {
            HostTerm::Laplacian => super::laplacian::laplacian_host,
            HostTerm::NormalConsistency => super::normal_consistency::normal_consistency_host,
            HostTerm::Equilateral => super::equilateral::equilateral_host,
        };
        term(&self.mesh, v, grad)
    }
}

/// Backends that run the fused regularisers.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait MeshLossBackend: Backend {
    /// The loss `[1]` of vertices `[V, 3]`.
    fn mesh_loss_forward(vertices: FloatTensor<Self>, loss: MeshLoss) -> FloatTensor<Self>;

    /// The `[V, 3]` gradient of the vertices given the gradient `grad` (`[1]`) of the loss.
    fn mesh_loss_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        loss: MeshLoss,
    ) -> FloatTensor<Self>;
}

/// The loss of vertices `[V, 3]` (f32 or f64) on a Flex or wgpu device, differentiable with
/// respect to them.
pub fn mesh_loss(vertices: Tensor<2>, loss: MeshLoss) -> Tensor<1> {
    Tensor::from_dispatch(<Dispatch as MeshLossBackend>::mesh_loss_forward(vertices.into_dispatch(), loss))
}

/// Fixed number of chunks the per-element terms are split into, whatever the thread count, so
/// the sums (and gradients) are the same bit for bit on any machine.
const CHUNKS: usize = 8;

/// `Σ_e element(e, grad)` over `n` elements, where each element returns its loss and, when given
/// a `[V·3]` buffer, adds its gradient there. Chunks run in parallel on their own buffers, which
/// are summed in chunk order.
pub(super) fn sum_over_elements(
    n: usize,
    num_vertices: usize,
    grad: Option<&mut [f64]>,
    element: impl Fn(usize, Option<&mut [f64]>) -> f64 + Sync,
) -> f64 {
    let want = grad.is_some();
    let per_chunk = n.div_ceil(CHUNKS).max(1);
    let parts: Vec<(f64, Vec<f64>)> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let mut buffer = vec![0.0; if want { 3 * num_vertices } else { 0 }];
            let mut sum = 0.0;
            for e in (c * per_chunk).min(n)..((c + 1) * per_chunk).min(n) {
                sum += element(e, want.then_some(buffer.as_mut_slice()));
            }
            (sum, buffer)
        })
        .collect();
    if let Some(grad) = grad {
        grad.fill(0.0);
        for (_, buffer) in &parts {
            grad.iter_mut().zip(buffer).for_each(|(g, b)| *g += b);
        }
    }
    parts.iter().map(|(s, _)| s).sum()
}

/// Vertex `i` of `[V·3]` values.
pub(super) fn vertex(v: &[f64], i: u32) -> glam::DVec3 {
    let i = 3 * i as usize;
    glam::DVec3::new(v[i], v[i + 1], v[i + 2])
}

/// Adds `d` to vertex `i`'s gradient.
pub(super) fn add(grad: &mut [f64], i: u32, d: glam::DVec3) {
    let i = 3 * i as usize;
    grad[i] += d.x;
    grad[i + 1] += d.y;
    grad[i + 2] += d.z;
}
