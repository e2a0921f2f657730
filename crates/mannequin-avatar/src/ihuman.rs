//! iHuman's binding (supplement §1.2): one Gaussian at each face centroid, its frame the face's
//! (normal, first edge, their cross product) turned in the face plane by a learned complex
//! number, with learned in-plane scales and a 1 mm normal scale.

use burn::tensor::Tensor;

use crate::canonical::Canonical;
use crate::mesh_gaussians::{Faces, GaussianGeometry, MeshIndex, normalise};

/// s1, the scale along the normal: 1 mm.
pub const NORMAL_SCALE: f64 = 1e-3;

/// Centroid Gaussians (Eqs. 1–6) of posed vertices, with `rotation` [F, 2] = (x, y) of the
/// complex in-plane rotation (normalised here) and `log_scales` [F, 2] = log (s2, s3).
pub fn centroid_gaussians(
    vertices: &Tensor<2>,
    index: &MeshIndex,
    rotation: Tensor<2>,
    log_scales: Tensor<2>,
) -> GaussianGeometry {
    let faces = Faces::of(vertices, index);
    let [a, b, c] = faces.corners;
    let means = (a + b + c) / 3.0;
    let n = normalise(faces.cross); // R0, Eq. 2
    let r1 = normalise(faces.edge_ab); // Eq. 3
    let r2 = normalise(n.clone().cross(r1.clone(), 1)); // Eq. 4
    let z = normalise(rotation);
    let (cos, sin) = (z.clone().narrow(1, 0, 1), z.narrow(1, 1, 1));
    let t1 = r1.clone() * cos.clone() + r2.clone() * sin.clone();
    let t2 = r2 * cos - r1 * sin;
    let eps = log_scales.clone().narrow(1, 0, 1).zeros_like() + NORMAL_SCALE;
    GaussianGeometry {
        means,
        frames: Tensor::stack(vec![t1, t2, n.clone()], 2),
        scales: Tensor::cat(vec![log_scales.exp(), eps], 1),
        normals: n,
    }
}

/// Canonical face centroids: the colour encoder's inputs.
pub fn face_centroids(c: &Canonical) -> Vec<[f32; 3]> {
    c.faces
        .iter()
        .map(|f| {
            let p: Vec<[f32; 3]> = f.iter().map(|&i| c.vertices[i as usize]).collect();
            [0, 1, 2].map(|k| (p[0][k] + p[1][k] + p[2][k]) / 3.0)
        })
        .collect()
}
