//! The 11-tap Gaussian blur (σ = 1.5) that SSIM's local statistics need, as a differentiable
//! Burn op on Flex (rayon) and CubeCL. It is separable (22 multiply-adds per value instead of
//! 121) and linear, so its backward is its transpose: for a symmetric window that is the same
//! blur with the complementary zero padding, `10 − p` for a forward padding `p`. The fused SSIM
//! op runs the same host and CubeCL blurs inside itself.

mod autodiff;
mod cube;
mod flex;
mod host;

pub(crate) use cube::{as_f32, blur_f32};
pub(crate) use host::{Planes, Sample, blur_rows};

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

use crate::AvatarError;

/// Half-width of the window.
pub const RADIUS: usize = 5;
/// Taps of the window.
pub const TAPS: usize = 2 * RADIUS + 1;
/// Standard deviation of the window, in pixels (Wang et al. 2004).
pub const SIGMA: f64 = 1.5;

/// The normalised window `exp(−d²/2σ²)`, d = −5..5.
pub fn gaussian_window() -> [f64; TAPS] {
    let w: [f64; TAPS] = std::array::from_fn(|i| {
        let d = i as f64 - RADIUS as f64;
        (-d * d / (2.0 * SIGMA * SIGMA)).exp()
    });
    let sum: f64 = w.iter().sum();
    w.map(|v| v / sum)
}

/// Backends that can blur.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait BlurBackend: Backend {
    /// Blurs each `[H, W]` plane of `[N, H, W]` along rows and then columns, reading zeros
    /// `padding` pixels beyond each border: `[N, H + 2p − 10, W + 2p − 10]`, with
    /// `out[y, x] = Σ_ij g_i g_j in[y + i − p, x + j − p]`. `padding ≤ 10`.
    fn gaussian_blur(x: FloatTensor<Self>, padding: usize) -> FloatTensor<Self>;
}

/// The 'valid' blur of every plane of `[N, H, W]` (H, W ≥ 11): `[N, H − 10, W − 10]`, each
/// output the window-weighted sum of the 11×11 pixels around it, as scikit-image's SSIM crops.
pub fn gaussian_blur_valid(x: Tensor<3>) -> Result<Tensor<3>, AvatarError> {
    let [_, h, w] = x.dims();
    if h < TAPS || w < TAPS {
        return Err(AvatarError::Invalid(format!(
            "a 'valid' {TAPS}×{TAPS} blur needs H, W ≥ {TAPS}; got {h}×{w}"
        )));
    }
    Ok(Tensor::from_dispatch(<Dispatch as BlurBackend>::gaussian_blur(x.into_dispatch(), 0)))
}
