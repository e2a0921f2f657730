//! The cotangent Laplacian (Pinkall & Polthier 1993; Meyer et al. 2003), the stiffness matrix of
//! piecewise-linear functions on a triangle mesh. NGD's Poisson solve and Tavatar's Laplacian
//! smoothing term are both built on it.
//!
//! Sign convention (the same as libigl's `cotmatrix`): `L_ij = (cot α_ij + cot β_ij) / 2` for an
//! edge ij, `L_ii = −Σ_j L_ij`, so `L` is **negative** semi-definite and `xᵀ L x = −∫|∇x|²`.
//! Factor `−L` (plus constraints or a mass term) when a positive-definite system is needed.

use faer::sparse::{SparseColMat, Triplet};

use crate::area::corners;

/// The V×V cotangent Laplacian of a mesh whose faces index into `positions`.
/// Degenerate (zero-area) faces contribute nothing rather than infinities.
pub fn cotan_laplacian(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> SparseColMat<usize, f64> {
    let mut triplets = Vec::with_capacity(12 * faces.len());
    for &tri in faces {
        let p = corners(positions, tri);
        for k in 0..3 {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let (a, b) = (p[i] - p[k], p[j] - p[k]);
            let sine = a.cross(b).length();
            if sine == 0.0 {
                continue;
            }
            let w = 0.5 * a.dot(b) / sine;
            let (vi, vj) = (tri[i] as usize, tri[j] as usize);
            triplets.extend([
                Triplet::new(vi, vj, w),
                Triplet::new(vj, vi, w),
                Triplet::new(vi, vi, -w),
                Triplet::new(vj, vj, -w),
            ]);
        }
    }
    let n = positions.len();
    SparseColMat::try_new_from_triplets(n, n, &triplets).expect("triplet indices are below the vertex count")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The right isoceles triangle's angles are 90°, 45°, 45°: the hypotenuse gets cot 90° = 0
    /// and each leg gets cot 45° / 2 = 1/2.
    #[test]
    fn right_triangle_weights() {
        let l =
            cotan_laplacian(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], &[[0, 1, 2]]).to_dense();
        let expected = [[-1.0, 0.5, 0.5], [0.5, -0.5, 0.0], [0.5, 0.0, -0.5]];
        for (r, row) in expected.iter().enumerate() {
            for (c, &e) in row.iter().enumerate() {
                assert!((l[(r, c)] - e).abs() < 1e-12, "L[{r},{c}] = {}", l[(r, c)]);
            }
        }
    }

    #[test]
    fn degenerate_face_adds_nothing() {
        let l = cotan_laplacian(&[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[[0, 1, 2]]);
        assert!(l.val().iter().all(|&x| x == 0.0));
    }
}
