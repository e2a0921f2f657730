//! The photometric loss of Tavatar Eqs. 12–13, used for both the RGB and the normal map:
//! `λ · (1 − SSIM) + (1 − λ) · mean |pred − target|`, λ_SSIM = 0.2 in the paper.

use burn::tensor::Tensor;

use super::ssim::ssim;
use crate::AvatarError;

/// The paper's weight of the SSIM term.
pub const LAMBDA_SSIM: f64 = 0.2;

/// `λ·(1 − SSIM(pred, target)) + (1 − λ)·mean|pred − target|` of `[C, H, W]` images, as `[1]`.
pub fn photometric(pred: Tensor<3>, target: Tensor<3>, lambda_ssim: f64) -> Result<Tensor<1>, AvatarError> {
    if !(0.0..=1.0).contains(&lambda_ssim) {
        return Err(AvatarError::Invalid(format!("λ_SSIM must lie in [0, 1], got {lambda_ssim}")));
    }
    let l1 = (pred.clone() - target.clone()).abs().mean();
    let d_ssim = ssim(pred, target)?.neg() + 1.0;
    Ok(d_ssim * lambda_ssim + l1 * (1.0 - lambda_ssim))
}
