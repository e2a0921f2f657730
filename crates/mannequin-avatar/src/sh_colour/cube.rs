//! The colour on the CubeCL backends (wgpu, CUDA, …): one kernel launch each way, nothing read
//! back. Works in f32; other float types are converted on the way in and out.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::FloatDType;
use mannequin_splat::sh::{MAX_DEGREE, basis_len};

use super::kernels::{colour_backward, colour_forward};
use super::{ColourBackend, ColourConfig};
use crate::cube_launch::{per_element, u32_of};
use crate::losses::blur::as_f32;

type B = CubeBackend;

/// The Gaussian count and the comptime degree, checked against the coefficients' width.
pub(crate) fn sizes(means: &CubeTensor, coeffs: &CubeTensor, degree: usize) -> (usize, u32) {
    assert!(degree <= MAX_DEGREE, "SH degree {degree} above {MAX_DEGREE}");
    let n = means.shape()[0];
    assert_eq!(coeffs.shape().to_vec(), [n, 3 * basis_len(degree)], "SH coefficients' shape");
    (n, u32::try_from(degree).expect("degree ≤ 3"))
}

impl ColourBackend for CubeBackend {
    fn sh_colour_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        config: ColourConfig,
    ) -> FloatTensor<Self> {
        let (n, degree) = sizes(&means, &coeffs, config.degree);
        let (means, back) = as_f32(means);
        let (coeffs, _) = as_f32(coeffs);
        let out = B::float_empty([n, 3].into(), &means.device, FloatDType::F32);
        let (count, dim) = per_element(&means, n);
        let [ex, ey, ez] = config.eye;
        colour_forward::launch(
            &means.client,
            count,
            dim,
            means.clone().into_buffer_arg(),
            coeffs.into_buffer_arg(),
            out.clone().into_buffer_arg(),
            u32_of(n),
            ex,
            ey,
            ez,
            degree,
        );
        back(out)
    }

    fn sh_colour_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ColourConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let (n, degree) = sizes(&means, &coeffs, config.degree);
        let (means, back) = as_f32(means);
        let (coeffs, _) = as_f32(coeffs);
        let (grad, _) = as_f32(grad);
        let d_means = B::float_empty([n, 3].into(), &means.device, FloatDType::F32);
        let d_coeffs = B::float_empty(coeffs.shape(), &means.device, FloatDType::F32);
        let (count, dim) = per_element(&means, n);
        let [ex, ey, ez] = config.eye;
        colour_backward::launch(
            &means.client,
            count,
            dim,
            means.clone().into_buffer_arg(),
            coeffs.into_buffer_arg(),
            grad.into_buffer_arg(),
            d_means.clone().into_buffer_arg(),
            d_coeffs.clone().into_buffer_arg(),
            u32_of(n),
            ex,
            ey,
            ez,
            degree,
        );
        (back(d_means), back(d_coeffs))
    }
}
