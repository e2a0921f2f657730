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

use super::mesh_loss::{HostMesh, HostTerm, add, sum_over_elements, vertex};
use super::regularisers::MeshRegularisers;
use super::rows::{EPS, dot, length};
use crate::AvatarError;

impl MeshRegularisers {
    /// Mean over face pairs sharing an edge of `1 − cos(n₁, n₂)`, as `[1]`; 0 when no edge is
    /// shared.
    pub fn normal_consistency(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
        self.fused_or(HostTerm::NormalConsistency, vertices, |v| self.normal_consistency_tensors(v))
    }

    /// [`Self::normal_consistency`] composed from tensor ops.
    pub fn normal_consistency_tensors(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
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

/// The loss on the host. Here the normals are formed (`n₁ = e × u`, `n₂ = w × e`, in f64), and
/// `∂cos/∂n₁ = n₂/(|n₁||n₂|) − cos·n₁/|n₁|²` (likewise for `n₂`) is taken back through the cross
/// products: `∂(n₁·g)/∂e = u × g`, `∂(n₁·g)/∂u = g × e`, `∂(n₂·g)/∂w = e × g`, `∂(n₂·g)/∂e = g × w`.
pub(super) fn normal_consistency_host(mesh: &HostMesh, v: &[f64], grad: Option<&mut [f64]>) -> f64 {
    let h = mesh.hinges.len();
    if h == 0 {
        if let Some(g) = grad {
            g.fill(0.0);
        }
        return 0.0;
    }
    let weight = -1.0 / h as f64;
    let cosines = sum_over_elements(h, mesh.rings.num_vertices, grad, |k, grad| {
        let [a, b, c, d] = mesh.hinges[k];
        let p = vertex(v, a);
        let (e, u, w) = (vertex(v, b) - p, vertex(v, c) - p, vertex(v, d) - p);
        let (n1, n2) = (e.cross(u), w.cross(e));
        // Lengths floored as in the tensor form, where the floor has no gradient.
        let floored = |n: glam::DVec3| {
            let s = n.length_squared();
            if s > EPS * EPS { (s.sqrt(), n / s) } else { (EPS, glam::DVec3::ZERO) }
        };
        let ((l1, dl1), (l2, dl2)) = (floored(n1), floored(n2));
        let cos = n1.dot(n2) / (l1 * l2);
        if let Some(grad) = grad {
            let g1 = weight * (n2 / (l1 * l2) - cos * dl1);
            let g2 = weight * (n1 / (l1 * l2) - cos * dl2);
            let (de, du, dw) = (u.cross(g1) + g2.cross(w), g1.cross(e), e.cross(g2));
            add(grad, a, -(de + du + dw));
            add(grad, b, de);
            add(grad, c, du);
            add(grad, d, dw);
        }
        cos
    });
    1.0 + weight * cosines
}
