//! The view loss's image terms as one op on the CubeCL backends: Eqs. 12–13 over stacked colour
//! and normal channels, `Σ_c w_c·[λ·(1 − SSIM_c) + (1 − λ)·mean|pred_c − target_c|]`, plus the
//! mask term `λ_m·mean|α − mask|`. Composed from Burn's ops (`photometric_weighted` and the mask
//! term), a GPU runs ~60 small kernels forward and twice that backward for them; here the SSIM
//! op's kernels, one kernel of per-pixel shares and one sum forward, and three kernels besides
//! the SSIM's backward. Flex keeps the composition, the reference this op is held to.

mod autodiff;
mod cube;
mod kernels;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

use super::blur::TAPS;
use crate::AvatarError;

/// The weights of the terms.
#[derive(Debug, Clone)]
pub struct ImageLossConfig {
    /// w_c per channel.
    pub weights: Vec<f32>,
    /// λ_SSIM.
    pub lambda_ssim: f32,
    /// λ_m.
    pub lambda_mask: f32,
}

/// Backends that run the fused image loss. Images are `[C, H, W]`, masks `[H, W]`, all `f32`.
#[backend_extension(Cube, Autodiff)]
pub trait ImageLossBackend: Backend {
    /// The loss `[1]`, and the SSIM's moments that the backward reads.
    fn image_loss_forward(
        pred: FloatTensor<Self>,
        alpha: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>);

    /// The gradients of `pred` and `alpha` given the loss's gradient `grad` `[1]`.
    #[allow(clippy::too_many_arguments)]
    fn image_loss_backward(
        pred: FloatTensor<Self>,
        alpha: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>);
}

/// The loss of rendered `pred` `[C, H, W]` and `alpha` `[H, W]` against `target` and `mask`,
/// differentiable with respect to `pred` and `alpha`, on a CubeCL device.
pub fn image_loss(
    pred: Tensor<3>,
    alpha: Tensor<2>,
    target: Tensor<3>,
    mask: Tensor<2>,
    config: &ImageLossConfig,
) -> Result<Tensor<1>, AvatarError> {
    let [c, h, w] = pred.dims();
    if target.dims() != [c, h, w] || alpha.dims() != [h, w] || mask.dims() != [h, w] {
        return Err(AvatarError::Invalid(format!(
            "image loss: prediction {:?}, target {:?}, alpha {:?} and mask {:?} do not match",
            pred.dims(),
            target.dims(),
            alpha.dims(),
            mask.dims()
        )));
    }
    if h < TAPS || w < TAPS || config.weights.len() != c {
        return Err(AvatarError::Invalid(format!(
            "image loss: needs H, W ≥ {TAPS} and one weight per channel; got {:?} and {} weights",
            pred.dims(),
            config.weights.len()
        )));
    }
    let (loss, _moments) = <Dispatch as ImageLossBackend>::image_loss_forward(
        pred.into_dispatch(),
        alpha.into_dispatch(),
        target.into_dispatch(),
        mask.into_dispatch(),
        config.clone(),
    );
    Ok(Tensor::from_dispatch(loss))
}
