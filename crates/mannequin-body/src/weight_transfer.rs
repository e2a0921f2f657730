//! Skinning weights carried from the body to a garment by Gaussian radial basis functions (NGD
//! §3.5): each garment point takes the kernel-weighted mean of the body vertices' weights. Where
//! a garment spans a gap (a skirt between the legs), both sides' vertices lie at similar
//! distances and the point blends their joints, so the garment follows the legs on average
//! instead of tearing along the nearest one.

use glam::Vec3;
use rayon::prelude::*;

/// Beyond this many σ past the nearest body vertex a kernel weighs under e⁻⁹, and is skipped.
const CUTOFF: f32 = 3.0;

/// The kernel's width σ for one garment point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KernelWidth {
    /// One σ (metres) everywhere: a skirt over the gap between the legs blends both legs.
    Fixed(f32),
    /// σ = the point's distance to its nearest body vertex, as NGD writes Q(r) = exp(−r²/m_i²),
    /// floored at this many metres: a point on the body takes that vertex's weights exactly,
    /// and the farther a point stands off, the more body it averages.
    NearestDistance(f32),
}

impl KernelWidth {
    fn sigma(self, nearest: f32) -> f32 {
        match self {
            KernelWidth::Fixed(s) => s,
            KernelWidth::NearestDistance(floor) => nearest.max(floor),
        }
    }
}

/// Weights (N × `joints`, rows summing to one) for `points`, from `body` vertices and their
/// `weights` (V × `joints`), with kernel exp(−(d² − d_min²)/σ²). Measuring
/// against the nearest vertex's distance d_min gives a point far from the body the same blend
/// as a near one, rather than underflowing every kernel to zero.
pub fn transfer_weights(
    body: &[[f32; 3]],
    weights: &[f32],
    joints: usize,
    points: &[[f32; 3]],
    width: KernelWidth,
) -> Vec<f32> {
    assert_eq!(weights.len(), body.len() * joints, "one weight row per body vertex");
    assert!(!body.is_empty(), "a body to take weights from");
    assert!(
        matches!(width, KernelWidth::Fixed(s) | KernelWidth::NearestDistance(s) if s > 0.0),
        "a positive kernel width"
    );
    let body: Vec<Vec3> = body.iter().map(|&p| Vec3::from(p)).collect();
    points
        .par_iter()
        .flat_map_iter(|&p| {
            let p = Vec3::from(p);
            let nearest = body.iter().map(|b| b.distance_squared(p)).fold(f32::INFINITY, f32::min);
            let sigma = width.sigma(nearest.sqrt());
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
        let w = transfer_weights(&body, &weights, 2, &points, KernelWidth::Fixed(sigma));
        assert!(w[0] > 0.98 && (w[0] + w[1] - 1.0).abs() < 1e-6);
        assert!((w[2] - 0.5).abs() < 1e-6 && (w[3] - 0.5).abs() < 1e-6);
        let far = (-((4.0f32 / 9.0 - 1.0 / 9.0) / 0.25)).exp();
        assert!((w[5] / w[4] - far).abs() < 1e-5, "{} vs {far}", w[5] / w[4]);
    }

    /// With σ = the distance to the nearest vertex, a point on a body vertex takes its weights
    /// exactly, however close the next vertex; a point 1 cm off the midpoint's normal blends both
    /// equally; a point 2 cm from vertex 0 and √(2² + 1²) cm from vertex 1 weighs them
    /// 1 : e^{−(5 − 4)/4}.
    #[test]
    fn nearest_distance_width_is_exact_on_the_body() {
        let body = [[0.0, 0.0, 0.0], [0.01, 0.0, 0.0]];
        let weights = [0.7, 0.3, 0.2, 0.8];
        let points = [[0.0, 0.0, 0.0], [0.005, 0.01, 0.0], [0.0, 0.02, 0.0]];
        let w = transfer_weights(&body, &weights, 2, &points, KernelWidth::NearestDistance(1e-4));
        assert_eq!(&w[..2], &[0.7, 0.3]);
        assert!((w[2] - 0.45).abs() < 1e-6 && (w[3] - 0.55).abs() < 1e-6);
        let k = (-0.25f32).exp();
        let expected = (0.7 + k * 0.2) / (1.0 + k);
        assert!((w[4] - expected).abs() < 1e-5 && (w[4] + w[5] - 1.0).abs() < 1e-6, "{} vs {expected}", w[4]);
    }
}
