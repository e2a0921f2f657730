//! Normal consistency, the `L_nc` of Tavatar Eq. 15, as PyTorch3D's `mesh_normal_consistency`:
//! for every pair of faces sharing an edge `(a, b)`, with opposite vertices `c` and `d`,
//! `1 − cos` of the angle between `n₁ = e × u` and `n₂ = w × e` (`e = b − a`, `u = c − a`,
//! `w = d − a`), averaged over the pairs. Built from the shared edge, these normals agree on a
//! flat pair whatever the faces' winding.
//!
//! The cross products are never formed: by the Binet–Cauchy identity
//! `n₁·n₂ = (e·w)(u·e) − (e·e)(u·w)`, `|n₁|² = |e|²|u|² − (e·u)²`, `|n₂|² = |e|²|w|² − (e·w)²`,
//! so six row-wise dot products suffice, which is cheaper on the CPU than component shuffles.

use burn::tensor::Tensor;

use super::rows::{dot, length};
use super::topology::MeshTopology;
use crate::AvatarError;

impl MeshTopology {
    /// Mean over face pairs sharing an edge of `1 − cos(n₁, n₂)`, as `[1]`; 0 when no edge is
    /// shared.
    pub fn normal_consistency(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
        self.check(&vertices)?;
        let Some(hinges) = &self.hinges else {
            return Ok(Tensor::zeros([1], (&vertices.device(), vertices.dtype())));
        };
        let [a, b, c, d] = hinges.clone().map(|idx| vertices.clone().select(0, idx));
        let (e, u, w) = (b - a.clone(), c - a.clone(), d - a);
        let (ee, uu, ww) = (dot(e.clone(), e.clone()), dot(u.clone(), u.clone()), dot(w.clone(), w.clone()));
        let (eu, ew, uw) = (dot(e.clone(), u.clone()), dot(e, w.clone()), dot(u, w));
        let n1_n2 = ew.clone() * eu.clone() - ee.clone() * uw;
        let n1_sq = ee.clone() * uu - eu.clone() * eu;
        let n2_sq = ee * ww - ew.clone() * ew;
        let cos = n1_n2 / (length(n1_sq) * length(n2_sq));
        Ok(cos.neg().mean() + 1.0)
    }
}
