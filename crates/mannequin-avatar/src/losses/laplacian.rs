//! Uniform Laplacian smoothness, the `L_lap` of Tavatar Eq. 15: each vertex should sit at the
//! mean of its one-ring. It reads any `[V, 3]` field, so it applies to positions or to the
//! offset field `ΔV` of Eq. 4 alike.

use burn::tensor::{IndexingUpdateOp, Tensor};

use super::topology::MeshTopology;
use crate::AvatarError;

impl MeshTopology {
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
        let delta = self.laplacian_vectors(vertices)?;
        Ok((delta.clone() * delta).sum() / self.num_connected as f64)
    }
}
