//! The rotation that best turns one centred point set onto another (Kabsch): the SVD of their
//! cross-covariance, with the reflection removed.

use faer::Mat;
use glam::{DMat3, DVec3};

/// R minimising Σ wᵢ |R aᵢ − bᵢ|² over rotations, both sets taken about their weighted means.
/// None when the points do not fix a rotation (fewer than three non-collinear ones).
pub fn best_rotation(a: &[DVec3], b: &[DVec3], w: &[f64]) -> Option<DMat3> {
    let total: f64 = w.iter().sum();
    if total <= 0.0 {
        return None;
    }
    let mean = |p: &[DVec3]| p.iter().zip(w).fold(DVec3::ZERO, |s, (p, &w)| s + w * *p) / total;
    let (ma, mb) = (mean(a), mean(b));
    let h = Mat::<f64>::from_fn(3, 3, |i, j| {
        a.iter().zip(b).zip(w).map(|((p, q), &w)| w * (*p - ma)[i] * (*q - mb)[j]).sum()
    });
    let svd = h.svd().ok()?;
    let s = svd.S().column_vector();
    if s[1] < 1e-9 * s[0].max(1e-300) {
        return None;
    }
    let (u, v) = (svd.U(), svd.V());
    let m = |x: faer::MatRef<f64>| {
        DMat3::from_cols_array_2d(&std::array::from_fn(|c| std::array::from_fn(|r| x[(r, c)])))
    };
    let (u, v) = (m(u), m(v));
    let d = (v * u.transpose()).determinant().signum();
    Some(v * DMat3::from_diagonal(DVec3::new(1.0, 1.0, d)) * u.transpose())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_a_known_rotation() {
        let r = DMat3::from_euler(glam::EulerRot::YXZ, 2.5, -0.4, 0.9);
        let a = [DVec3::X, DVec3::Y, DVec3::new(0.3, -0.2, 1.0), DVec3::new(-1.0, 0.5, 0.2)];
        let b: Vec<DVec3> = a.iter().map(|p| r * *p + DVec3::new(4.0, 5.0, 6.0)).collect();
        let got = best_rotation(&a, &b, &[1.0; 4]).unwrap();
        assert!((got - r).to_cols_array().iter().all(|d| d.abs() < 1e-9), "{got:?}");
    }

    #[test]
    fn collinear_points_fix_no_rotation() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(best_rotation(&a, &a, &[1.0; 3]).is_none());
    }
}
