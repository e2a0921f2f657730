//! Equilateral regularisation, Tavatar Eq. 14: per face, the variance of the three edge lengths
//! plus an angular term, so that triangles (whose inradius and edge lengths set the Gaussian
//! scales, Eqs. 8 and 11) stay well shaped.
//!
//! Two readings of Eq. 14, both deliberate:
//! - The angular term is written `Σ_φ (1 − cos φ)²`, which is zero at φ = 0, not at 60°; the text
//!   says it "penalizes deviations from 60°". We implement that intent: `Σ_φ (cos φ − ½)²`,
//!   zero exactly for an equilateral triangle.
//! - Eq. 14 sums over faces; we average, so that the weight λ_t = 0.01 does not grow with the
//!   face count. `Var` is the population variance (divide by 3).
//!
//! The variance term carries units of length², so on a metre-scale body it is small next to the
//! dimensionless angular term.

use burn::tensor::Tensor;

use super::rows::{dot, length};
use super::topology::MeshTopology;
use crate::AvatarError;

/// `cos 60°`.
const COS_60: f64 = 0.5;

impl MeshTopology {
    /// `mean_f [Var(‖e₁‖, ‖e₂‖, ‖e₃‖) + Σ_φ (cos φ − ½)²]` over faces, as `[1]`.
    pub fn equilateral(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
        self.check(&vertices)?;
        let [v0, v1, v2] = self.face_corners(&vertices);
        // Edges around the face; the angle at a corner lies between the edge in and the edge out.
        let edges = [v1.clone() - v0.clone(), v2.clone() - v1, v0 - v2];
        let lengths = edges.clone().map(|e| length(dot(e.clone(), e)));
        let [l0, l1, l2] = lengths.clone();
        let mean = (l0.clone() + l1.clone() + l2.clone()) / 3.0;
        let deviation = |l: Tensor<2>| {
            let d = l - mean.clone();
            d.clone() * d
        };
        let variance = (deviation(l0) + deviation(l1) + deviation(l2)) / 3.0;
        let mut loss = variance;
        for k in 0..3 {
            let (into, out) = ((k + 2) % 3, k);
            let cos = dot(edges[into].clone(), edges[out].clone()).neg()
                / (lengths[into].clone() * lengths[out].clone());
            let off = cos - COS_60;
            loss = loss + off.clone() * off;
        }
        Ok(loss.mean())
    }
}
