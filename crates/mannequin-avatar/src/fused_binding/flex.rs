//! The op on Flex: the host passes run on the tensors' own buffers.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::tensor::TensorData;

use super::{BindConfig, BindingBackend, PACKED, host};
use crate::host_ops::contiguous;

const LAYOUT: &str = "binding tensors are f32 (`bind` takes the avatar's f32 vertices)";

impl BindingBackend for Flex {
    fn tavatar_bind_forward(vertices: FloatTensor<Self>, config: BindConfig) -> FloatTensor<Self> {
        let v = contiguous(vertices);
        let out = host::forward(v.as_slice::<f32>().expect(LAYOUT), &config);
        FlexTensor::from_data(TensorData::new(out, [config.num_gaussians() * PACKED]))
    }

    fn tavatar_bind_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: BindConfig,
    ) -> FloatTensor<Self> {
        let (v, g) = (contiguous(vertices), contiguous(grad));
        let d =
            host::backward(v.as_slice::<f32>().expect(LAYOUT), g.as_slice::<f32>().expect(LAYOUT), &config);
        FlexTensor::from_data(TensorData::new(d, [config.mesh.num_vertices, 3]))
    }
}
