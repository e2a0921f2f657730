//! Uniform Laplacian smoothness, the `L_lap` of Tavatar Eq. 15: each vertex should sit at the
//! mean of its one-ring. It reads any `[V, 3]` field, so it applies to positions or to the
//! offset field `ΔV` of Eq. 4 alike.

use burn::tensor::{IndexingUpdateOp, Tensor};
use glam::DVec3;
use rayon::prelude::*;

use super::mesh_loss::{HostMesh, HostTerm, vertex};
use super::regularisers::MeshRegularisers;
use crate::AvatarError;

impl MeshRegularisers {
    /// `δ_i = v_i − (1/|N(i)|) Σ_{j∈N(i)} v_j` per vertex, `[V, 3]`; 0 for isolated vertices.
    pub fn laplacian_vectors(&self, vertices: Tensor<2>) -> Result<Tensor<2>, AvatarError> {
        self.check(&vertices)?;
        let dtype = vertices.dtype();
        let neighbour_sum = vertices.zeros_like().select_assign(
            0,
            self.neighbour_to.clone(),
            vertices.clone().select(0, self.neighbour_from.clone()),
            IndexingUpdateOp::Add,
        );
        Ok(vertices * self.connected.clone().cast(dtype) - neighbour_sum / self.degree.clone().cast(dtype))
    }

    /// `mean_i ‖δ_i‖²` over the vertices that have neighbours, as `[1]`. The squared norm (not
    /// PyTorch3D's plain norm) keeps the loss smooth where δ = 0.
    pub fn laplacian(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
        self.fused_or(HostTerm::Laplacian, vertices, |v| self.laplacian_tensors(v))
    }

    /// [`Self::laplacian`] composed from tensor ops.
    pub fn laplacian_tensors(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
        let delta = self.laplacian_vectors(vertices)?;
        Ok((delta.clone() * delta).sum() / self.num_connected as f64)
    }
}

/// δ_i of every vertex, from the one-rings.
fn deltas(mesh: &HostMesh, v: &[f64]) -> Vec<DVec3> {
    let t = &mesh.rings;
    (0..t.num_vertices as u32)
        .into_par_iter()
        .map(|i| {
            let ring = t.ring(i as usize);
            if ring.is_empty() {
                return DVec3::ZERO;
            }
            vertex(v, i) - ring.iter().map(|&j| vertex(v, j)).sum::<DVec3>() / ring.len() as f64
        })
        .collect()
}

/// The loss on the host, with `∂L/∂v_k = (2/N)(δ_k − Σ_{i∈N(k)} δ_i/|N(i)|)` (rings are
/// symmetric, so each vertex gathers from its own ring).
pub(super) fn laplacian_host(mesh: &HostMesh, v: &[f64], grad: Option<&mut [f64]>) -> f64 {
    let delta = deltas(mesh, v);
    let scale = 1.0 / mesh.num_connected as f64;
    if let Some(grad) = grad {
        let t = &mesh.rings;
        grad.par_chunks_mut(3).enumerate().for_each(|(k, g)| {
            let pulled: DVec3 =
                t.ring(k).iter().map(|&i| delta[i as usize] / t.ring(i as usize).len() as f64).sum();
            g.copy_from_slice(&(2.0 * scale * (delta[k] - pulled)).to_array());
        });
    }
    delta.iter().map(|d| d.length_squared()).sum::<f64>() * scale
}
