//! The op on the CubeCL backends (wgpu, CUDA, …). Everything runs as CubeCL kernels on the
//! device: projection, tile binning (`binning.rs`), compositing, the compositing replay and the
//! per-Gaussian backward. The forward reads back one word (the number of tile entries, to size
//! the lists) and the backward the header of the saved state; no per-Gaussian data leaves the
//! device.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::FloatDType;

use burn_cubecl::cubecl::prelude::{CubeCount, CubeDim};
use burn_cubecl::kernel::into_contiguous;

use super::binning::bin;
use super::device_buffers::{buffer, empty, u32_of, units_dim, units_grid, upload, zeros};
use super::kernels::{LayoutLaunch, composite_backward, composite_forward, pack_state};
use super::project_kernels::{camera_words, project_backward, project_forward};
use super::saved::{SKIPPED, WordLayout, size_words};
use super::{SplatBackend, SplatConfig};
use crate::camera::CameraParams;
use crate::composite::field;
use crate::composite_vjp::SCREEN_GRADS;

/// Alpha threshold, cap, transmittance floor and background, as the compositing kernels read them.
fn params(config: &SplatConfig, like: &CubeTensor) -> CubeTensor {
    let o = &config.options;
    let mut p = vec![o.alpha_threshold as f32, o.max_alpha as f32, o.min_transmittance as f32];
    p.extend((0..config.channels()).map(|c| o.background.get(c).copied().unwrap_or(0.0) as f32));
    upload(p, like)
}

fn camera(config: &SplatConfig, like: &CubeTensor) -> CubeTensor {
    upload(camera_words(&CameraParams::new(&config.camera), &config.options), like)
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

/// The projected Gaussians: packed rows (index order, `stride` words each), radii (0: not drawn;
/// one per axis) and the count of Gaussians skipped for a NaN or infinite parameter (one `f32`).
pub(super) struct Projected {
    pub rows: CubeTensor,
    pub radii: CubeTensor,
    pub skipped: CubeTensor,
    pub stride: usize,
}

pub(super) fn project(inputs: [CubeTensor; 5], config: &SplatConfig) -> Projected {
    let [means, rotations, scales, opacities, colors] = inputs;
    let like = means.clone();
    let n = means.shape()[0];
    let stride = field::COLOR + config.channels();
    // `project_forward` writes every row and radius; the count starts at zero.
    let rows = buffer(n * stride, &like);
    let radii = buffer(2 * n, &like);
    let skipped = upload(vec![0.0], &like);
    if n > 0 {
        project_forward::launch(
            &like.client,
            units_grid(n),
            units_dim(),
            into_contiguous(means).into_buffer_arg(),
            into_contiguous(rotations).into_buffer_arg(),
            into_contiguous(scales).into_buffer_arg(),
            into_contiguous(opacities).into_buffer_arg(),
            into_contiguous(colors).into_buffer_arg(),
            camera(config, &like).into_buffer_arg(),
            rows.clone().into_buffer_arg(),
            radii.clone().into_buffer_arg(),
            skipped.clone().into_buffer_arg(),
            u32_of(n),
            config.matrices,
            config.sh_degree.unwrap_or(0) as u32,
            config.sh_degree.is_some(),
            config.color_len,
            stride,
        );
    }
    Projected { rows, radii, skipped, stride }
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
        let p = project([means, rotations, scales, opacities, colors], &config);
        let tiles = bin(&p.rows, &p.radii, n, p.stride, &config);
        let (tiles_x, tiles_y) = config.camera.tiles();
        let n_offsets = tiles_x * tiles_y + 1;
        let sizes = [p.stride, tiles_x, tiles_y, 0, n_offsets, tiles.n_ids, w * h, n * p.stride];
        let head = size_words(sizes);
        let layout = WordLayout::parse(&head).expect("sizes just written");
        // A second forward on one config would leave the first header: never, see the field.
        let _ = config.header.set(head.clone());
        let words = buffer(layout.last + w * h, &like);
        let ids = tiles.ids.unwrap_or_else(|| tiles.offsets.clone());
        pack_state::launch(
            &like.client,
            units_grid(layout.last),
            units_dim(),
            upload(head, &like).into_buffer_arg(),
            p.skipped.into_buffer_arg(),
            tiles.offsets.into_buffer_arg(),
            ids.into_buffer_arg(),
            p.rows.into_buffer_arg(),
            words.clone().into_buffer_arg(),
            launch_layout(&layout, &config),
            u32_of(SKIPPED),
        );
        // The compositing writes every pixel of both.
        let rendered = Self::float_empty([c + 2, h, w].into(), &like.device, FloatDType::F32);
        composite_forward::launch(
            &like.client,
            tile_grid(&config),
            CubeDim::new_2d(16, 16),
            words.clone().into_buffer_arg(),
            params(&config, &like).into_buffer_arg(),
            rendered.clone().into_buffer_arg(),
            launch_layout(&layout, &config),
            c,
        );
        (rendered, words)
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
        // `project_backward` writes every word of these.
        let d = [&means, &rotations, &scales, &opacities, &colors].map(|t| empty(shape(t), &like));
        let c = config.channels();
        let head = config.header.get().expect("splat_forward wrote the header on this config").clone();
        let layout = WordLayout::parse(&head).expect("the state splat_forward saved");
        // Pixels add into these.
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
                units_grid(n),
                units_dim(),
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
