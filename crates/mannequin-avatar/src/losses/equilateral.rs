//! Equilateral regularisation, Tavatar Eq. 14: per face, the variance of the three edge lengths
//! plus an angular term, so that triangles (whose inradius and edge lengths set the Gaussian
//! scales, Eqs. 8 and 11) stay well shaped.
//!
//! - The angular term is Eq. 14's `Σ_φ (1 − cos φ)²`. Each summand is smallest at φ = 0, but a
//!   triangle's angles sum to 180°, and over triangles the sum is smallest (¾) exactly at the
//!   equilateral one, so it penalises deviations from 60° as the text says: a right isosceles
//!   triangle costs 1.17, a 120°–30°–30° one 2.29.
//! - Eq. 14 sums over faces; we average, so that the weight λ_t = 0.01 does not grow with the
//!   face count. `Var` is the population variance (divide by 3).
//!
//! The variance term carries units of length², so on a metre-scale body it is small next to the
//! dimensionless angular term.

use burn::tensor::Tensor;
use glam::DVec3;

use super::mesh_loss::{HostMesh, HostTerm, add, sum_over_elements, vertex};
use super::regularisers::MeshRegularisers;
use super::rows::{EPS, dot, length};
use crate::AvatarError;

impl MeshRegularisers {
    /// `mean_f [Var(‖e₁‖, ‖e₂‖, ‖e₃‖) + Σ_φ (1 − cos φ)²]` over faces, as `[1]`.
    pub fn equilateral(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
        self.fused_or(HostTerm::Equilateral, vertices, |v| self.equilateral_tensors(v))
    }

    /// [`Self::equilateral`] composed from tensor ops.
    pub fn equilateral_tensors(&self, vertices: Tensor<2>) -> Result<Tensor<1>, AvatarError> {
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
            let off = cos.neg() + 1.0;
            loss = loss + off.clone() * off;
        }
        Ok(loss.mean())
    }
}

/// The loss on the host. Gradients are gathered per edge: `g_l` for each length and `g_E` for
/// each edge vector directly (through the dot products of the cosines), then `∂l/∂E = E/l`.
/// The variance's mean drops out of its gradient (`Σ (l − m) = 0`).
pub(super) fn equilateral_host(mesh: &HostMesh, v: &[f64], grad: Option<&mut [f64]>) -> f64 {
    let faces = &mesh.rings.faces;
    let weight = 1.0 / faces.len() as f64;
    let total = sum_over_elements(faces.len(), mesh.rings.num_vertices, grad, |f, grad| {
        let corners = faces[f];
        let p = corners.map(|i| vertex(v, i));
        let edges = [p[1] - p[0], p[2] - p[1], p[0] - p[2]];
        // Lengths floored as in the tensor form, where the floor has no gradient.
        let squared = edges.map(|e| e.length_squared());
        let lengths = squared.map(|s| if s > EPS * EPS { s.sqrt() } else { EPS });
        let mean = lengths.iter().sum::<f64>() / 3.0;
        let mut loss = lengths.iter().map(|l| (l - mean) * (l - mean)).sum::<f64>() / 3.0;
        let (mut g_l, mut g_e) = (lengths.map(|l| weight * 2.0 / 3.0 * (l - mean)), [DVec3::ZERO; 3]);
        for k in 0..3 {
            let (into, out) = ((k + 2) % 3, k);
            let (li, lo) = (lengths[into], lengths[out]);
            let cos = -edges[into].dot(edges[out]) / (li * lo);
            loss += (1.0 - cos) * (1.0 - cos);
            let gamma = -weight * 2.0 * (1.0 - cos);
            g_e[into] -= gamma / (li * lo) * edges[out];
            g_e[out] -= gamma / (li * lo) * edges[into];
            g_l[into] -= gamma * cos / li;
            g_l[out] -= gamma * cos / lo;
        }
        if let Some(grad) = grad {
            for k in 0..3 {
                let along = if squared[k] > EPS * EPS { edges[k] / lengths[k] } else { DVec3::ZERO };
                let d = g_e[k] + g_l[k] * along;
                // Edge k runs from corner k to corner k + 1.
                add(grad, corners[(k + 1) % 3], d);
                add(grad, corners[k], -d);
            }
        }
        loss
    });
    total * weight
}
