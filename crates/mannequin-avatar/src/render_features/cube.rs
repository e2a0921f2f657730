//! The features on the CubeCL backends: one kernel launch each way, nothing read back. Works in
//! f32; other float types are converted on the way in and out.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::TensorData;

use super::kernels::{features_backward, features_forward};
use super::{FeaturesBackend, FeaturesConfig};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::blur::as_f32;
use crate::sh_colour::cube::sizes;

type B = CubeBackend;

fn rotation(config: &FeaturesConfig, like: &CubeTensor) -> CubeTensor {
    B::float_from_data(TensorData::new(config.rotation.to_vec(), [9]), &like.device)
}

impl FeaturesBackend for CubeBackend {
    fn features_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        normals: FloatTensor<Self>,
        config: FeaturesConfig,
    ) -> FloatTensor<Self> {
        let (n, degree) = sizes(&means, &coeffs, config.colour.degree);
        let (means, back) = as_f32(means);
        let [coeffs, normals] = [coeffs, normals].map(|t| as_f32(t).0);
        let out = empty_f32(vec![n, 6], &means);
        let (count, dim) = per_element(&means, n);
        let [ex, ey, ez] = config.colour.eye;
        features_forward::launch(
            &means.client,
            count,
            dim,
            means.clone().into_buffer_arg(),
            coeffs.into_buffer_arg(),
            normals.into_buffer_arg(),
            rotation(&config, &means).into_buffer_arg(),
            out.clone().into_buffer_arg(),
            u32_of(n),
            ex,
            ey,
            ez,
            degree,
        );
        back(out)
    }

    fn features_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: FeaturesConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let (n, degree) = sizes(&means, &coeffs, config.colour.degree);
        let (means, back) = as_f32(means);
        let [coeffs, grad] = [coeffs, grad].map(|t| as_f32(t).0);
        let d_means = empty_f32(vec![n, 3], &means);
        let d_coeffs = empty_f32(coeffs.shape().to_vec(), &means);
        let d_normals = empty_f32(vec![n, 3], &means);
        let (count, dim) = per_element(&means, n);
        let [ex, ey, ez] = config.colour.eye;
        features_backward::launch(
            &means.client,
            count,
            dim,
            means.clone().into_buffer_arg(),
            coeffs.into_buffer_arg(),
            rotation(&config, &means).into_buffer_arg(),
            grad.into_buffer_arg(),
            d_means.clone().into_buffer_arg(),
            d_coeffs.clone().into_buffer_arg(),
            d_normals.clone().into_buffer_arg(),
            u32_of(n),
            ex,
            ey,
            ez,
            degree,
        );
        (back(d_means), back(d_coeffs), back(d_normals))
    }
}
