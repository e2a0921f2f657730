//! The op on Flex: the host passes run on the tensors' own buffers.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::tensor::TensorData;

use mannequin_splat::sh::basis_len;

use super::{ColourBackend, ColourConfig, host};
use crate::host_ops::contiguous;

const LAYOUT: &str = "colour tensors are f32 (the avatar's parameters and means)";

impl ColourBackend for Flex {
    fn sh_colour_forward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        config: ColourConfig,
    ) -> FloatTensor<Self> {
        let (m, c) = (contiguous(means), contiguous(coeffs));
        let m = m.as_slice::<f32>().expect(LAYOUT);
        let out = host::forward(m, c.as_slice::<f32>().expect(LAYOUT), &config);
        FlexTensor::from_data(TensorData::new(out, [m.len() / 3, 3]))
    }

    fn sh_colour_backward(
        means: FloatTensor<Self>,
        coeffs: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: ColourConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let (m, c, g) = (contiguous(means), contiguous(coeffs), contiguous(grad));
        let (m, c) = (m.as_slice::<f32>().expect(LAYOUT), c.as_slice::<f32>().expect(LAYOUT));
        let (dm, dc) = host::backward(m, c, g.as_slice::<f32>().expect(LAYOUT), &config);
        let n = m.len() / 3;
        let k3 = 3 * basis_len(config.degree);
        (
            FlexTensor::from_data(TensorData::new(dm, [n, 3])),
            FlexTensor::from_data(TensorData::new(dc, [n, k3])),
        )
    }
}
