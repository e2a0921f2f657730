//! Mean SSIM (Wang et al. 2004) as a differentiable tensor function, the `L_SSIM = 1 − SSIM`
//! of Tavatar Eqs. 12–13. It computes what `mannequin_data::metrics::ssim` (and scikit-image
//! with `gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1`) does:
//! local moments under an 11-tap Gaussian window, `C1 = 0.01²`, `C2 = 0.03²`, the map averaged
//! over the pixels whose window lies inside the image, then over channels. Training and
//! evaluation therefore score the same quantity.
//!
//! It runs every training iteration on images up to 540×540, so it is one fused op with a
//! hand-written backward (Flex and CubeCL): the five moments are blurred straight from the
//! images, and the backward blurs three or four coefficient maps with the transposed window.
//! Built from Burn's elementwise ops instead ([`ssim_with_blur`]), the autodiff graph's
//! elementwise passes cost more than the blurs themselves.

mod autodiff;
mod cube;
mod flex;
mod kernels;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

use super::blur::TAPS;
use crate::AvatarError;

pub(crate) const C1: f64 = 0.01 * 0.01;
pub(crate) const C2: f64 = 0.03 * 0.03;

/// Backends with the fused SSIM op. Inputs are `[C, H, W]` with H, W ≥ 11, of one float type.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait SsimBackend: Backend {
    /// The SSIM map `[C, H − 10, W − 10]`, and the local moments (E[x], E[y], E[x²], E[y²],
    /// E[xy]) that the backward pass reads, laid out as the backend likes.
    fn ssim_forward(x: FloatTensor<Self>, y: FloatTensor<Self>) -> (FloatTensor<Self>, FloatTensor<Self>);

    /// Gradients of `x` and `y` given the gradient `grad` of the map; an input whose gradient is
    /// not wanted gets an empty tensor.
    fn ssim_backward(
        x: FloatTensor<Self>,
        y: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        want_x: bool,
        want_y: bool,
    ) -> (FloatTensor<Self>, FloatTensor<Self>);
}

/// Checks that two `[C, H, W]` images can be compared with an 11×11 window.
fn check_pair(pred: &Tensor<3>, target: &Tensor<3>) -> Result<(), AvatarError> {
    let (a, b) = (pred.dims(), target.dims());
    if a != b {
        return Err(AvatarError::Invalid(format!("SSIM of images of different shapes: {a:?} and {b:?}")));
    }
    let [c, h, w] = a;
    if c == 0 || h < TAPS || w < TAPS {
        return Err(AvatarError::Invalid(format!(
            "SSIM needs [C, H, W] images with C ≥ 1 and H, W ≥ {TAPS}; got {a:?}"
        )));
    }
    let (s, t) = (pred.dtype(), target.dtype());
    if s != t {
        return Err(AvatarError::Invalid(format!(
            "SSIM of images of different float types: {s:?} and {t:?}"
        )));
    }
    Ok(())
}

/// The SSIM map of `[C, H, W]` images (any crop with H, W ≥ 11): `[C, H − 10, W − 10]`, one
/// value per pixel whose window lies inside the image.
pub fn ssim_map(pred: Tensor<3>, target: Tensor<3>) -> Result<Tensor<3>, AvatarError> {
    check_pair(&pred, &target)?;
    let (map, _moments) =
        <Dispatch as SsimBackend>::ssim_forward(pred.into_dispatch(), target.into_dispatch());
    Ok(Tensor::from_dispatch(map))
}

/// Mean SSIM of `[C, H, W]` images (any crop with H, W ≥ 11), as a `[1]` tensor. Identical
/// images score exactly 1.
pub fn ssim(pred: Tensor<3>, target: Tensor<3>) -> Result<Tensor<1>, AvatarError> {
    Ok(ssim_map(pred, target)?.mean())
}

/// The same mean SSIM written with Burn's tensor ops around a caller's 'valid' blur of
/// `[N, H, W]` planes (the blur op, or Burn's convolutions), called only once the images are
/// checked: the independent formulation that the fused op is tested and benchmarked against.
/// Grouped as the fused op groups it, so identical images give exactly 1 here too.
pub fn ssim_with_blur(
    pred: Tensor<3>,
    target: Tensor<3>,
    blur: impl Fn(Tensor<3>) -> Tensor<3>,
) -> Result<Tensor<1>, AvatarError> {
    check_pair(&pred, &target)?;
    let (x, y) = (pred, target);
    // The five local moments E[x], E[y], E[x²], E[y²], E[xy], blurred one by one (concatenating
    // them first costs more than the four extra calls).
    let [mx, my, exx, eyy, exy] =
        [x.clone(), y.clone(), x.clone() * x.clone(), y.clone() * y.clone(), x * y].map(blur);
    let (mx2, my2, mxy) = (mx.clone() * mx.clone(), my.clone() * my.clone(), mx * my);
    let luminance = mxy.clone() * 2.0 + C1;
    let structure = (exy - mxy) * 2.0 + C2;
    let mean_energy = mx2.clone() + my2.clone() + C1;
    let variance = (exx - mx2) + (eyy - my2) + C2;
    Ok((luminance * structure / (mean_energy * variance)).mean())
}
