//! The op on Flex: the CPU renderer runs on the tensors' own buffers.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::tensor::TensorData;

use super::config::Inputs;
use super::host;
use super::{SplatBackend, SplatConfig};

/// Contiguous `f32` views of Flex tensors (converting only when a tensor is strided).
fn contiguous(t: FlexTensor) -> FlexTensor {
    if t.is_contiguous() { t } else { t.to_contiguous() }
}

fn values(t: &FlexTensor) -> &[f32] {
    t.as_slice::<f32>().expect("splat tensors are contiguous f32")
}

fn tensor(v: Vec<f32>, shape: Vec<usize>) -> FlexTensor {
    FlexTensor::from_data(TensorData::new(v, shape))
}

impl SplatBackend for Flex {
    fn splat_forward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let t = [means, rotations, scales, opacities, colors].map(contiguous);
        let x = Inputs {
            means: values(&t[0]),
            rotations: values(&t[1]),
            scales: values(&t[2]),
            opacities: values(&t[3]),
            colors: values(&t[4]),
        };
        let (rendered, saved) = host::forward(&x, &config);
        let (c, h, w) = (config.channels(), config.camera.height, config.camera.width);
        let n_saved = saved.len();
        (tensor(rendered, vec![c + 2, h, w]), tensor(saved, vec![n_saved]))
    }

    fn splat_backward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        rendered: FloatTensor<Self>,
        saved: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>, FloatTensor<Self>) {
        let t = [means, rotations, scales, opacities, colors].map(contiguous);
        let shapes: Vec<Vec<usize>> = t.iter().map(|t| t.layout().shape().to_vec()).collect();
        let x = Inputs {
            means: values(&t[0]),
            rotations: values(&t[1]),
            scales: values(&t[2]),
            opacities: values(&t[3]),
            colors: values(&t[4]),
        };
        let [rendered, saved, grad] = [rendered, saved, grad].map(contiguous);
        let d = host::backward(&x, &config, values(&rendered), values(&saved), values(&grad));
        let mut d = d.into_iter().zip(shapes).map(|(v, s)| tensor(v, s));
        let mut next = || d.next().expect("five gradients");
        (next(), next(), next(), next(), next())
    }
}
