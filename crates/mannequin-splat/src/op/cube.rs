//! The op on the CubeCL backends (wgpu, CUDA, …). Projection, compositing, the compositing
//! replay and the per-Gaussian backward run as CubeCL kernels on the device. Binning (the depth
//! sort and tile lists) runs on the host with the CPU code: the forward reads back the packed
//! screen-space rows and uploads the lists. The backward reads nothing back.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::{FloatDType, TensorData, read_sync};
use burn_cubecl::cubecl::prelude::{CubeCount, CubeDim};
use burn_cubecl::kernel::into_contiguous;

use super::kernels::{LayoutLaunch, composite_backward, composite_forward};
use super::project_kernels::{camera_words, project_backward, project_forward};
use super::saved::{WordLayout, encode_lists};
use super::{SplatBackend, SplatConfig};
use crate::camera::CameraParams;
use crate::composite::field;
use crate::composite_vjp::SCREEN_GRADS;
use crate::project::Projection;
use crate::tiles::bin;

/// Units per cube for the per-Gaussian kernels.
const GROUP: u32 = 256;

fn read(t: FloatTensor<CubeBackend>) -> Vec<f32> {
    read_sync(CubeBackend::float_into_data(t))
        .expect("reading a splat tensor from the device")
        .try_to_vec::<f32>()
        .expect("f32 tensor")
}

fn upload(v: Vec<f32>, like: &CubeTensor) -> CubeTensor {
    let n = v.len();
    CubeBackend::float_from_data(TensorData::new(v, vec![n]), &like.device())
}

fn zeros(shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    CubeBackend::float_zeros(shape.into(), &like.device(), FloatDType::F32)
}

/// Alpha threshold, cap, transmittance floor and background, as the compositing kernels read them.
fn params(config: &SplatConfig, like: &CubeTensor) -> CubeTensor {
    let o = &config.options;
    let mut p = vec![o.alpha_threshold as f32, o.max_alpha as f32, o.min_transmittance as f32];
    p.extend((0..config.channels()).map(|c| o.background.get(c).copied().unwrap_or(0.0) as f32));
    upload(p, like)
}

fn camera(config: &SplatConfig, like: &CubeTensor) -> CubeTensor {
    upload(camera_words(&CameraParams::new(&config.camera), config.options.alpha_threshold), like)
}

fn u32_of(v: usize) -> u32 {
    u32::try_from(v).expect("splat buffers index within u32")
}

fn launch_layout(l: &WordLayout, config: &SplatConfig) -> LayoutLaunch {
    LayoutLaunch::new(
        u32_of(config.camera.width),
        u32_of(config.camera.height),
        u32_of(l.tiles_x),
        u32_of(l.stride),
        u32_of(l.offsets),
        u32_of(l.ids),
        u32_of(l.rows),
        u32_of(l.last),
    )
}

fn tile_grid(config: &SplatConfig) -> CubeCount {
    let (tx, ty) = config.camera.tiles();
    CubeCount::Static(tx as u32, ty as u32, 1)
}

fn gaussian_grid(n: usize) -> CubeCount {
    CubeCount::Static(u32_of(n).div_ceil(GROUP), 1, 1)
}

/// The screen-space rows read back from the device, in the form the binning takes.
fn projection_of(rows: &[f32], radii: &[f32], stride: usize) -> (Projection<f32>, Vec<f32>) {
    let n = radii.len() / 2;
    let at = |i: usize, f: usize| rows[i * stride + f];
    let projection = Projection {
        means2d: (0..n).flat_map(|i| [at(i, field::MX), at(i, field::MY)]).collect(),
        conics: (0..n).flat_map(|i| [at(i, field::A), at(i, field::B), at(i, field::C)]).collect(),
        depths: (0..n).map(|i| at(i, field::DEPTH)).collect(),
        radii: radii.iter().map(|&r| r.min(u32::MAX as f32) as u32).collect(),
        colors: Vec::new(),
        skipped: 0,
    };
    (projection, (0..n).map(|i| at(i, field::OPACITY)).collect())
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
        let n = means.shape()[0];
        let (c, h, w) = (config.channels(), config.camera.height, config.camera.width);
        let stride = field::COLOR + c;
        let rows = zeros(vec![n * stride], &like);
        let radii = zeros(vec![2 * n], &like);
        if n > 0 {
            project_forward::launch(
                &like.client,
                gaussian_grid(n),
                CubeDim::new_1d(GROUP),
                into_contiguous(means).into_buffer_arg(),
                into_contiguous(rotations).into_buffer_arg(),
                into_contiguous(scales).into_buffer_arg(),
                into_contiguous(opacities).into_buffer_arg(),
                into_contiguous(colors).into_buffer_arg(),
                camera(&config, &like).into_buffer_arg(),
                rows.clone().into_buffer_arg(),
                radii.clone().into_buffer_arg(),
                u32_of(n),
                config.matrices,
                config.sh_degree.unwrap_or(0) as u32,
                config.sh_degree.is_some(),
                config.color_len,
                stride,
            );
        }
        // Binning on the host; the lists name Gaussians by index (the rows stay in index order).
        let (projection, opacity) = projection_of(&read(rows.clone()), &read(radii), stride);
        let tiles = bin(&projection, &opacity, config.options.alpha_threshold, w, h);
        let ids: Vec<u32> = tiles.ids.iter().map(|&r| tiles.order[r as usize]).collect();
        let header =
            [stride, tiles.tiles_x, tiles.tiles_y, 0, tiles.offsets.len(), ids.len(), w * h, n * stride];
        let lists = encode_lists(header, &[], &tiles.offsets, &ids);
        let layout = WordLayout::parse(&lists).expect("a header just written");
        let words = Self::float_cat(vec![upload(lists, &like), rows], 0);
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
        let n = means.shape()[0];
        let shape = |t: &CubeTensor| t.shape().to_vec();
        let d = [&means, &rotations, &scales, &opacities, &colors].map(|t| zeros(shape(t), &like));
        let c = config.channels();
        let head = read(Self::float_slice(saved.clone(), &[(0..8).into()]));
        let layout = WordLayout::parse(&head).expect("the state splat_forward saved");
        let sums = zeros(vec![n.max(1) * (SCREEN_GRADS + c)], &like);
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
        if n > 0 {
            project_backward::launch(
                &like.client,
                gaussian_grid(n),
                CubeDim::new_1d(GROUP),
                into_contiguous(means).into_buffer_arg(),
                into_contiguous(rotations).into_buffer_arg(),
                into_contiguous(scales).into_buffer_arg(),
                into_contiguous(colors).into_buffer_arg(),
                camera(&config, &like).into_buffer_arg(),
                sums.into_buffer_arg(),
                d[0].clone().into_buffer_arg(),
                d[1].clone().into_buffer_arg(),
                d[2].clone().into_buffer_arg(),
                d[3].clone().into_buffer_arg(),
                d[4].clone().into_buffer_arg(),
                u32_of(n),
                config.matrices,
                config.sh_degree.unwrap_or(0) as u32,
                config.sh_degree.is_some(),
                config.color_len,
            );
        }
        let [a, b, s, o, col] = d;
        (a, b, s, o, col)
    }
}
