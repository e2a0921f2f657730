//! The renderer's per-Gaussian features as one op on the CubeCL backends: Tavatar's SH colour
//! seen from the eye (3) and the normal turned into camera space (3), `[G, 6]`. Composed (the
//! fused colour, a matrix product and a concatenation) the GPU launches five kernels forward and
//! four backward for them; here one each way. Flex keeps the composition, which the tests hold
//! this op to.

mod autodiff;
mod cube;
mod kernels;

use burn::backend::tensor::FloatTensor;
use burn::backend::{Backend, Dispatch, backend_extension};
use burn::tensor::Tensor;

use crate::sh_colour::ColourConfig;

/// The colour's camera and SH degree, and the world-to-camera rotation (row-major).
#[derive(Clone, Debug)]
pub struct FeaturesConfig {
    pub colour: ColourConfig,
    pub rotation: [f32; 9],
}

/// Backends that run the fused features.
#[backend_extension(Cube, Autodiff)]
pub trait FeaturesBackend: Backend {
    /// `[G, 6]`: colours of means `[G, 3]` and SH coefficients `[G, (degree + 1)² · 3]` (as
    /// [`crate::sh_colour`] reads them), then `R·n` of normals `[G, 3]`.
    fn features_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        normals: FloatTensor<Self>,
        config: FeaturesConfig,
    ) -> FloatTensor<Self>;

    /// The gradients of the means, the coefficients and the normals given the features' `grad`.
    fn features_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: FeaturesConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>);
}

/// The features `[G, 6]` of `f32` means, SH coefficients and normals on a CubeCL device,
/// differentiable with respect to all three.
pub fn render_features(
    means: Tensor<2>,
    coeffs: Tensor<2>,
    normals: Tensor<2>,
    config: &FeaturesConfig,
) -> Tensor<2> {
    Tensor::from_dispatch(<Dispatch as FeaturesBackend>::features_forward(
        means.into_dispatch(),
        coeffs.into_dispatch(),
        normals.into_dispatch(),
        config.clone(),
    ))
}
