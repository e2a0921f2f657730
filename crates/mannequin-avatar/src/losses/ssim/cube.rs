//! The fused SSIM on the CubeCL backends: the moments through the blur kernel, the per-pixel
//! parts through the kernels of `kernels.rs`. Works in f32 (the saved moments stay f32); other
//! float types are converted on the way in and out. Both gradients are always computed.
//!
//! The sizes are `y`'s `[C, H, W]`: `x` may hold more planes after its first C (the image loss
//! passes the renderer's stacked planes, compared in place), and `x`'s gradient is `[C, H, W]`.

use burn::backend::TensorMetadata;
use burn::backend::ops::FloatTensorOps;
use burn::backend::tensor::FloatTensor;
use burn::backend::wgpu::CubeBackend;
use burn_cubecl::kernel::into_contiguous;

use super::kernels::{moment_planes, ssim_coefficients, ssim_combine, ssim_map};
use super::{C1, C2, SsimBackend};
use crate::cube_launch::{empty_f32, per_element, u32_of};
use crate::losses::blur::{TAPS, as_f32, blur_f32};

type B = CubeBackend;

impl SsimBackend for CubeBackend {
    fn ssim_forward(x: FloatTensor<Self>, y: FloatTensor<Self>) -> (FloatTensor<Self>, FloatTensor<Self>) {
        let [c, h, w]: [usize; 3] = y.shape().to_vec().try_into().expect("SSIM inputs are [C, H, W]");
        let (x, back) = as_f32(x);
        let (y, _) = as_f32(y);
        let size = c * h * w;
        let planes = empty_f32(vec![5 * c, h, w], &x);
        let (count, dim) = per_element(&x, size);
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
        let map = empty_f32(vec![c, oh, ow], &moments);
        let (count, dim) = per_element(&moments, plane);
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
        let [c, h, w]: [usize; 3] = y.shape().to_vec().try_into().expect("SSIM inputs are [C, H, W]");
        let (x, back) = as_f32(x);
        let (y, _) = as_f32(y);
        let (grad, _) = as_f32(grad);
        let moments = into_contiguous(moments);
        let (oh, ow) = (h + 1 - TAPS, w + 1 - TAPS);
        let plane = c * oh * ow;
        let coeff = empty_f32(vec![4 * c, oh, ow], &moments);
        let (count, dim) = per_element(&moments, plane);
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
        let (dx, dy) = (empty_f32(vec![c, h, w], &t), empty_f32(vec![c, h, w], &t));
        let (count, dim) = per_element(&t, size);
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
