//! The per-face gradient of piecewise-linear functions: NGD's Jacobians are this operator applied
//! to vertex positions, and its Poisson solve is `Gᵀ A G` with A the face areas.

use faer::sparse::{SparseColMat, Triplet};

use crate::area::corners;

/// The 3F×V gradient operator: `(G x)[3f + d]` is component d of the gradient, on face f, of the
/// linear interpolant of the vertex values x. Rows are face-major (libigl's `grad` orders them
/// coordinate-major, `d F + f`), so a face's gradient is three consecutive entries.
/// Degenerate faces get zero rows.
pub fn gradient_operator(positions: &[[f32; 3]], faces: &[[u32; 3]]) -> SparseColMat<usize, f64> {
    let mut triplets = Vec::with_capacity(9 * faces.len());
    for (f, &tri) in faces.iter().enumerate() {
        let p = corners(positions, tri);
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let n2 = n.length_squared();
        if n2 == 0.0 {
            continue;
        }
        for k in 0..3 {
            // ∇φ_k is perpendicular to the opposite edge, pointing into the triangle, with length
            // 1 / height: N × e / |N|², where |N| is twice the area.
            let g = n.cross(p[(k + 2) % 3] - p[(k + 1) % 3]) / n2;
            for (d, x) in g.to_array().into_iter().enumerate() {
                triplets.push(Triplet::new(3 * f + d, tri[k] as usize, x));
            }
        }
    }
    SparseColMat::try_new_from_triplets(3 * faces.len(), positions.len(), &triplets)
        .expect("triplet indices are below the face and vertex counts")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A linear function's gradient is exact on every face: x ↦ a·x has gradient a (in-plane).
    #[test]
    fn linear_function_has_its_own_gradient() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.2, 0.0], [0.3, 1.1, 0.0], [1.4, 1.3, 0.0]];
        let f = [[0, 1, 2], [1, 3, 2]];
        let g = gradient_operator(&p, &f).to_dense();
        let a = [0.7, -1.9, 0.0];
        let values: Vec<f64> = p.iter().map(|q| (0..3).map(|d| a[d] * q[d] as f64).sum()).collect();
        for row in 0..6 {
            let got: f64 = (0..4).map(|v| g[(row, v)] * values[v]).sum();
            assert!((got - a[row % 3]).abs() < 1e-6, "row {row}: {got}");
        }
    }
}
