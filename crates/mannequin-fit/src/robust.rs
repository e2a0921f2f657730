//! The fits' robust penalty, as a residual the least-squares solver can take.

/// The factor that turns an error vector of length `e` into one whose squared length is the
/// pseudo-Huber penalty ρ(e) = 2δ²(√(1 + (e/δ)²) − 1): quadratic below δ, linear (Eq. 2.12's L1)
/// beyond, and smooth for the solver. Multiply each component of the error by it.
pub fn pseudo_huber_scale(e: f64, delta: f64) -> f64 {
    if e > 1e-12 {
        (2.0 * delta * delta * ((1.0 + (e / delta).powi(2)).sqrt() - 1.0)).sqrt() / e
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scaled_error_squares_to_the_penalty() {
        for e in [1e-3f64, 0.5, 2.0, 40.0] {
            let delta: f64 = 2.0;
            let rho = 2.0 * delta * delta * ((1.0 + (e / delta) * (e / delta)).sqrt() - 1.0);
            let scaled = pseudo_huber_scale(e, delta) * e;
            assert!((scaled * scaled - rho).abs() < 1e-9 * rho.max(1.0), "{e}");
        }
        // Quadratic near zero, linear far out: ρ ≈ e² and ρ ≈ 2δe.
        assert!((pseudo_huber_scale(1e-4, 2.0) - 1.0).abs() < 1e-6);
        assert!(((pseudo_huber_scale(1e4, 2.0) * 1e4).powi(2) / (2.0 * 2.0 * 1e4) - 1.0).abs() < 1e-3);
    }
}
