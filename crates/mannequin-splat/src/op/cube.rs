//! The op on the CubeCL backends (wgpu, CUDA, …).

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::CubeBackend;
use burn::tensor::{TensorData, read_sync};

use super::host::{self, Inputs};
use super::{SplatBackend, SplatConfig};

fn read(t: FloatTensor<CubeBackend>) -> Vec<f32> {
    read_sync(CubeBackend::float_into_data(t))
        .expect("reading a splat input from the device")
        .try_to_vec::<f32>()
        .expect("f32 tensor")
}

impl SplatBackend for CubeBackend {
    fn splat_forward(
        means: FloatTensor<Self>,
        rotations: FloatTensor<Self>,
        scales: FloatTensor<Self>,
        opacities: FloatTensor<Self>,
        colors: FloatTensor<Self>,
        config: SplatConfig,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let device = means.device();
        let v = [means, rotations, scales, opacities, colors].map(read);
        let x = Inputs { means: &v[0], rotations: &v[1], scales: &v[2], opacities: &v[3], colors: &v[4] };
        let (rendered, saved) = host::forward(&x, &config);
        let (c, h, w) = (config.channels(), config.camera.height, config.camera.width);
        let n_saved = saved.len();
        (
            Self::float_from_data(TensorData::new(rendered, vec![c + 2, h, w]), &device),
            Self::float_from_data(TensorData::new(saved, vec![n_saved]), &device),
        )
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
        let device = means.device();
        let shapes: Vec<Vec<usize>> =
            [&means, &rotations, &scales, &opacities, &colors].iter().map(|t| t.shape().to_vec()).collect();
        let v = [means, rotations, scales, opacities, colors].map(read);
        let x = Inputs { means: &v[0], rotations: &v[1], scales: &v[2], opacities: &v[3], colors: &v[4] };
        let [rendered, saved, grad] = [rendered, saved, grad].map(read);
        let d = host::backward(&x, &config, &rendered, &saved, &grad);
        let mut d =
            d.into_iter().zip(shapes).map(|(v, s)| Self::float_from_data(TensorData::new(v, s), &device));
        let mut next = || d.next().expect("five gradients");
        (next(), next(), next(), next(), next())
    }
}
