//! The op on the CubeCL backends (wgpu, CUDA, …). The per-pixel work (compositing and its
//! backward replay) runs as CubeCL kernels on the device. Projection, binning and the
//! per-Gaussian backward run on the host with the CPU code, on inputs read back from the device
//! (a few floats per Gaussian, against width × height × list length for the pixel work).

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::{FloatDType, TensorData, read_sync};
use burn_cubecl::cubecl::prelude::{CubeCount, CubeDim};
use burn_cubecl::kernel::into_contiguous;

use super::host::Inputs;
use super::kernels::{LayoutLaunch, composite_backward, composite_forward};
use super::saved::{WordLayout, encode_prepared};
use super::{SplatBackend, SplatConfig};
use crate::composite_vjp::SCREEN_GRADS;
use crate::render::{prepare, screen_vjp};

fn read(t: FloatTensor<CubeBackend>) -> Vec<f32> {
    read_sync(CubeBackend::float_into_data(t))
        .expect("reading a splat tensor from the device")
        .try_to_vec::<f32>()
        .expect("f32 tensor")
}

fn upload(v: Vec<f32>, shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    CubeBackend::float_from_data(TensorData::new(v, shape), &like.device())
}

fn zeros(shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    CubeBackend::float_zeros(shape.into(), &like.device(), FloatDType::F32)
}

/// Alpha threshold, cap, transmittance floor and background, as the kernels read them.
fn params(config: &SplatConfig, like: &CubeTensor) -> CubeTensor {
    let o = &config.options;
    let mut p = vec![o.alpha_threshold as f32, o.max_alpha as f32, o.min_transmittance as f32];
    p.extend((0..config.channels()).map(|c| o.background.get(c).copied().unwrap_or(0.0) as f32));
    let n = p.len();
    upload(p, vec![n], like)
}

fn launch_layout(l: &WordLayout, config: &SplatConfig) -> LayoutLaunch {
    let u = |v: usize| u32::try_from(v).expect("splat buffers index within u32");
    LayoutLaunch::new(
        u(config.camera.width),
        u(config.camera.height),
        u(l.tiles_x),
        u(l.stride),
        u(l.offsets),
        u(l.ids),
        u(l.rows),
        u(l.last),
    )
}

fn tile_grid(config: &SplatConfig) -> CubeCount {
    let (tx, ty) = config.camera.tiles();
    CubeCount::Static(tx as u32, ty as u32, 1)
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
        let like = means.clone();
        let v = [means, rotations, scales, opacities, colors].map(read);
        let x = Inputs { means: &v[0], rotations: &v[1], scales: &v[2], opacities: &v[3], colors: &v[4] };
        let (prep, _) = prepare(&config.gaussians(&x), &config.camera, &config.options, false)
            .expect("inputs checked by splat_render");
        let (c, h, w) = (config.channels(), config.camera.height, config.camera.width);
        let words = encode_prepared(&prep, w * h);
        let layout = WordLayout::parse(&words).expect("a header just written");
        let n_words = words.len();
        let words = upload(words, vec![n_words], &like);
        let rendered = zeros(vec![c + 2, h, w], &like);
        let last = zeros(vec![w * h], &like);
        composite_forward::launch(
            &like.client,
            tile_grid(&config),
            CubeDim::new_2d(16, 16),
            words.clone().into_buffer_arg(),
            params(&config, &like).into_buffer_arg(),
            rendered.clone().into_buffer_arg(),
            last.clone().into_buffer_arg(),
            launch_layout(&layout, &config),
            c,
        );
        (rendered, Self::float_cat(vec![words, last], 0))
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
        let like = means.clone();
        let shapes: Vec<Vec<usize>> =
            [&means, &rotations, &scales, &opacities, &colors].iter().map(|t| t.shape().to_vec()).collect();
        let v = [means, rotations, scales, opacities, colors].map(read);
        let x = Inputs { means: &v[0], rotations: &v[1], scales: &v[2], opacities: &v[3], colors: &v[4] };
        // The header and the depth order are all the host needs from the saved state.
        let head = read(Self::float_slice(saved.clone(), &[(0..8).into()]));
        let mut layout = WordLayout::parse(&head).expect("the state splat_forward saved");
        let order: Vec<u32> =
            read(Self::float_slice(saved.clone(), &[(layout.order..layout.order + layout.visible).into()]))
                .iter()
                .map(|v| v.to_bits())
                .collect();
        layout.visible = order.len();
        let c = config.channels();
        let slots = SCREEN_GRADS + c;
        let sums = zeros(vec![layout.visible.max(1) * slots], &like);
        composite_backward::launch(
            &like.client,
            tile_grid(&config),
            CubeDim::new_2d(16, 16),
            into_contiguous(saved).into_buffer_arg(),
            params(&config, &like).into_buffer_arg(),
            into_contiguous(rendered).into_buffer_arg(),
            into_contiguous(grad).into_buffer_arg(),
            sums.clone().into_buffer_arg(),
            launch_layout(&layout, &config),
            c,
        );
        let sums = read(sums);
        let d = screen_vjp(&config.gaussians(&x), &config.camera, &order, &[&sums], c);
        let mut d = [d.means, d.rotations, d.scales, d.opacities, d.colors]
            .into_iter()
            .zip(shapes)
            .map(|(v, s)| upload(v, s, &like));
        let mut next = || d.next().expect("five gradients");
        (next(), next(), next(), next(), next())
    }
}
