//! Skinning weights carried from the body to a garment by Gaussian radial basis functions (NGD
//! §3.5): each garment point takes the kernel-weighted mean of the body vertices' weights. Where
//! a garment spans a gap (a skirt between the legs), both sides' vertices lie at similar
//! distances and the point blends their joints, so the garment follows the legs on average
//! instead of tearing along the nearest one.

use glam::Vec3;
use rayon::prelude::*;

/// Beyond this many σ past the nearest body vertex a kernel weighs under e⁻⁹, and is skipped.
const CUTOFF: f32 = 3.0;

/// Weights (N × `joints`, rows summing to one) for `points`, from `body` vertices and their
/// `weights` (V × `joints`), with kernel exp(−(d² − d_min²)/σ²), `sigma` in metres. Measuring
/// against the nearest vertex's distance d_min gives a point far from the body the same blend
/// as a near one, rather than underflowing every kernel to zero.
pub fn transfer_weights(
    body: &[[f32; 3]],
    weights: &[f32],
    joints: usize,
    points: &[[f32; 3]],
    sigma: f32,
) -> Vec<f32> {
    assert_eq!(weights.len(), body.len() * joints, "one weight row per body vertex");
    assert!(!body.is_empty() && sigma > 0.0, "a body and a positive kernel width");
    let body: Vec<Vec3> = body.iter().map(|&p| Vec3::from(p)).collect();
    points
        .par_iter()
        .flat_map_iter(|&p| {
            let p = Vec3::from(p);
            let nearest = body.iter().map(|b| b.distance_squared(p)).fold(f32::INFINITY, f32::min);
            let reach = (nearest.sqrt() + CUTOFF * sigma).powi(2);
            let mut row = vec![0.0f64; joints];
            let mut total = 0.0f64;
            for (b, w) in body.iter().zip(weights.chunks_exact(joints)) {
                let d2 = b.distance_squared(p);
                if d2 > reach {
                    continue;
                }
                let k = (-((d2 - nearest) / (sigma * sigma)) as f64).exp();
                total += k;
                row.iter_mut().zip(w).for_each(|(r, &w)| *r += k * w as f64);
            }
            row.into_iter().map(move |r| (r / total) as f32)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two body vertices, one per joint: a point at the first takes its joint (the other's kernel
    /// is e^{−d²/σ²} ≈ 0); the midpoint takes both equally; a point a third of the way takes
    /// them in the analytic ratio 1 : e^{−((2/3)² − (1/3)²)/σ²}.
    #[test]
    fn blends_by_the_gaussian_kernel() {
        let body = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]];
        let weights = [1.0, 0.0, 0.0, 1.0];
        let sigma = 0.5;
        let points = [[0.0, 0.0, 0.0], [0.5, 0.3, 0.0], [1.0 / 3.0, 0.0, 0.0]];
        let w = transfer_weights(&body, &weights, 2, &points, sigma);
        assert!(w[0] > 0.98 && (w[0] + w[1] - 1.0).abs() < 1e-6);
        assert!((w[2] - 0.5).abs() < 1e-6 && (w[3] - 0.5).abs() < 1e-6);
        let far = (-((4.0f32 / 9.0 - 1.0 / 9.0) / 0.25)).exp();
        assert!((w[5] / w[4] - far).abs() < 1e-5, "{} vs {far}", w[5] / w[4]);
    }
}
