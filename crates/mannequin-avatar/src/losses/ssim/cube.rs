//! The fused SSIM on the CubeCL backends: the moments through the blur kernel, the per-pixel
//! parts through the kernels of `kernels.rs`. Works in f32 (the saved moments stay f32); other
//! float types are converted on the way in and out. Both gradients are always computed.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::{CubeBackend, CubeTensor};
use burn::tensor::FloatDType;
use burn_cubecl::cubecl;
use burn_cubecl::kernel::into_contiguous;
use cubecl::prelude::*;

use super::kernels::{moment_planes, ssim_coefficients, ssim_combine, ssim_map};
use super::{C1, C2, SsimBackend};
use crate::losses::blur::{TAPS, as_f32, blur_f32};

type B = CubeBackend;

fn u32_of(v: usize) -> u32 {
    u32::try_from(v).expect("SSIM sizes index within u32")
}

fn empty(shape: Vec<usize>, like: &CubeTensor) -> CubeTensor {
    B::float_empty(shape.into(), &like.device, FloatDType::F32)
}

/// Launch geometry for one unit per element.
fn grid(like: &CubeTensor, n: usize) -> (CubeCount, CubeDim) {
    let dim = CubeDim::new_1d(256);
    (cubecl::calculate_cube_count_elemwise(&like.client, n.max(1), dim), dim)
}

impl SsimBackend for CubeBackend {
    fn ssim_forward(x: FloatTensor<Self>, y: FloatTensor<Self>) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let [c, h, w]: [usize; 3] = x.shape().to_vec().try_into().expect("SSIM inputs are [C, H, W]");
        let (x, back) = as_f32(x);
        let (y, _) = as_f32(y);
        let size = c * h * w;
        let planes = empty(vec![5 * c, h, w], &x);
        let (count, dim) = grid(&x, size);
        moment_planes::launch(
            &x.client,
            count,
            dim,
            x.clone().into_buffer_arg(),
            y.into_buffer_arg(),
            planes.clone().into_buffer_arg(),
            u32_of(size),
        );
        let moments = blur_f32(planes, 0);
        let (oh, ow) = (h + 1 - TAPS, w + 1 - TAPS);
        let plane = c * oh * ow;
        let map = empty(vec![c, oh, ow], &moments);
        let (count, dim) = grid(&moments, plane);
        ssim_map::launch(
            &moments.client,
            count,
            dim,
            moments.clone().into_buffer_arg(),
            map.clone().into_buffer_arg(),
            u32_of(plane),
            C1 as f32,
            C2 as f32,
        );
        (back(map), B::float_reshape(moments, [5, c, oh, ow].into()))
    }

    fn ssim_backward(
        x: FloatTensor<Self>,
        y: FloatTensor<Self>,
        moments: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        _want_x: bool,
        _want_y: bool,
    ) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let [c, h, w]: [usize; 3] = x.shape().to_vec().try_into().expect("SSIM inputs are [C, H, W]");
        let (x, back) = as_f32(x);
        let (y, _) = as_f32(y);
        let (grad, _) = as_f32(grad);
        let moments = into_contiguous(moments);
        let (oh, ow) = (h + 1 - TAPS, w + 1 - TAPS);
        let plane = c * oh * ow;
        let coeff = empty(vec![4 * c, oh, ow], &moments);
        let (count, dim) = grid(&moments, plane);
        ssim_coefficients::launch(
            &moments.client,
            count,
            dim,
            moments.clone().into_buffer_arg(),
            grad.into_buffer_arg(),
            coeff.clone().into_buffer_arg(),
            u32_of(plane),
            C1 as f32,
            C2 as f32,
        );
        let t = blur_f32(coeff, TAPS - 1);
        let size = c * h * w;
        let (dx, dy) = (empty(vec![c, h, w], &t), empty(vec![c, h, w], &t));
        let (count, dim) = grid(&t, size);
        ssim_combine::launch(
            &t.client,
            count,
            dim,
            x.into_buffer_arg(),
            y.into_buffer_arg(),
            t.clone().into_buffer_arg(),
            dx.clone().into_buffer_arg(),
            dy.clone().into_buffer_arg(),
            u32_of(size),
        );
        (back(dx), back(dy))
    }
}
