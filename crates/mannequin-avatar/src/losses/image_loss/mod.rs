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
use crate::row_totals::MAX_LEN;

/// The weights of the terms, and where the rendered alpha is.
#[derive(Debug, Clone)]
pub struct ImageLossConfig {
    /// w_c per compared channel (the target's C).
    pub weights: Vec<f32>,
    /// λ_SSIM.
    pub lambda_ssim: f32,
    /// λ_m.
    pub lambda_mask: f32,
    /// The index of the alpha plane in the rendered planes.
    pub alpha_plane: usize,
}

/// Backends that run the fused image loss. The rendered planes are `[K, H, W]` as the splatting
/// op stacks them (the compared channels first, alpha at `alpha_plane`), the target `[C, H, W]`
/// with `C ≤ alpha_plane`, the mask `[H, W]`, all `f32`. Reading the planes in place saves the
/// slices (copies, where a plane is not aligned) and, backward, their zero-filled assembly.
#[backend_extension(Cube, Autodiff)]
pub trait ImageLossBackend: Backend {
    /// The loss `[1]`, the colour MSE `[1]` (the first three channels; not differentiated) and
    /// the SSIM's moments that the backward reads.
    fn image_loss_forward(
        rendered: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>);

    /// The gradient of the rendered planes `[K, H, W]` given the loss's gradient `grad` `[1]`.
    fn image_loss_backward(
        rendered: FloatTensor<Self>,
        target: FloatTensor<Self>,
        mask: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ImageLossConfig,
    ) -> FloatTensor<Self>;
}

/// What the fused loss gives.
pub struct ImageLoss {
    /// The loss `[1]`, differentiable with respect to the rendered planes.
    pub loss: Tensor<1>,
    /// The mean squared error of the first three channels `[1]`, for the PSNR.
    pub colour_mse: Tensor<1>,
}

/// The loss of the rendered planes `rendered` `[K, H, W]` against `target` `[C, H, W]` (its
/// channels compared with the first C planes) and of the plane `config.alpha_plane` against
/// `mask`, on a CubeCL device.
pub fn image_loss(
    rendered: Tensor<3>,
    target: Tensor<3>,
    mask: Tensor<2>,
    config: &ImageLossConfig,
) -> Result<ImageLoss, AvatarError> {
    let [k, h, w] = rendered.dims();
    let [c, th, tw] = target.dims();
    if [th, tw] != [h, w]
        || mask.dims() != [h, w]
        || c < 3
        || c > config.alpha_plane
        || config.alpha_plane >= k
    {
        return Err(AvatarError::Invalid(format!(
            "image loss: rendered planes {:?} (alpha at {}), target {:?} and mask {:?} do not match \
             (want 3 ≤ C ≤ the alpha plane < K and equal H, W)",
            rendered.dims(),
            config.alpha_plane,
            target.dims(),
            mask.dims()
        )));
    }
    if h < TAPS || w < TAPS || config.weights.len() != c || h * w > MAX_LEN {
        return Err(AvatarError::Invalid(format!(
            "image loss: needs {TAPS} ≤ H, W, H·W ≤ {MAX_LEN} and one weight per target channel; \
             got {:?} and {} weights",
            target.dims(),
            config.weights.len()
        )));
    }
    let (loss, colour_mse, _moments) = <Dispatch as ImageLossBackend>::image_loss_forward(
        rendered.into_dispatch(),
        target.into_dispatch(),
        mask.into_dispatch(),
        config.clone(),
    );
    Ok(ImageLoss { loss: Tensor::from_dispatch(loss), colour_mse: Tensor::from_dispatch(colour_mse) })
}
