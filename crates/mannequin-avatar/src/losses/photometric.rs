//! The photometric loss of Tavatar Eqs. 12–13, used for both the RGB and the normal map:
//! `λ · (1 − SSIM) + (1 − λ) · mean |pred − target|`, λ_SSIM = 0.2 in the paper.

use burn::tensor::{Tensor, TensorData};

use super::ssim::ssim_map;
use crate::AvatarError;

/// The paper's weight of the SSIM term.
pub const LAMBDA_SSIM: f64 = 0.2;

/// `λ·(1 − SSIM(pred, target)) + (1 − λ)·mean|pred − target|` of `[C, H, W]` images, as `[1]`.
pub fn photometric(pred: Tensor<3>, target: Tensor<3>, lambda_ssim: f64) -> Result<Tensor<1>, AvatarError> {
    let c = pred.dims()[0];
    photometric_weighted(pred, target, lambda_ssim, &vec![1.0 / c as f64; c])
}

/// Eqs. 12 and 13 in one pass over stacked maps (colour, then normals): channel `c` adds
/// `w_c · [λ·(1 − mean SSIM_c) + (1 − λ)·mean |pred_c − target_c|]`. With `w_c = 1/C` this is
/// [`photometric`]; the trainer weighs three colour channels by 1/3 and three normal channels
/// by λ_n/3, so both losses take one SSIM call and the rendered image is never split.
pub fn photometric_weighted(
    pred: Tensor<3>,
    target: Tensor<3>,
    lambda_ssim: f64,
    channel_weights: &[f64],
) -> Result<Tensor<1>, AvatarError> {
    if !(0.0..=1.0).contains(&lambda_ssim) {
        return Err(AvatarError::Invalid(format!("λ_SSIM must lie in [0, 1], got {lambda_ssim}")));
    }
    let [c, h, w] = pred.dims();
    if channel_weights.len() != c {
        return Err(AvatarError::Invalid(format!(
            "{} channel weights for images of {c} channels",
            channel_weights.len()
        )));
    }
    let weights = TensorData::new(channel_weights.to_vec(), [c, 1]);
    let weights = Tensor::<2>::from_data(weights, (&pred.device(), pred.dtype()));
    let l1 = (pred.clone() - target.clone()).abs().reshape([c, h * w]).mean_dim(1);
    let map = ssim_map(pred, target)?;
    let [_, mh, mw] = map.dims();
    let d_ssim = map.reshape([c, mh * mw]).mean_dim(1).neg() + 1.0;
    Ok(((d_ssim * lambda_ssim + l1 * (1.0 - lambda_ssim)) * weights).sum())
}
