//! 3DGS's view-dependent colour, `max(Σ_k Y_k(d)·c_k + ½, 0)` with `d` the unit direction from
//! the eye to the Gaussian, as one differentiable op with a hand-written backward (Flex and CubeCL).
//! Composed from tensor ops it is ~40 small allocating ops each way over `[G, 9, 3]` tensors,
//! a tenth of a CPU training step; here it is one pass over the Gaussians each way, on the host
//! (Flex) or as one CubeCL kernel launch (wgpu) ([`crate::host_ops`] says where it runs;
//! [`sh_colour_tensors`] is the composition).

mod autodiff;
pub(crate) mod cube;
mod flex;
mod host;
pub(crate) mod kernels;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::{Tensor, TensorData};

/// The camera and the SH degree of one colour evaluation.
#[derive(Clone, Debug)]
pub struct ColourConfig {
    pub eye: [f32; 3],
    /// 0 to 3: each Gaussian has `(degree + 1)²` coefficients per channel.
    pub degree: usize,
}

/// Backends that run the fused colour.
#[backend_extension(Flex, Cube, Autodiff)]
pub trait ColourBackend: Backend {
    /// `[G, 3]` colours of means `[G, 3]` and coefficients `[G, (degree + 1)² · 3]` (basis-major,
    /// then channel, as [`crate::Avatar::sh_coefficients`] stores them).
    fn sh_colour_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        config: ColourConfig,
    ) -> FloatTensor<Self>;

    /// The gradients of the means and the coefficients given the gradient `grad` of the colours.
    fn sh_colour_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ColourConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>);
}

/// The colours `[G, 3]` of `f32` means and SH coefficients on a Flex or wgpu device,
/// differentiable with respect to both.
pub fn sh_colour(means: Tensor<2>, coeffs: Tensor<2>, config: &ColourConfig) -> Tensor<2> {
    Tensor::from_dispatch(<Dispatch as ColourBackend>::sh_colour_forward(
        means.into_dispatch(),
        coeffs.into_dispatch(),
        config.clone(),
    ))
}

/// 3DGS's colour convention: SH value + ½, clamped at zero.
pub fn colour_convention(value: Tensor<2>) -> Tensor<2> {
    (value + 0.5).clamp_min(0.0)
}

/// The same colours composed from tensor ops (degree ≤ 2), for backends without the fused op.
pub fn sh_colour_tensors(
    means: Tensor<2>,
    coeffs: Tensor<2>,
    config: &ColourConfig,
) -> Result<Tensor<2>, mannequin_splat::SplatError> {
    let [g, _] = means.dims();
    let k = mannequin_splat::sh::basis_len(config.degree);
    let eye = Tensor::<2>::from_data(
        TensorData::new(config.eye.to_vec(), [1, 3]),
        (&means.device(), means.dtype()),
    );
    let d = means - eye;
    let d = d.clone() / (d.square().sum_dim(1) + 1e-20).sqrt();
    let basis = mannequin_splat::sh::basis_tensor(config.degree, d)?; // [G, k]
    let value = (basis.unsqueeze_dim::<3>(2) * coeffs.reshape([g, k, 3])).sum_dim(1).reshape([g, 3]);
    Ok(colour_convention(value))
}
